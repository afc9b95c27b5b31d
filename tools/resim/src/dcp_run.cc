#include "dcp_run.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <optional>
#include <spdlog/sinks/base_sink.h>
#include <spdlog/spdlog.h>
#include <thread>

#include "rms/base/check.h"
#include "rms/base/other_core.h"
#include "rms/dcp_state_t.hpp"
#include "rms/dynamics_proc/dynamics_proc.h"
#include "rms/transport/lcm_interface.h"
#include "rms/transport/process.h"
#include "rms/wire/channels.h"
#include "rms/wire/checkpoint.h"
#include "rms/wire/frame_numbers.h"
#include "rms/wire/message_io.h"

#include "comparison.h"

namespace fs = std::filesystem;

namespace rms::resim {

namespace {

using Clock = std::chrono::steady_clock;
using Progress = std::function<void(double, const std::string&)>;

// A logged state: a restore, a resume, a malfunction or a start is taken as
// the live DCP took it (another design keeps its own state at a resume: only
// the numbering; at a malfunction, the numbering and the malfunctions in
// force); a periodic one is checked against the re-simulated state (the same
// design only: another one is expected to differ).
void TakeState(const dcp_state_t& m, bool first, bool other_design,
               dynamics_proc::DynamicsProc* node, ResimResult* result) {
  if (m.reason == dcp_state_t::PERIODIC && !first) {
    if (other_design || !result->state_difference.empty()) return;
    ++result->states_checked;
    const nlohmann::json now = node->MakeCheckpoint().dcp;
    if (!wire::TextHoldsDcp(m.checkpoint, now, "RMS_DCP_STATE") &&
        wire::ParseCheckpoint(m.checkpoint, "RMS_DCP_STATE").dcp != now) {
      result->state_difference = "the DCP's state before DCP frame " +
                                 std::to_string(m.next_frame) +
                                 " differs from the state it logged there";
    }
    return;
  }
  const bool own_state =
      other_design && (m.reason == dcp_state_t::RESUME || m.reason == dcp_state_t::MALFUNCTION);
  node->ApplyState(m, first || !own_state);
  ++result->states_taken;
  // Into the new session's log too, so it can be re-simulated and its
  // summary sees the same restores (its attempts).
  node->PublishState(m.reason == dcp_state_t::PERIODIC ? dcp_state_t::START : m.reason);
}

// One DCP node over a log-backed transport (out_log: the new session's log,
// "" for none), stepped through a stretch of the plan, with what it sent in
// the order sent. During the run the outputs go to vectors reserved up front
// (no allocation a frame).
class DcpRunner {
 public:
  DcpRunner(const LabConfig& config, const Recording& rec, const std::string& out_log,
            bool other_design, std::size_t steps)
      : rec_(rec),
        other_design_(other_design),
        in_memory_(other_design && out_log.empty()),
        lcm_("", out_log, rec.suffix),
        node_(config, &lcm_) {
    frame_verdicts.reserve(steps);
    telemetry_verdicts.reserve(steps);
    if (in_memory_) frames.reserve(steps);
    if (other_design) telemetry.reserve(steps);
    // Nobody reads a periodic state unless it is written.
    node_.set_periodic_states(!out_log.empty());
    // The new log's first event (the state it starts from, sent before any
    // input) at the recorded log's first input's time, not at 0: its
    // readers' wall times count from it (docs/sessions.md "Session time").
    if (!rec.inputs.empty()) lcm_.SetNowUs(rec.inputs.front().timestamp_us);
    Subscribe();
  }
  DcpRunner(const DcpRunner&) = delete;
  DcpRunner& operator=(const DcpRunner&) = delete;

  // Steps [begin, end) of the plan; with until_frame >= 0, up to the DCP
  // frame of that number.
  void Run(const Plan& plan, std::size_t begin, std::size_t end, long until_frame,
           const Progress& progress, ResimResult* result) {
    const std::size_t n = plan.steps.size();
    for (std::size_t k = begin; k < end; ++k) {
      const Step& step = plan.steps[k];
      if (step.state) {
        TakeState(*step.state, step.first, other_design_, &node_, result);
        continue;
      }
      Answer(step.input_frame);
      if (until_frame >= 0 && !frame_verdicts.empty() && frame_verdicts.back().frame >= until_frame)
        break;
      if (progress && n >= 20 && k % (n / 20) == 0)
        progress(static_cast<double>(k) / n,
                 std::to_string(k) + " of " + std::to_string(n) + " steps");
    }
  }
  // A periodic state logged in the plan taken as this node's start: the
  // second half's.
  void StartFrom(const dcp_state_t& m, ResimResult* result) {
    TakeState(m, true, other_design_, &node_, result);
  }
  const dynamics_proc::DynamicsProc& node() const { return node_; }
  // The new session's log written whole, or InputError naming it.
  void FinishLog(const std::string& path) {
    std::string why;
    if (!lcm_.FinishOutput(&why))
      throw InputError("cannot write the new session's log " + path + ": " + why);
  }

