#include "recording.h"

#include <algorithm>
#include <filesystem>
#include <limits>
#include <set>
#include <string>
#include <tuple>

#include "rms/base/check.h"
#include "rms/session/sender_check.h"
#include "rms/session/session_summary.h"
#include "rms/wire/channels.h"
#include "rms/wire/message_io.h"

namespace rms::resim {

namespace {

// What one part of the log holds of the recording, as read.
void Keep(session::SessionLog& log, const session::LogMessage& ev, std::uint8_t part,
          Recording* r) {
  // A message kept as logged.
  auto keep = [&](std::int64_t frame) {
    std::vector<std::uint8_t>& bytes = r->bytes[part];
    const auto* p = static_cast<const std::uint8_t*>(ev.data);
    const RecordedMessage m{frame, ev.log_us, bytes.size(), static_cast<std::size_t>(ev.size),
                            part};
    bytes.insert(bytes.end(), p, p + ev.size);
    return m;
  };
  if (ev.base == wire::channels::kOperatorInput) {
    operator_input_t m;
    if (log.Decode(ev, &m)) r->inputs.push_back(keep(m.frame));
  } else if (ev.base == wire::channels::kDcpFrame) {
    std::int64_t frame = 0, input_frame = 0;
    if (log.Check<dcp_frame_t>(ev) && wire::ReadFrameNumber(ev.data, ev.size, &frame) &&
        wire::ReadInt64At(ev.data, ev.size, wire::kDcpFrameInputFrameAt, &input_frame))
      r->dcp_frames.push_back({keep(frame), input_frame});
  } else if (ev.base == wire::channels::kDcpTelemetry) {
    std::int64_t frame = 0;
    if (log.Check<dcp_telemetry_t>(ev) && wire::ReadFrameNumber(ev.data, ev.size, &frame))
      r->telemetry.push_back(keep(frame));
  } else {
    LoggedState st;
    st.before = r->dcp_frames.size();
    if (log.Decode(ev, &st.m)) r->states.push_back(std::move(st));
  }
}

// The second part's after the first's (its bytes stay where they are).
void Append(Recording&& second, Recording* r) {
  for (LoggedState& st : second.states) st.before += r->dcp_frames.size();
  auto append = [](auto& from, auto* to) {
    to->insert(to->end(), std::make_move_iterator(from.begin()),
               std::make_move_iterator(from.end()));
  };
  append(second.inputs, &r->inputs);
  append(second.dcp_frames, &r->dcp_frames);
  append(second.telemetry, &r->telemetry);
  append(second.states, &r->states);
  r->bytes[1] = std::move(second.bytes[1]);
}

// A state logged again (the network's second copy, in a log made from the
// wire alone) is the first one's: taken at its receive time it would stand
// after frames the DCP made after it.
void DropRepeatedStates(Recording* r) {
  using Key = std::tuple<std::int64_t, int, std::int64_t, std::string>;
  std::set<Key> seen;  // a set: a log of many states stays n log n
  std::vector<LoggedState> kept;
  kept.reserve(r->states.size());
  for (LoggedState& st : r->states) {
    if (seen.emplace(st.m.send_time_us, st.m.reason, st.m.next_frame, st.m.checkpoint).second)
      kept.push_back(std::move(st));
  }
  r->states = std::move(kept);
}

// What the sender check left out, said for a log with nothing to
// re-simulate (" (N messages ...)", or ""): a manifest whose session id is
// not the log's leaves out every message.
std::string LeftOut(const session::SenderCheck& check) {
  if (check.ignored_total() == 0) return "";
  const nlohmann::ordered_json j = check.Json();
  std::string why;
  for (const auto& [reason, n] : j["by_reason"].items())
    why += (why.empty() ? "" : ", ") + reason + " " + std::to_string(n.get<std::int64_t>());
  std::string others;
  for (const auto& id : j["other_sessions"])
    others += (others.empty() ? "" : ", ") + id.get<std::string>();
  return " (" + std::to_string(check.ignored_total()) +
         " messages left out as not the session's: " + why +
         (others.empty() ? ""
                         : "; sent by session " + others +
                               ", not the manifest's: is manifest.json this log's?") +
         ")";
}

// Of each DCP frame's telemetry, the first logged that answers the operator
// frame the (kept) DCP frame of its number answered, as the summary believes
// it (docs/security.md "What the summary trusts"); a frame with none keeps
// its first.
void KeepAnsweringTelemetry(Recording* r) {
  std::vector<std::int64_t> frames, inputs;
  for (const RecordedDcpFrame& f : r->dcp_frames) {
    frames.push_back(f.frame);
    inputs.push_back(f.input_frame);
  }
  SortByFrameKeeping(&r->telemetry, [&](auto first, auto last) {
    const auto at = std::lower_bound(frames.begin(), frames.end(), first->frame);
    if (last - first == 1 || at == frames.end() || *at != first->frame) return first;
    const std::int64_t want = inputs[static_cast<std::size_t>(at - frames.begin())];
    for (auto it = first; it != last; ++it) {
      std::int64_t input = -1;
      if (wire::ReadInt64At(r->BytesOf(*it), static_cast<int>(it->size),
                            wire::kDcpFrameInputFrameAt, &input) &&
          input == want)
        return it;
    }
    return first;
  });
}

}  // namespace

Recording ReadRecording(session::SessionLog& log, const session::SessionLog::TwoParts& parts) {
  Recording r, second;
  r.suffix = log.suffix();
  // The kept bytes are fewer than the log's: reserved once (pages not
  // written are not touched, up to 1 GiB), no copy as they grow.
  std::error_code ec;
  const std::uintmax_t log_bytes = std::filesystem::file_size(log.log_path(), ec);
  if (!ec) {
    r.bytes[0].reserve(static_cast<std::size_t>(std::min<std::uintmax_t>(log_bytes, 1u << 30)));
    second.bytes[1].reserve(static_cast<std::size_t>(std::min<std::uintmax_t>(
        static_cast<std::uintmax_t>(static_cast<double>(log_bytes) * parts.second_share) + 1,
        1u << 30)));
  }
  const bool in_two = log.ReadInTwo(
      {wire::channels::kOperatorInput, wire::channels::kDcpFrame, wire::channels::kDcpTelemetry,
       wire::channels::kDcpState},
      [&](int part, const session::LogMessage& ev) {
        Keep(log, ev, static_cast<std::uint8_t>(part), part == 0 ? &r : &second);
      },
      parts);
  if (in_two) Append(std::move(second), &r);
  r.read_in_two = in_two;
  DropRepeatedStates(&r);
  // The first of a frame's inputs: the one the live DCP took (a later copy
  // is a duplicate it dropped).
  SortByFrameKeeping(&r.inputs, [](auto first, auto) { return first; });
  if (r.dcp_frames.empty())
    throw InputError(log.log_path() + ": no RMS_DCP_FRAME recorded: nothing to re-simulate" +
                     LeftOut(log.check()));
  // Only the DCP's increasing run of frames, as the summary believes them: a
  // frame forged far ahead or behind is not one the DCP made.
  std::vector<std::int64_t> numbers;
  for (const auto& f : r.dcp_frames) numbers.push_back(f.frame);
  const std::vector<std::size_t> run = session::LongestIncreasingRun(numbers);
  if (run.size() != r.dcp_frames.size()) {
    std::vector<RecordedDcpFrame> kept;
    for (const std::size_t i : run) kept.push_back(r.dcp_frames[i]);
    // A state keeps its place: the number of kept frames before it.
    for (auto& st : r.states) {
      st.before = static_cast<std::size_t>(std::lower_bound(run.begin(), run.end(), st.before) -
                                           run.begin());
    }
    r.dcp_frames = std::move(kept);
  }
  KeepAnsweringTelemetry(&r);
  return r;
}

std::vector<dcp_telemetry_t> DecodedTelemetry(const Recording& r) {
  std::vector<dcp_telemetry_t> v;
  v.reserve(r.telemetry.size());
  for (const RecordedMessage& t : r.telemetry) v.push_back(r.Decoded<dcp_telemetry_t>(t));
  return v;
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

namespace {

// The inputs logged after `after` and before `before`, operator frames in order.
std::vector<std::int64_t> InputsBetween(const Recording& r, std::int64_t after,
                                        std::int64_t before) {
  std::vector<std::int64_t> between;
  auto it =
      std::upper_bound(r.inputs.begin(), r.inputs.end(), after,
                       [](std::int64_t f, const RecordedMessage& in) { return f < in.frame; });
  for (; it != r.inputs.end() && it->frame < before; ++it) between.push_back(it->frame);
  return between;
}

// Builds the plan frame by frame (MakePlan).
class Planner {
 public:
  explicit Planner(const Recording& r) : r_(r) {}

  Plan Make() {
    const LoggedState* start = StartState(r_, &plan_);
    if (start) Take(start->m, true);
    next_state_ = start ? static_cast<std::size_t>(start - r_.states.data()) + 1 : 0;
    for (std::size_t k = plan_.first; k < r_.dcp_frames.size();) k = Frame(k);
    return std::move(plan_);
  }

 private:
  // Where a state leaves the numbering: the next frame's, or (a resumed
  // process) the first frame after it sets it.
  void Take(const dcp_state_t& m, bool first) {
    plan_.steps.push_back({&m, -1, first});
    if (m.reason == dcp_state_t::PERIODIC && !first) return;
    pending_resume_ = m.resume_pending;
    prev_frame_ = m.next_frame - 1;
    prev_input_ = m.input_frame;
  }

  // Recorded DCP frame k, with the states logged before it; the index of
  // the next frame to plan.
  std::size_t Frame(std::size_t k) {
    const std::size_t steps_before = plan_.steps.size();
    const std::vector<const dcp_state_t*> periodic = TakeStatesBefore(k);
    const RecordedDcpFrame& f = r_.dcp_frames[k];
    if (pending_resume_) {  // the first frame after a resume: nothing between was made
      prev_frame_ = f.frame - 1;
      pending_resume_ = false;
    }
    const std::int64_t lost = f.frame - prev_frame_ - 1;
    std::string why;
    std::vector<std::int64_t> between;
    if (lost > 0) {
      // The DCP answered `lost` inputs between prev_input and this frame's
      // that the log does not show: unambiguous only if exactly that many
      // were logged.
      between = InputsBetween(r_, prev_input_, f.input_frame);
      if (static_cast<std::int64_t>(between.size()) != lost)
        why = "lost from every source, and which operator frames they answered cannot be told (" +
              std::to_string(between.size()) + " logged between)";
    } else if (lost < 0) {
      why = "DCP frame " + std::to_string(f.frame) + " follows DCP frame " +
            std::to_string(prev_frame_) + " with no RMS_DCP_STATE between to say why";
    }
    if (why.empty() && !FindFrame(r_.inputs, f.input_frame))
      why = "operator frame " + std::to_string(f.input_frame) + ", which DCP frame " +
            std::to_string(f.frame) + " answered, is not in the log";
    if (!why.empty())
      return Skip(k, steps_before, lost > 0 ? prev_frame_ + 1 : f.frame,
                  lost > 0 ? f.frame - 1 : f.frame, why);
    // A periodic state is checked before the frame it names: among the
    // frames filled in, not before them all (DCP frame 1049 lost, the state
    // before 1050 was checked before 1049 was made, and "differed").
    std::size_t p = 0;
    auto check_before = [&](std::int64_t frame) {
      for (; p < periodic.size() && periodic[p]->next_frame <= frame; ++p)
        plan_.steps.push_back({periodic[p], -1, false});
    };
    std::int64_t n = prev_frame_ + 1;
    if (!between.empty()) {
      plan_.filled_in += static_cast<std::int64_t>(between.size());
      if (plan_.first_filled_in < 0) plan_.first_filled_in = n;
      plan_.last_filled_in = f.frame - 1;
    }
    for (const std::int64_t in : between) {
      check_before(n++);
      plan_.steps.push_back({nullptr, in, false});
    }
    check_before(std::numeric_limits<std::int64_t>::max());
    plan_.steps.push_back({nullptr, f.input_frame, false});
    prev_frame_ = f.frame;
    prev_input_ = f.input_frame;
    return k + 1;
  }

  // Takes the states logged before recorded frame k; the periodic ones at
  // their end (checks, which change no numbering) are returned instead, to
  // be placed by the frame each names among frames the log lost.
  std::vector<const dcp_state_t*> TakeStatesBefore(std::size_t k) {
    std::vector<const dcp_state_t*> slot;
    for (; next_state_ < r_.states.size() && r_.states[next_state_].before <= k; ++next_state_) {
      if (r_.states[next_state_].before == k) slot.push_back(&r_.states[next_state_].m);
    }
    std::size_t take = slot.size();
    while (take > 0 && slot[take - 1]->reason == dcp_state_t::PERIODIC) --take;
    for (std::size_t i = 0; i < take; ++i) Take(*slot[i], false);
    return {slot.begin() + static_cast<std::ptrdiff_t>(take), slot.end()};
  }

  // Frames from recorded frame k on cannot be re-made from here: the run
  // goes on from the next state logged at or after k (the states of k taken
  // above are undone: the one to go on from is taken as a start), the
  // frames before it left unchecked. Returns the index to go on from.
  std::size_t Skip(std::size_t k, std::size_t steps_before, std::int64_t lost_from,
                   std::int64_t lost_to, const std::string& why) {
    plan_.steps.resize(steps_before);
    // A state taken to go on from, that frame k does not follow either, is
    // not taken again: the next one is.
    std::size_t s = min_state_;
    while (s < r_.states.size() && r_.states[s].before < k) ++s;
    Unchecked u{k, r_.dcp_frames.size(), lost_from, lost_to, why, -1};
    if (s < r_.states.size() && r_.states[s].before < r_.dcp_frames.size()) {
      u.end = r_.states[s].before;
      u.resumed_from = r_.states[s].m.next_frame;
      Take(r_.states[s].m, true);
      next_state_ = min_state_ = s + 1;
    } else {
      next_state_ = min_state_ = r_.states.size();
    }
    // The state gone on from last time was logged inside a lost stretch
    // (frames 500..700 lost, a state at 600; or two stretches, 530..560 and
    // 570..640, the state at 600 in the second) and frame k, where the run
    // was to go on, does not follow from it either: one stretch from the
    // first lost frame, not two that overlap.
    if (!plan_.unchecked.empty() && plan_.unchecked.back().end == k) {
      Unchecked& last = plan_.unchecked.back();
      u.begin = last.begin;
      u.lost_from = std::min(u.lost_from, last.lost_from);
      u.lost_to = std::max(u.lost_to, last.lost_to);
      last = u;
    } else {
      plan_.unchecked.push_back(u);
    }
    return u.end;
  }

  const Recording& r_;
  Plan plan_;
  std::size_t next_state_ = 0, min_state_ = 0;
  std::int64_t prev_frame_ = -1, prev_input_ = -1;
  bool pending_resume_ = false;
};

}  // namespace

Plan MakePlan(const Recording& r) { return Planner(r).Make(); }

}  // namespace rms::resim
