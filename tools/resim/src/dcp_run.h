#pragma once
// The re-simulated DCP's run through the plan, and its comparison word for
// word with the recording (docs/sessions.md "Re-simulation").
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "rms/base/config.h"
#include "rms/base/other_core.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/resim/resim.h"
#include "rms/session/session_summary.h"

#include "recording.h"

namespace rms::resim {

// A re-simulated output (RMS_DCP_FRAME, RMS_DCP_TELEMETRY) against the
// recorded one of its frame, compared as it was sent: its bytes
// (SameButSenderAndTime).
struct Verdict {
  enum Kind : std::int8_t { kDiffers, kSame, kNoneRecorded };
  std::int64_t frame = 0;
  Kind kind = kNoneRecorded;
  std::string what;  // kDiffers: the first field that differs ("arm_words[3]", "telemetry")
};

// What the re-simulated DCP sent, in DCP frame order, one message a frame
// (the last sent, were there two); FindFrame looks one up. Its telemetry
// decoded for another design only (its comparison reads it). For a design
// made in memory, also all of it in the order sent, with its restores: what
// its summary is made from, as from a log of it.
struct Outputs {
  std::vector<Verdict> frame_verdicts, telemetry_verdicts;
  std::vector<dcp_telemetry_t> telemetry;
  session::DcpRun published;
};

struct RunOptions {
  std::string out_log;              // the new session's log ("" for none)
  bool other_design = false;        // the configuration is not the recorded one
  long until_frame = -1;            // the last DCP frame to make (-1: all)
  OtherCore* other_core = nullptr;  // for the two halves (below); null: one run
  std::function<void(double, const std::string&)> progress;
};

// The DCP's own node over a log-backed transport, step by step through the
// plan, then compared with the recording from the plan's first frame
// (result: frames, compared, identical, the differences, the states taken
// and checked, run_seconds, and with until_frame checkpoint_text).
// The session's own design, nothing written, to its end, with another core:
// run in two halves at once, the second from the periodic state logged
// nearest the middle, which the first half's end is checked against. Kept
// only when the whole agrees with the recording; otherwise the first half
// runs on through the second, as one run does: the result is one run's.
Outputs RunAndCompare(const LabConfig& config, const Recording& rec, const Plan& plan,
                      const RunOptions& options, ResimResult* result);

}  // namespace rms::resim