  std::vector<Verdict> frame_verdicts, telemetry_verdicts;
  std::vector<dcp_frame_t> frames;           // decoded, another design made in memory only
  std::vector<dcp_telemetry_t> telemetry;    // decoded, another design only
  std::vector<std::size_t> restores_before;  // where a restore's RMS_DCP_STATE went among them

 private:
  // The DCP answers the operator frame as logged.
  void Answer(std::int64_t input_frame) {
    const RecordedMessage* input = FindFrame(rec_.inputs, input_frame);
    if (!input) {
      throw InputError(
          "operator frame " + std::to_string(input_frame) +
          ", which the DCP answered, is not in the log: the re-simulation cannot be exact");
    }
    lcm_.SetNowUs(input->timestamp_us);
    lcm_.Publish(wire::channels::kOperatorInput, rec_.BytesOf(*input),
                 static_cast<int>(input->size));
    lcm_.HandleSubscriptions(0);  // the input to the DCP
    lcm_.HandleSubscriptions(0);  // its outputs to the runner
  }
  void Subscribe();

  const Recording& rec_;
  bool other_design_, in_memory_;
  transport::LogLcm lcm_;
  dynamics_proc::DynamicsProc node_;
};

// A message the DCP sent (of type Msg, found whole by wire::CheckEncoded)
// against the recorded one of its frame among `recorded`; what(recorded)
// names the first field that differs, asked only when the bytes do (a
// callable, not a std::function: nothing allocated a message).
template <class Msg, class Recorded, class What>
Verdict Judge(const void* d, int n, const Recording& rec, const std::vector<Recorded>& recorded,
              const What& what) {
  Verdict v;
  RMS_CHECK(wire::ReadFrameNumber(d, n, &v.frame));
  const Recorded* r = FindFrame(recorded, v.frame);
  if (!r) return v;  // kNoneRecorded
  if (SameButSenderAndTime<Msg>(rec.BytesOf(*r), static_cast<const std::uint8_t*>(d))) {
    v.kind = Verdict::kSame;
  } else {
    v.kind = Verdict::kDiffers;
    v.what = what(*r);
  }
  return v;
}

void DcpRunner::Subscribe() {
  lcm_.Subscribe(wire::channels::kDcpFrame, [this](const void* d, int n, std::int64_t) {
    if (wire::CheckEncoded<dcp_frame_t>(d, n) != wire::DecodeError::kNone) return;
    dcp_frame_t here;  // decoded once, where it is kept (a design made in memory) or here
    dcp_frame_t* made = in_memory_ ? &frames.emplace_back() : &here;
    bool decoded = false;
    const auto what = [&](const RecordedDcpFrame& recorded) {
      if (!decoded) RMS_CHECK(wire::SafeDecode(d, n, made) == wire::DecodeError::kNone);
      decoded = true;
      std::string field;
      return SameFrame(*made, rec_.Decoded<dcp_frame_t>(recorded), &field)
                 ? std::string("frame")  // (the bytes differ, so some field does)
                 : field;
    };
    frame_verdicts.push_back(Judge<dcp_frame_t>(d, n, rec_, rec_.dcp_frames, what));
    if (in_memory_ && !decoded) RMS_CHECK(wire::SafeDecode(d, n, made) == wire::DecodeError::kNone);
  });
  lcm_.Subscribe(wire::channels::kDcpTelemetry, [this](const void* d, int n, std::int64_t) {
    if (wire::CheckEncoded<dcp_telemetry_t>(d, n) != wire::DecodeError::kNone) return;
    const auto what = [](const RecordedMessage&) { return std::string("telemetry"); };
    telemetry_verdicts.push_back(Judge<dcp_telemetry_t>(d, n, rec_, rec_.telemetry, what));
    if (other_design_) {
      telemetry.emplace_back();
      RMS_CHECK(wire::SafeDecode(d, n, &telemetry.back()) == wire::DecodeError::kNone);
    }
  });
  lcm_.Subscribe(wire::channels::kDcpState, [this](const void* d, int n, std::int64_t) {
    dcp_state_t m;
    if (wire::SafeDecode(d, n, &m) == wire::DecodeError::kNone && m.reason == dcp_state_t::RESTORE)
      restores_before.push_back(telemetry_verdicts.size());
  });
}

// The runner's outputs by frame, moved out of it; for a design made in
// memory, also as sent.
Outputs Collect(DcpRunner* r, bool in_memory) {
  Outputs out;
  out.frame_verdicts = std::move(r->frame_verdicts);
  out.telemetry_verdicts = std::move(r->telemetry_verdicts);
  if (in_memory) {
    out.published =
        session::DcpRun{std::move(r->frames), r->telemetry, std::move(r->restores_before)};
  }
  out.telemetry = std::move(r->telemetry);
  SortByFrame(&out.frame_verdicts);
  SortByFrame(&out.telemetry_verdicts);
  SortByFrame(&out.telemetry);
  return out;
}

// Word for word against the recording: its DCP frames [begin, end) (up to
// until_frame, when >= 0) against the re-simulated frames and telemetry
// verdicts, each in increasing order of frame. Counts, and notes the first
// difference.
void CompareRange(const Recording& rec, const Plan& plan, std::size_t begin, std::size_t end,
                  long until_frame, const std::vector<Verdict>& frames,
                  const std::vector<Verdict>& telemetry, ResimResult* result) {
  for (std::size_t i = begin; i < end; ++i) {
    const std::int64_t frame = rec.dcp_frames[i].frame;
    if (until_frame >= 0 && frame > until_frame) break;
    if (!plan.Checked(i)) continue;  // lost before it from every source: not re-made
    ++result->compared;
    const Verdict* made = FindFrame(frames, frame);
    bool same = made && made->kind == Verdict::kSame;
    std::string what = made ? made->what : "missing";
    if (!same && result->first_decision_frame < 0) {  // the DCP's words: its decisions
      result->first_decision_frame = static_cast<long>(frame);
      result->first_decision = what;
    }
    if (same) {
      const Verdict* t = FindFrame(telemetry, frame);
      if (t && t->kind == Verdict::kDiffers) {
        same = false;
        what = t->what;
      }
    }
    if (same) {
      ++result->identical;
    } else if (result->first_difference.empty()) {
      result->first_difference = "DCP frame " + std::to_string(frame) + ": " + what;
      result->first_difference_frame = static_cast<long>(frame);
    }
  }
}

// The whole comparison, from the plan's first frame; a state that differed
// is the first difference when no frame is.
void CompareWithRecording(const Recording& rec, const Plan& plan, long until_frame,
                          const Outputs& out, ResimResult* result) {
  CompareRange(rec, plan, plan.first, rec.dcp_frames.size(), until_frame, out.frame_verdicts,
               out.telemetry_verdicts, result);
  if (result->first_difference.empty() && !result->state_difference.empty()) {
    result->first_difference = result->state_difference;
  }
}

// Where the run can be cut in two: the periodic state logged nearest the
// plan's middle, with at least kMinHalf steps on either side; 0 for none.
std::size_t SplitStep(const Plan& plan) {
  constexpr std::size_t kMinHalf = 300;
  const std::size_t n = plan.steps.size(), middle = n / 2;
  std::size_t best = 0;
  auto distance = [&](std::size_t k) { return k > middle ? k - middle : middle - k; };
  for (std::size_t k = kMinHalf; k + kMinHalf < n; ++k) {
    const Step& s = plan.steps[k];
    if (s.state && !s.first && s.state->reason == dcp_state_t::PERIODIC &&
        (best == 0 || distance(k) < distance(best)))
      best = k;
  }
  return best;
}

// A half's outputs, each message a frame of its own, in increasing order,
// all below `below` (or at or above `from`); one of them compared with the
// recorded frames [begin, end) and found identical, its states agreeing.
template <class Msg>
bool Within(const std::vector<Msg>& v, std::int64_t from, std::int64_t below) {
  return std::adjacent_find(v.begin(), v.end(),
                            [](const Msg& a, const Msg& b) { return a.frame >= b.frame; }) ==
             v.end() &&
         (v.empty() || (v.front().frame >= from && v.back().frame < below));
}
bool HalfAgrees(const Recording& rec, const Plan& plan, std::size_t begin, std::size_t end,
                std::int64_t from, std::int64_t below, const DcpRunner& half, ResimResult* result) {
  if (!Within(half.frame_verdicts, from, below) || !Within(half.telemetry_verdicts, from, below))
    return false;
  CompareRange(rec, plan, begin, end, -1, half.frame_verdicts, half.telemetry_verdicts, result);
  return result->first_difference.empty() && result->state_difference.empty() &&
         result->identical == result->compared;
}

// Whether one run, going on from the first half's node at the split, is
// where the second half starts: the logged state's numbering is the first
// half's, and the second half's fresh node takes its first operator frame as
// the first half's node would (a fresh one takes any: one run takes it only
// after its last, not a duplicate, stale or too far ahead). The DCP's own
// state at the split is checked as any periodic state is.
bool ContinuesAsLogged(const Plan& plan, std::size_t split,
                       const dynamics_proc::DynamicsProc& first) {
  if (!first.NumberingIs(*plan.steps[split].state)) return false;
  const wire::SequenceTracker& seen = first.input_sequence();
  for (std::size_t k = split + 1; k < plan.steps.size(); ++k) {
    const std::int64_t f = plan.steps[k].input_frame;
    if (plan.steps[k].state || f < 0) continue;
    return !seen.started() ||
           (f > seen.last() && f - seen.last() <= wire::SequenceTracker::kMaxJump);
  }
  return true;  // no input after it
}

// The default logger's lines, but those of one thread (the second half's):
// counted, never shown. One run says the lines a half would have said, in
// their order, so a second half that said any is not kept.
class SecondHalfLines : public spdlog::sinks::base_sink<std::mutex> {
 public:
  // In the default logger's place until Restore() (no other thread logging
  // as it comes and goes).
  static std::shared_ptr<SecondHalfLines> Installed() {
    auto lines = std::make_shared<SecondHalfLines>();
    lines->logger_->sinks() = {lines};
    return lines;
  }
  SecondHalfLines() : logger_(spdlog::default_logger()), sinks_(logger_->sinks()) {}
  void Restore() { logger_->sinks() = sinks_; }
  // The calling thread's lines are held from now on.
  void HoldThisThread() { held_ = std::this_thread::get_id(); }
  int held_lines() const { return held_lines_; }

