#pragma once
// Non-fatal trouble becomes a counter that is reported (after MuJoCo's warning
// counters in mjdata.h), never a silent skip. Counters are named with dots:
// "dropped.wrong_type", "clamped.shoulder_yaw", "frames.gap".
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace rms {

class Counters {
 public:
  void Add(const std::string& name, std::int64_t n = 1) { values_[name] += n; }
  void Set(const std::string& name, std::int64_t v) { values_[name] = v; }
  std::int64_t Get(const std::string& name) const {
    auto it = values_.find(name);
    return it == values_.end() ? 0 : it->second;
  }
  // Sum of every counter whose name starts with prefix.
  std::int64_t SumPrefix(const std::string& prefix) const;
  const std::map<std::string, std::int64_t>& values() const { return values_; }

 private:
  std::map<std::string, std::int64_t> values_;
};

// Latency (or any duration) samples in microseconds, in a fixed-size
// histogram: bounded memory for sessions of any length. 1 us bins below 1 ms,
// 10 us bins to 100 ms, 1 ms bins to 10 s, then one overflow bin.
// Timing health (docs/sessions.md "Timing health"): a frame is late at a
// stage when it reaches it more than one frame period after the operator
// sent it. Adds the end-to-end latency to `latencies[link]` and counts
// "frames.late".
class LatencyHistogram;
void RecordEndToEnd(std::int64_t latency_us, double frame_rate_hz, LatencyHistogram* histogram, Counters* counters);

class LatencyHistogram {
 public:
  LatencyHistogram();
  void Add(std::int64_t us);
  std::int64_t count() const { return count_; }
  // Percentile q in [0, 1], us: exact below 1 ms, within 5 us below 100 ms,
  // within 0.5 ms above; 0 when empty.
  double Percentile(double q) const;
  double max_us() const { return static_cast<double>(max_); }
  double mean_us() const { return count_ ? static_cast<double>(sum_) / count_ : 0.0; }
  void Reset();

 private:
  static int BinOf(std::int64_t us);
  static double Representative(int bin);
  std::vector<std::int64_t> bins_;
  std::int64_t count_ = 0;
  std::int64_t sum_ = 0;
  std::int64_t max_ = 0;
};

}  // namespace rms
