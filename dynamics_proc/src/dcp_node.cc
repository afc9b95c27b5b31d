#include "dcp_node.h"

#include <spdlog/spdlog.h>

#include "rms/channels.h"
#include "rms/check.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/message_io.h"
#include "rms/operator_input_t.hpp"

namespace rms::dcp {

namespace {
// operator_input_t has a fixed size: 8 (fingerprint) + 2 x 8 + 12 x 4.
constexpr int kMaxInputSize = 8 + 16 + 4 * kInputWords;
}  // namespace

DcpNode::DcpNode(const LabConfig& config, LcmInterface* lcm)
    : config_(config), lcm_(lcm), dcp_(config) {
  lcm_->Subscribe(channels::kOperatorInput, [this](const void* d, int n, std::int64_t t) {
    OnInput(d, n, t);
  });
}

void DcpNode::OnInput(const void* data, int size, std::int64_t recv_time_us) {
  counters_.Add("received");
  operator_input_t msg;
  const DecodeError err = SafeDecode(data, size, kMaxInputSize, &msg);
  if (err != DecodeError::kNone) {
    counters_.Add(std::string("dropped.") + DecodeErrorName(err));
    return;
  }
  OperatorInputs in;
  try {
    std::array<std::int32_t, kInputWords> words{};
    std::copy(msg.words, msg.words + kInputWords, words.begin());
    in = DecodeInputs(words, config_.inputs, &counters_);
  } catch (const InputError& e) {
    counters_.Add("dropped.bad_word");
    spdlog::debug("input frame {} dropped: {}", msg.frame, e.what());
    return;
  }
  switch (inputs_.Accept(msg.frame)) {
    case SequenceTracker::Verdict::kDuplicate: counters_.Add("dropped.duplicate"); return;
    case SequenceTracker::Verdict::kStale: counters_.Add("dropped.stale"); return;
    default: break;
  }
  counters_.Set("input.missing", inputs_.missing());
  latencies_["input_to_dcp"].Add(recv_time_us - msg.send_time_us);

  DcpFrameData out = dcp_.Step(in);
  out.frame = next_frame_++;
  out.input_frame = msg.frame;
  out.input_send_time_us = msg.send_time_us;
  out.send_time_us = lcm_->NowUs();
  dcp_frame_t wire_msg;
  PackDcpFrame(out, &wire_msg, &counters_);
  if (PublishMessage(*lcm_, channels::kDcpFrame, wire_msg)) counters_.Add("published");
  else counters_.Add("publish_failed");
  counters_.Set("mode", dcp_.mode());
}

int RunDynamicsProc(const LabConfig& config, LcmInterface& lcm, const std::string& stats_path,
                    const std::string& ready_path) {
  DcpNode node(config, &lcm);
  StatusReporter status(&lcm, "dynamics_proc");
  if (!ready_path.empty()) TouchFile(ready_path);
  spdlog::info("ready: {} -> {}", lcm.FullChannel(channels::kOperatorInput),
               lcm.FullChannel(channels::kDcpFrame));
  while (!StopRequested()) {
    if (lcm.HandleSubscriptions(100) < 0) {
      node.counters().Add("transport_errors");
    }
    Counters report = node.counters();
    AddLatencyCounters(node.latencies(), &report);
    status.Tick(node.last_frame(), report);
  }
  Counters report = node.counters();
  AddLatencyCounters(node.latencies(), &report);
  status.Final(node.last_frame(), report);
  if (!stats_path.empty()) WriteStatsJson(stats_path, "dynamics_proc", node.counters(), node.latencies());
  spdlog::info("published {} DCP frames; inputs missing {}, dropped {}; final mode {}",
               node.counters().Get("published"), node.counters().Get("input.missing"),
               node.counters().SumPrefix("dropped."), node.program().mode());
  return 0;
}

}  // namespace rms::dcp
