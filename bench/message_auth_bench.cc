// The cost of authenticated messages (docs/security.md "Authenticated
// messages"): a tag made (publishing) and checked (receiving) for each of
// the session's messages as they travel, their typical sizes encoded here.
// scripts/bench runs it; the suite runs it briefly (label bench).
#include <benchmark/benchmark.h>
#include <cstdint>
#include <vector>

#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/esg_frame_t.hpp"
#include "rms/operator_input_t.hpp"
#include "rms/process_status_t.hpp"
#include "rms/wire/message_auth.h"
#include "rms/wire/message_io.h"

namespace {

rms::wire::SessionKey Key() {
  rms::wire::SessionKey k;
  for (std::size_t i = 0; i < k.bytes.size(); ++i)
    k.bytes[i] = static_cast<std::uint8_t>(i * 5 + 1);
  return k;
}

// A message of each kind, encoded as the processes send it.
std::vector<std::uint8_t> Message(int kind) {
  switch (kind) {
    case 0:
      return rms::wire::EncodeMessage(rms::operator_input_t{});
    case 1:
      return rms::wire::EncodeMessage(rms::dcp_frame_t{});
    case 2:
      return rms::wire::EncodeMessage(rms::dcp_telemetry_t{});
    case 3: {
      rms::esg_frame_t m{};
      m.num_words = 64;
      m.words.assign(64, 0xABCDEF);
      return rms::wire::EncodeMessage(m);
    }
    default: {
      rms::process_status_t m{};
      m.process = "dynamics_proc";
      for (int i = 0; i < 60; ++i) {
        m.counter_names.push_back("dropped.counter_" + std::to_string(i));
        m.counter_values.push_back(i);
      }
      m.num_counters = static_cast<std::int16_t>(m.counter_names.size());
      return rms::wire::EncodeMessage(m);
    }
  }
}
const char* kNames[] = {"operator_input", "dcp_frame", "dcp_telemetry", "esg_frame_64_words",
                        "status_60_counters"};

void BM_MessageMacMake(benchmark::State& state) {
  const auto key = Key();
  const std::vector<std::uint8_t> m = Message(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    auto tag = rms::wire::MessageMac(key, "RMS_DCP_FRAME", m.data(), static_cast<int>(m.size()));
    benchmark::DoNotOptimize(tag);
  }
  state.SetLabel(std::string(kNames[state.range(0)]) + ", " + std::to_string(m.size()) + " bytes");
}

void BM_MessageMacCheck(benchmark::State& state) {
  const auto key = Key();
  std::vector<std::uint8_t> m = Message(static_cast<int>(state.range(0)));
  const auto tag =
      rms::wire::MessageMac(key, "RMS_DCP_FRAME", m.data(), static_cast<int>(m.size()));
  m.insert(m.end(), tag.begin(), tag.end());
  for (auto _ : state) {
    const bool ok =
        rms::wire::VerifyMessageMac(key, "RMS_DCP_FRAME", m.data(), static_cast<int>(m.size()));
    benchmark::DoNotOptimize(ok);
  }
  state.SetLabel(std::string(kNames[state.range(0)]) + ", " + std::to_string(m.size()) + " bytes");
}

BENCHMARK(BM_MessageMacMake)->DenseRange(0, 4);
BENCHMARK(BM_MessageMacCheck)->DenseRange(0, 4);

}  // namespace

BENCHMARK_MAIN();
