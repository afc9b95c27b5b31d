#include "dcp_node.h"

#include <spdlog/spdlog.h>

#include "rms/channels.h"
#include "rms/check.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/frame_receiver.h"
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
  auto got = ReceiveFrame<operator_input_t>(
      data, size, kMaxInputSize, &inputs_, &counters_, [this](const operator_input_t& m) {
        std::array<std::int32_t, kInputWords> words{};
        std::copy(m.words, m.words + kInputWords, words.begin());
        return DecodeInputs(words, config_.inputs, &counters_);
      });
  if (!got) return;
  const auto& [msg, in] = *got;
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
  if (!ready_path.empty()) TouchFile(ready_path);
  spdlog::info("ready: {} -> {}", lcm.FullChannel(channels::kOperatorInput),
               lcm.FullChannel(channels::kDcpFrame));
  RunNodeLoop(lcm, "dynamics_proc", node.counters(), node.latencies(),
              [&] { return node.last_frame(); }, nullptr, stats_path);
  spdlog::info("published {} DCP frames; inputs missing {}, dropped {}; final mode {}",
               node.counters().Get("published"), node.counters().Get("input.missing"),
               node.counters().SumPrefix("dropped."), node.program().mode());
  return 0;
}

}  // namespace rms::dcp
