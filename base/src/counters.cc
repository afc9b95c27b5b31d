#include "rms/base/counters.h"

#include <algorithm>

namespace rms {

std::optional<Counter> CounterNamed(std::string_view name) {
  for (const CounterInfo& c : kCounterTable) {
    if (c.name == name) return c.id;
  }
  return std::nullopt;
}

std::int64_t Counters::Sum(Counter first, Counter last) const {
  std::int64_t s = 0;
  for (int i = static_cast<int>(first); i <= static_cast<int>(last); ++i) s += values_[i];
  return s;
}

void Counters::AddAll(const Counters& other) {
  for (int i = 0; i < kNumCounters; ++i) {
    if (other.touched_[i]) Add(static_cast<Counter>(i), other.values_[i]);
  }
}

std::map<std::string, std::int64_t> Counters::ByName() const {
  std::map<std::string, std::int64_t> out;
  for (int i = 0; i < kNumCounters; ++i) {
    if (touched_[i]) out.emplace(kCounterTable[i].name, values_[i]);
  }
  return out;
}

std::string CounterTableMarkdown() {
  std::string out = "| Counter | Process | Meaning |\n|---|---|---|\n";
  for (const CounterInfo& c : kCounterTable) {
    out += "| `" + std::string(c.name) + "` | " + std::string(c.processes) + " | " +
           std::string(c.meaning) + " |\n";
  }
  return out;
}

namespace {
constexpr int kFineBins = 1000;    // 0..999 us, 1 us each
constexpr int kMidBins = 9900;     // 1 ms..100 ms, 10 us each
constexpr int kCoarseBins = 9900;  // 100 ms..10 s, 1 ms each
constexpr int kTotalBins = kFineBins + kMidBins + kCoarseBins + 1;
}  // namespace

LatencyHistogram::LatencyHistogram() : bins_(kTotalBins, 0) {}

int LatencyHistogram::BinOf(std::int64_t us) {
  if (us < 0) us = 0;
  if (us < 1000) return static_cast<int>(us);
  if (us < 100000) return kFineBins + static_cast<int>((us - 1000) / 10);
  if (us < 10000000) return kFineBins + kMidBins + static_cast<int>((us - 100000) / 1000);
  return kTotalBins - 1;
}

double LatencyHistogram::Representative(int bin) {
  // Exact for the 1 us bins; the middle of the wider bins.
  if (bin < kFineBins) return bin;
  if (bin < kFineBins + kMidBins) return 1000 + (bin - kFineBins) * 10.0 + 5.0;
  if (bin < kTotalBins - 1) return 100000 + (bin - kFineBins - kMidBins) * 1000.0 + 500.0;
  return 1e7;
}

void LatencyHistogram::Add(std::int64_t us) {
  ++bins_[BinOf(us)];
  ++count_;
  sum_ += std::max<std::int64_t>(us, 0);
  max_ = std::max(max_, us);
}

double LatencyHistogram::Percentile(double q) const {
  if (count_ == 0) return 0.0;
  q = std::clamp(q, 0.0, 1.0);
  const std::int64_t rank =
      std::max<std::int64_t>(1, static_cast<std::int64_t>(q * count_ + 0.999999));
  std::int64_t seen = 0;
  for (int b = 0; b < kTotalBins; ++b) {
    seen += bins_[b];
    if (seen >= rank) return std::min(Representative(b), static_cast<double>(max_));
  }
  return static_cast<double>(max_);
}

void LatencyHistogram::Reset() {
  std::fill(bins_.begin(), bins_.end(), 0);
  count_ = sum_ = max_ = 0;
}

void RecordEndToEnd(std::int64_t latency_us, double frame_rate_hz, LatencyHistogram* histogram,
                    Counters* counters) {
  histogram->Add(latency_us);
  if (latency_us > static_cast<std::int64_t>(1e6 / frame_rate_hz))
    counters->Add(Counter::kFramesLate);
}

}  // namespace rms
