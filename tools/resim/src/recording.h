#pragma once
// What re-simulation reads of a session's log (docs/sessions.md
// "Re-simulation"): the operator frames, the DCP's frames and telemetry it
// made from them, the states it logged; and the plan that replays them in
// order, from the state the log allows the re-simulation to start from.
#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "rms/base/check.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_state_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/session/session_log.h"
#include "rms/wire/message_io.h"

namespace rms::resim {

// A message as logged, undecoded: its bytes are Recording::bytes[part]
// [offset, offset + size), its frame number read where it lies
// (wire::ReadFrameNumber).
struct RecordedMessage {
  std::int64_t frame = 0;
  std::int64_t timestamp_us = 0;  // the recorder's receive time
  std::size_t offset = 0, size = 0;
  std::uint8_t part = 0;  // the part of the log it was read in (SessionLog::ReadInTwo)
};

// An RMS_DCP_FRAME as logged, undecoded, with the operator frame it answers
// (read where it lies: wire::kSendTimeAt + 8).
struct RecordedDcpFrame : RecordedMessage {
  std::int64_t input_frame = -1;
};

// An RMS_DCP_STATE as logged, with the number of the DCP's (believed)
// frames logged before it: its place among them.
struct LoggedState {
  std::size_t before = 0;
  dcp_state_t m;
};

struct Recording {
  std::string suffix;
  std::vector<RecordedMessage> inputs;       // by operator frame (the last logged of a frame)
  std::vector<RecordedDcpFrame> dcp_frames;  // in log order, undecoded
  std::vector<RecordedMessage> telemetry;    // by DCP frame (the last logged of a frame), undecoded
  std::vector<LoggedState> states;           // in log order
  bool read_in_two = false;                  // the log read in two parts at once
  // The inputs' and the telemetry's, one after another, by the part of the
  // log they were read in.
  std::array<std::vector<std::uint8_t>, 2> bytes;
  const std::uint8_t* BytesOf(const RecordedMessage& m) const {
    return bytes[m.part].data() + m.offset;
  }
  // A recorded message decoded as the Msg it was checked to be as it was
  // read (RMS_DCP_FRAME, RMS_DCP_TELEMETRY).
  template <class Msg>
  Msg Decoded(const RecordedMessage& m) const {
    Msg out;
    RMS_CHECK(wire::SafeDecode(BytesOf(m), static_cast<int>(m.size), &out) ==
              wire::DecodeError::kNone);
    return out;
  }
};

// Messages with a frame number, in increasing order of it, one a frame:
// the last of equal frames kept (left as they are when already so).
template <class Msg>
void SortByFrame(std::vector<Msg>* v) {
  if (std::adjacent_find(v->begin(), v->end(),
                         [](const Msg& a, const Msg& b) { return a.frame >= b.frame; }) == v->end())
    return;
  std::stable_sort(v->begin(), v->end(),
                   [](const Msg& a, const Msg& b) { return a.frame < b.frame; });
  std::vector<Msg> kept;
  kept.reserve(v->size());
  for (std::size_t i = 0; i < v->size(); ++i) {
    if (i + 1 < v->size() && (*v)[i + 1].frame == (*v)[i].frame) continue;
    kept.push_back(std::move((*v)[i]));
  }
  v->swap(kept);
}

// The message of a frame in a vector SortByFrame made, or null.
template <class Msg>
const Msg* FindFrame(const std::vector<Msg>& v, std::int64_t frame) {
  const auto it = std::lower_bound(v.begin(), v.end(), frame,
                                   [](const Msg& m, std::int64_t f) { return m.frame < f; });
  return it != v.end() && it->frame == frame ? &*it : nullptr;
}

// The recording's telemetry decoded (what the design comparison reads), in
// increasing order of frame, one a frame, as Recording::telemetry.
std::vector<dcp_telemetry_t> DecodedTelemetry(const Recording& r);

// The channels re-simulation needs, read from the log (the DCP's increasing
// run of frames only, as the summary believes them); the operator frames,
// the DCP's frames and its telemetry are kept as logged, undecoded (the
// re-simulation compares them byte for byte). With another core, the log
// is read in two parts at once (SessionLog::ReadInTwo, `parts`). Throws
// InputError when there is no DCP frame.
Recording ReadRecording(session::SessionLog& log, const session::SessionLog::TwoParts& parts = {});

// What the re-simulation does, step by step: a logged state to take (or,
// PERIODIC, to check against), then an operator frame to answer.
struct Step {
  const dcp_state_t* state = nullptr;
  std::int64_t input_frame = -1;  // -1: a state only
  bool first = false;  // the state the re-simulation starts from (taken, whatever its reason)
};

struct Plan {
  std::vector<Step> steps;
  std::size_t first = 0;  // the index of the first recorded DCP frame re-simulated
  std::string note;       // what the log lacks, when it does not start at the session's start
};

// The operator frame each DCP frame answered, in DCP frame order, with the
// logged states in their places, and DCP frames the recorder lost filled in
// where that is unambiguous; throws InputError where the log cannot be
// re-simulated exactly.
Plan MakePlan(const Recording& r);

}  // namespace rms::resim