 protected:
  void sink_it_(const spdlog::details::log_msg& m) override {
    if (std::this_thread::get_id() == held_.load()) {
      ++held_lines_;
      return;
    }
    for (const spdlog::sink_ptr& s : sinks_)
      if (s->should_log(m.level)) s->log(m);
  }
  void flush_() override {
    for (const spdlog::sink_ptr& s : sinks_) s->flush();
  }

 private:
  std::shared_ptr<spdlog::logger> logger_;
  std::vector<spdlog::sink_ptr> sinks_;
  std::atomic<std::thread::id> held_{};
  std::atomic<int> held_lines_ = 0;
};

// The two halves at once (RunAndCompare): true, with the outputs and the
// result, when both agree with the recording, each in its own range of
// frames; false otherwise (the second not started, or anything differing),
// `first` then having run through the state at the split (checked there).
bool RunInHalves(const LabConfig& config, const Recording& rec, const Plan& plan, std::size_t split,
                 const Progress& progress, OtherCore* other, DcpRunner* first, Outputs* out,
                 ResimResult* result) {
  const std::size_t n = plan.steps.size();
  const dcp_state_t& at = *plan.steps[split].state;
  // The recorded frames made after the state at the split: the second half's.
  const std::int64_t boundary = at.next_frame;
  const std::size_t begin = plan.first, end = rec.dcp_frames.size();
  const std::size_t middle = static_cast<std::size_t>(
      std::lower_bound(rec.dcp_frames.begin() + static_cast<std::ptrdiff_t>(begin),
                       rec.dcp_frames.end(), boundary,
                       [](const RecordedDcpFrame& f, std::int64_t b) { return f.frame < b; }) -
      rec.dcp_frames.begin());
  std::optional<DcpRunner> second;
  ResimResult second_result;
  bool second_agrees = false;
  const auto lines = SecondHalfLines::Installed();
  struct Restore {
    SecondHalfLines* lines;
    ~Restore() { lines->Restore(); }
  } restore{lines.get()};
  other->Start([&] {
    lines->HoldThisThread();
    second.emplace(config, rec, "", false, n - split);
    second->StartFrom(at, &second_result);
    second->Run(plan, split + 1, n, -1, {}, &second_result);
    second_agrees =
        HalfAgrees(rec, plan, middle, end, boundary, INT64_MAX, *second, &second_result);
  });
  ResimResult whole;
  bool first_agrees = false;
  try {
    first->Run(plan, 0, split + 1, -1, progress, result);  // through the state at the split
    whole = *result;
    first_agrees = ContinuesAsLogged(plan, split, first->node()) &&
                   HalfAgrees(rec, plan, begin, middle, INT64_MIN, boundary, *first, &whole);
  } catch (...) {
    other->Finish();  // the other half refers to this frame's variables
    throw;
  }
  if (!other->Finish() || other->error() || !first_agrees || !second_agrees ||
      lines->held_lines() > 0)
    return false;
  whole.compared += second_result.compared;
  whole.identical += second_result.identical;
  whole.states_checked += second_result.states_checked;
  whole.states_taken += second_result.states_taken - 1;  // its start is no state the DCP took
  for (const DcpRunner* half : {first, &*second}) {      // each in order, the second after
    out->frame_verdicts.insert(out->frame_verdicts.end(), half->frame_verdicts.begin(),
                               half->frame_verdicts.end());
    out->telemetry_verdicts.insert(out->telemetry_verdicts.end(), half->telemetry_verdicts.begin(),
                                   half->telemetry_verdicts.end());
  }
  *result = std::move(whole);
  return true;
}

// The DCP's own receive warnings ("gap: 250 frames missing before frame
// 750 ...") over the stretches the plan already names (Plan::unchecked,
// said once in the result's note) are not said again with other numbers,
// unless asked for (--verbose: the info level).
class QuietOverNamedGaps {
 public:
  explicit QuietOverNamedGaps(const Plan& plan) : was_(spdlog::get_level()) {
    if (!plan.unchecked.empty() && was_ > spdlog::level::info)
      spdlog::set_level(spdlog::level::err);
  }
  ~QuietOverNamedGaps() { spdlog::set_level(was_); }
  QuietOverNamedGaps(const QuietOverNamedGaps&) = delete;
  QuietOverNamedGaps& operator=(const QuietOverNamedGaps&) = delete;

