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

// The frame numbers a session's clock allows (docs/protocol.md "Frame
// numbers"): every sender numbers its frames from the session's epoch, so by
// now_us none can have gone past (now_us - epoch_us) x max_rate_hz, plus a
// margin. epoch_us 0: no session clock (a process started by hand).
struct FrameClock {
  std::int64_t epoch_us = 0;
  double max_rate_hz = 0;
  double margin_s = 10.0;
  bool active() const { return epoch_us > 0 && max_rate_hz > 0; }
  std::int64_t Limit(std::int64_t now_us) const;
};

// Frame-number bookkeeping for one incoming stream: detects lost frames
// (gaps), duplicates and stale (out-of-order) frames, and refuses frame
// numbers that cannot be real: beyond the session clock (FrameClock), or --
// with no clock -- more than kMaxJump ahead of the last. A sender whose
// numbering really moved (restarted without the session's epoch; or the
// last accepted frame was a forgery far ahead) is followed again after
// kResyncAfter refusals in a row, each after the one before: kResync.
// docs/protocol.md "Frame numbers".
class SequenceTracker {
 public:
  enum class Verdict { kFirst, kNext, kGap, kDuplicate, kStale, kFarAhead, kResync };
  static constexpr int kResyncAfter = 30;
  static constexpr std::int64_t kMaxJump = std::int64_t{1} << 20;  // 9.7 h at 30 Hz

  void SetClock(const FrameClock& clock) { clock_ = clock; }
  // now_us: when it arrived (wall clock); only the clock check uses it.
  Verdict Accept(std::int64_t frame, std::int64_t now_us = 0);
  std::int64_t received() const { return received_; }
  std::int64_t missing() const { return missing_; }   // frames never seen (sum of gaps)
  std::int64_t duplicates() const { return duplicates_; }
  std::int64_t stale() const { return stale_; }
  std::int64_t far_ahead() const { return far_ahead_; }
  std::int64_t resyncs() const { return resyncs_; }
  std::int64_t last() const { return last_; }
  std::int64_t previous() const { return previous_; }  // the last frame before the latest
  bool started() const { return started_; }

 private:
  Verdict Refuse(std::int64_t frame, Verdict why);
  FrameClock clock_;
  bool started_ = false;
  std::int64_t last_ = -1, previous_ = -1;
  std::int64_t received_ = 0, missing_ = 0, duplicates_ = 0, stale_ = 0, far_ahead_ = 0, resyncs_ = 0;
  int refused_run_ = 0;            // refusals in a row, each after the one before
  std::int64_t refused_last_ = -1;
};

}  // namespace rms
