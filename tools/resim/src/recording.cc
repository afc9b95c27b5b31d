#include "recording.h"

#include <algorithm>

#include "rms/base/check.h"
#include "rms/session/session_summary.h"
#include "rms/wire/channels.h"

namespace rms::resim {

Recording ReadRecording(session::SessionLog& log) {
  Recording r;
  r.suffix = log.suffix();
  log.Read({wire::channels::kOperatorInput, wire::channels::kDcpFrame,
            wire::channels::kDcpTelemetry, wire::channels::kDcpState},
           [&](const session::LogMessage& ev) {
             if (ev.base == wire::channels::kOperatorInput) {
               operator_input_t m;
               if (!log.Decode(ev, &m)) return;
               const auto* p = static_cast<const std::uint8_t*>(ev.data);
               r.inputs.push_back(
                   {m.frame, ev.log_us, r.input_bytes.size(), static_cast<std::size_t>(ev.size)});
               r.input_bytes.insert(r.input_bytes.end(), p, p + ev.size);
             } else if (ev.base == wire::channels::kDcpFrame) {
               dcp_frame_t m;
               if (log.Decode(ev, &m)) r.dcp_frames.push_back(m);
             } else if (ev.base == wire::channels::kDcpTelemetry) {
               r.telemetry.emplace_back();
               if (!log.Decode(ev, &r.telemetry.back())) r.telemetry.pop_back();
             } else {
               LoggedState st;
               st.before = r.dcp_frames.size();
               if (log.Decode(ev, &st.m)) r.states.push_back(std::move(st));
             }
           });
  SortByFrame(&r.inputs);
  SortByFrame(&r.telemetry);
  if (r.dcp_frames.empty()) {
    throw InputError(log.log_path() + ": no RMS_DCP_FRAME recorded: nothing to re-simulate");
  }
  // Only the DCP's increasing run of frames, as the summary believes them: a
  // frame forged far ahead or behind is not one the DCP made.
  std::vector<std::int64_t> numbers;
  for (const auto& f : r.dcp_frames) numbers.push_back(f.frame);
  const std::vector<std::size_t> run = session::LongestIncreasingRun(numbers);
  if (run.size() != r.dcp_frames.size()) {
    std::vector<dcp_frame_t> kept;
    for (const std::size_t i : run) kept.push_back(r.dcp_frames[i]);
    // A state keeps its place: the number of kept frames before it.
    for (auto& st : r.states) {
      st.before = static_cast<std::size_t>(std::lower_bound(run.begin(), run.end(), st.before) -
                                           run.begin());
    }
    r.dcp_frames = std::move(kept);
  }
  return r;
}

std::map<std::int64_t, dcp_telemetry_t> TelemetryByFrame(const std::vector<dcp_telemetry_t>& v) {
  std::map<std::int64_t, dcp_telemetry_t> m;
  for (const auto& t : v) m.emplace_hint(m.end(), t.frame, t);
  return m;
}

namespace {

std::string Frames(std::int64_t a, std::int64_t b) {
  return a == b ? "DCP frame " + std::to_string(a)
                : "DCP frames " + std::to_string(a) + ".." + std::to_string(b);
}

// Where the re-simulation can start: the state logged before the first
// frame (the DCP sends it at start and until its first frame), or, when the
// log begins later, the first state logged (every 5 s of frames); a log from
// frame 0 with no state at all (recorded before RMS_DCP_STATE) starts from
// the initial state.
const LoggedState* StartState(const Recording& r, Plan* plan) {
  const LoggedState* start = nullptr;
  for (const LoggedState& st : r.states) {
    if (st.before == 0) start = &st;
  }
  if (start) return start;
  const std::int64_t first = r.dcp_frames.front().frame;
  if (r.states.empty()) {
    if (first == 0) return nullptr;
    throw InputError(
        "the log starts at DCP frame " + std::to_string(first) +
        " and holds no RMS_DCP_STATE: the DCP's state there is not in it (the log misses the "
        "session's start, and was recorded before the DCP logged its state), so nothing can be "
        "re-simulated");
  }
  start = &r.states.front();
  if (start->before >= r.dcp_frames.size()) {
    throw InputError(
        "the log's only RMS_DCP_STATE comes after its last DCP frame: nothing to re-simulate from");
  }
  plan->first = start->before;
  const std::int64_t skipped_to = r.dcp_frames[plan->first].frame - 1;
  plan->note =
      Frames(first, skipped_to) + " not re-simulated: the log starts at DCP frame " +
      std::to_string(first) +
      " without the DCP's state there; re-simulated from the state it logged before DCP frame " +
      std::to_string(r.dcp_frames[plan->first].frame);
  return start;
}

}  // namespace

Plan MakePlan(const Recording& r) {
  Plan plan;
  const LoggedState* start = StartState(r, &plan);
  std::int64_t prev_frame = -1, prev_input = -1;
  bool pending_resume = false;
  // Where a state leaves the numbering: the next frame's, or (a resumed
  // process) the first frame after it sets it.
  auto take = [&](const dcp_state_t& m, bool first) {
    plan.steps.push_back({&m, -1, first});
    if (m.reason == dcp_state_t::PERIODIC && !first) return;
    pending_resume = m.resume_pending;
    prev_frame = m.next_frame - 1;
    prev_input = m.input_frame;
  };
  if (start) take(start->m, true);
  std::size_t next_state = start ? static_cast<std::size_t>(start - r.states.data()) + 1 : 0;
  for (std::size_t k = plan.first; k < r.dcp_frames.size(); ++k) {
    for (; next_state < r.states.size() && r.states[next_state].before <= k; ++next_state) {
      if (r.states[next_state].before == k) take(r.states[next_state].m, false);
    }
    const dcp_frame_t& f = r.dcp_frames[k];
    if (pending_resume) {  // the first frame after a resume: nothing between was made
      prev_frame = f.frame - 1;
      pending_resume = false;
    }
    const std::int64_t lost = f.frame - prev_frame - 1;
    if (lost > 0) {
      // The DCP answered `lost` inputs between prev_input and this frame's
      // that the log does not show: unambiguous only if exactly that many
      // were logged.
      std::vector<std::int64_t> between;
      auto it =
          std::upper_bound(r.inputs.begin(), r.inputs.end(), prev_input,
                           [](std::int64_t f, const RecordedInput& in) { return f < in.frame; });
      for (; it != r.inputs.end() && it->frame < f.input_frame; ++it) between.push_back(it->frame);
      if (static_cast<std::int64_t>(between.size()) != lost) {
        throw InputError("the log lost " + Frames(prev_frame + 1, f.frame - 1) +
                         " and which operator frames they answered cannot be told (" +
                         std::to_string(between.size()) +
                         " logged between): the re-simulation cannot be exact");
      }
      for (const std::int64_t in : between) plan.steps.push_back({nullptr, in, false});
    } else if (lost < 0) {
      throw InputError("DCP frame " + std::to_string(f.frame) + " follows " +
                       Frames(prev_frame, prev_frame) +
                       " with no RMS_DCP_STATE between to say why: the log cannot be re-simulated");
    }
    plan.steps.push_back({nullptr, f.input_frame, false});
    prev_frame = f.frame;
    prev_input = f.input_frame;
  }
  return plan;
}

}  // namespace rms::resim