 private:
  spdlog::level::level_enum was_;
};

}  // namespace

Outputs RunAndCompare(const LabConfig& config, const Recording& rec, const Plan& plan,
                      const RunOptions& options, ResimResult* result) {
  const std::size_t n = plan.steps.size();
  const bool whole_own_run = !options.other_design && options.out_log.empty() &&
                             options.until_frame < 0 && options.other_core;
  // (A plan that goes on past frames lost from every source runs as one.)
  const std::size_t split = whole_own_run && plan.unchecked.empty() ? SplitStep(plan) : 0;
  const auto t_run = Clock::now();
  DcpRunner first(config, rec, options.out_log, options.other_design, n);
  const QuietOverNamedGaps quiet(plan);
  Outputs out;
  if (split > 0 && RunInHalves(config, rec, plan, split, options.progress, options.other_core,
                               &first, &out, result)) {
    result->run_seconds = std::chrono::duration<double>(Clock::now() - t_run).count();
    result->frames = static_cast<long>(out.frame_verdicts.size());
    result->in_halves = true;
    return out;
  }
  // One run (or the first half on through the second).
  first.Run(plan, split > 0 ? split + 1 : 0, n, options.until_frame, options.progress, result);
  if (!options.out_log.empty()) first.FinishLog(options.out_log);
  result->run_seconds = std::chrono::duration<double>(Clock::now() - t_run).count();
  if (options.until_frame >= 0)
    result->checkpoint_text = wire::CheckpointText(first.node().MakeCheckpoint());
  out = Collect(&first, options.other_design && options.out_log.empty());
  result->frames = static_cast<long>(out.frame_verdicts.size());
  CompareWithRecording(rec, plan, options.until_frame, out, result);
  if (!result->out_dir.empty()) {
    transport::WriteStatsJson((fs::path(result->out_dir) / "stats" / "dynamics_proc.json").string(),
                              "dynamics_proc", first.node().counters(), first.node().latencies());
  }
  return out;
}

}  // namespace rms::resim
