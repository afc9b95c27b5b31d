#include "rms/wire/message_io.h"

#include <cstdio>

#include "rms/control_answer_t.hpp"
#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_state_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/esg_frame_t.hpp"
#include "rms/operator_input_t.hpp"
#include "rms/operator_state_t.hpp"
#include "rms/process_status_t.hpp"
#include "rms/sender_t.hpp"
#include "rms/session_control_t.hpp"
#include "rms/window_keys_t.hpp"

namespace rms::wire {

namespace {
std::uint64_t ReadBigEndian(const std::uint8_t* b, int n) {
  std::uint64_t v = 0;
  for (int i = 0; i < n; ++i) v = (v << 8) | b[i];
  return v;
}
}  // namespace

bool IsRmslabFingerprint(std::int64_t fp) {
  static const std::int64_t kTypes[] = {
      operator_input_t::getHash(), dcp_frame_t::getHash(),      esg_frame_t::getHash(),
      process_status_t::getHash(), dcp_telemetry_t::getHash(),  session_control_t::getHash(),
      window_keys_t::getHash(),    operator_state_t::getHash(), dcp_state_t::getHash(),
      control_answer_t::getHash(),
  };
  for (std::int64_t t : kTypes) {
    if (t == fp) return true;
  }
  return false;
}

bool ReadSessionId(const void* data, int size, std::int64_t* session_id) {
  if (size < 8 + kSenderBytes) return false;
  *session_id =
      static_cast<std::int64_t>(ReadBigEndian(static_cast<const std::uint8_t*>(data) + 8, 8));
  return true;
}

bool ReadInt64At(const void* data, int size, int at, std::int64_t* value) {
  if (at < 0 || size < at + 8) return false;
  *value = static_cast<std::int64_t>(ReadBigEndian(static_cast<const std::uint8_t*>(data) + at, 8));
  return true;
}

bool ReadSenderProcess(const void* data, int size, std::int8_t* process, std::int32_t* pid) {
  if (size < 8 + kSenderBytes) return false;
  const auto* b = static_cast<const std::uint8_t*>(data);
  *process = static_cast<std::int8_t>(b[16]);
  *pid = static_cast<std::int32_t>(static_cast<std::uint32_t>(ReadBigEndian(b + 17, 4)));
  return true;
}

std::string FormatSessionId(std::int64_t session_id) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "0x%016llx", static_cast<unsigned long long>(session_id));
  return buf;
}

namespace {
constexpr struct {
  std::int8_t code;
  const char* name;
} kProcessNames[] = {
    {sender_t::PROCESS_OPERATOR_STATION, "operator_station"},
    {sender_t::PROCESS_DYNAMICS, "dynamics_proc"},
    {sender_t::PROCESS_SCENE, "scene_proc"},
    {sender_t::PROCESS_ESG, "esg_renderer"},
    {sender_t::PROCESS_CONTROL, "rms_control"},
    {sender_t::PROCESS_TOOL, "tool"},
    {sender_t::PROCESS_INSTRUCTOR, "instructor_station"},
};
}  // namespace

const char* ControlCommandName(std::int8_t command) {
  static constexpr const char* kNames[] = {
      "?", "freeze", "run", "step", "checkpoint", "restore", "reset", "malfunction", "repair"};
  static_assert(session_control_t::REPAIR == 8, "kNames follows session_control_t's commands");
  return command >= 1 && command <= 8 ? kNames[command] : "?";
}

control_answer_t MakeControlAnswer(const session_control_t& command, std::int8_t outcome,
                                   std::int64_t frame, std::string text) {
  control_answer_t a{};
  a.command_process = command.sender.process;
  a.command_pid = command.sender.pid;
  a.command_sequence = command.sequence;
  a.command = command.command;
  a.outcome = outcome;
  a.frame = frame;
  if (text.size() > static_cast<std::size_t>(control_answer_t::MAX_TEXT_BYTES)) {
    std::size_t n = control_answer_t::MAX_TEXT_BYTES;
    while (n > 0 && (static_cast<unsigned char>(text[n]) & 0xC0) == 0x80) --n;  // a continuation
    text.resize(n);
  }
  a.text = std::move(text);
  return a;
}

const char* ProcessCodeName(std::int8_t process) {
  for (const auto& p : kProcessNames) {
    if (p.code == process) return p.name;
  }
  return "unknown";
}

std::int8_t ProcessCode(std::string_view name) {
  for (const auto& p : kProcessNames) {
    if (name == p.name) return p.code;
  }
  return sender_t::PROCESS_TOOL;
}

const char* DecodeErrorName(DecodeError e) {
  switch (e) {
    case DecodeError::kNone:
      return "none";
    case DecodeError::kTooLarge:
    case DecodeError::kWrongType:
    case DecodeError::kTruncated:
    case DecodeError::kTrailingBytes:
    case DecodeError::kBadCount:
      return kDecodeErrorNames[static_cast<int>(e) - 1].data();
  }
  return "unknown";
}

}  // namespace rms::wire
