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
  std::vector<RecordedMessage> inputs;       // by operator frame (the first logged of a frame)
  std::vector<RecordedDcpFrame> dcp_frames;  // in log order, undecoded
  // By DCP frame, undecoded: of a frame's, the first logged that answers the
  // operator frame its DCP frame answered (else the first).
  std::vector<RecordedMessage> telemetry;
  std::vector<LoggedState> states;  // in log order
  bool read_in_two = false;         // the log read in two parts at once
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

// The same, keeping of each frame's messages the one `pick` chooses among
// [first, last) (in the order they were logged).
template <class Msg, class Pick>
void SortByFrameKeeping(std::vector<Msg>* v, const Pick& pick) {
  std::stable_sort(v->begin(), v->end(),
                   [](const Msg& a, const Msg& b) { return a.frame < b.frame; });
  std::vector<Msg> kept;
  kept.reserve(v->size());
  for (auto it = v->begin(); it != v->end();) {
    auto end = it + 1;
    while (end != v->end() && end->frame == it->frame) ++end;
    kept.push_back(std::move(*pick(it, end)));
    it = end;
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

// Recorded DCP frames the re-simulation could not check: lost from every
// source before them (a crash), so which inputs the DCP answered there
// cannot be told; the run goes on from the next state logged after them
// (docs/sessions.md "Re-simulation", "Through what is lost").
struct Unchecked {
  std::size_t begin = 0, end = 0;           // recorded DCP frames [begin, end), by index
  std::int64_t lost_from = 0, lost_to = 0;  // the DCP frames lost before them
  std::string why;
  std::int64_t resumed_from = -1;  // the DCP frame of the state gone on from; -1: none logged later
};

struct Plan {
  std::vector<Step> steps;
  std::size_t first = 0;  // the index of the first recorded DCP frame re-simulated
  std::string note;       // what the log lacks, when it does not start at the session's start
  std::vector<Unchecked> unchecked;  // in order, after `first`
  // DCP frames not in the log made again from the logged inputs they
  // answered (unambiguous: exactly as many logged between): nothing to
  // check them against.
  std::int64_t filled_in = 0, first_filled_in = -1, last_filled_in = -1;
  // Whether recorded DCP frame i is checked: at or after `first`, in no
  // unchecked stretch.
  bool Checked(std::size_t i) const {
    if (i < first) return false;
    for (const Unchecked& u : unchecked)
      if (i >= u.begin && i < u.end) return false;
    return true;
  }
};

// The operator frame each DCP frame answered, in DCP frame order, with the
// logged states in their places, and DCP frames the recorder lost filled in
// where that is unambiguous; where it is not (frames lost from every
// source), the stretch up to the next logged state is left unchecked
// (Plan::unchecked) and the run goes on from that state. Throws InputError
// only where nothing can be re-simulated.
Plan MakePlan(const Recording& r);

}  // namespace rms::resim
