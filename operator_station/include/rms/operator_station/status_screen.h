#pragma once
// The operator's live status screen in the terminal (docs/operator.md
// "The status screen"): the mode; the hand controllers' control mode, frame,
// scale and motion; guidance -- the offset to the target in the command
// frame's axes, the key that closes each, every acquisition condition with
// its margin, the docking distance and angle; collisions; the camera; the
// arm; the frame rates and the end-to-end latency; the devices; and the
// session's events (acquired, clear of the bay, docked, collisions, holds,
// resets, ...) in a pane that takes the rest of the terminal's height. The
// screen follows the terminal's width and height. While it is up, log lines
// go to the pane (and are written out when it closes, so none is lost).
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rms/base/config.h"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/operator_station/guidance.h"
#include "rms/operator_station/hand_controllers.h"
#include "rms/wire/input_block.h"

namespace rms::operator_station {

struct StatusSnapshot {
  std::string source;           // "by hand", "autopilot: approach", "timeline mission.tl"
  std::int64_t frame = 0;       // the operator frame just published
  double session_s = 0.0;       // session time: frames published over the rate
  wire::OperatorInputs inputs;  // as published
  std::optional<dcp_telemetry_t> telemetry;  // the DCP's newest since the last reset or restore
  std::optional<Guidance> guidance;          // from that telemetry
  std::optional<HandStatus> hand;            // by hand: what the hand controllers do
  std::map<std::string, std::string> keys;   // action name ("thc_x+") -> its keys, for hints
  bool show_guidance = true;                 // the window's guidance overlay
  long key_actions = -1;                     // by hand: presses so far
  double publish_hz = 0.0;                   // operator frames a second, measured
  double telemetry_hz = 0.0;                 // DCP telemetry frames a second, measured
  double input_to_dcp_ms = -1.0;  // this block's round trip through the DCP (-1: none yet)
  double render_hz = -1.0;        // esg_renderer's frames a second (from RMS_STATUS; -1: not heard)
  double input_to_render_p50_ms = -1.0, input_to_render_p99_ms = -1.0;  // esg_renderer's end to end
  std::uint32_t not_following =
      0;                    // FollowWatch::failing(): bit p, joint p (6: the finger, 7: the arm)
  long clamped_inputs = 0;  // inputs clamped to their range so far
  std::vector<std::string> devices;  // what is connected
  std::vector<std::string> log;      // the session's events and log lines, oldest first
  std::string help;                  // the key map, one line (wrapped to the width)
};

// The smallest terminal the screen fits; a smaller one is told so.
inline constexpr int kMinWidth = 60, kMinHeight = 20;

// The screen as text: lines of at most `width` characters, at most `height`
// lines (the log pane takes what is left, at least 3 lines).
std::string RenderStatusScreen(const StatusSnapshot& s, const LabConfig& config, int width = 100,
                               int height = 48);

// Draws the screen on the terminal (alternate screen, cursor hidden) at the
// terminal's size, and captures the log meanwhile. Restores both on
// destruction.
class StatusScreen {
 public:
  explicit StatusScreen(const LabConfig& config);
  ~StatusScreen();
  StatusScreen(const StatusScreen&) = delete;
  StatusScreen& operator=(const StatusScreen&) = delete;
  void Draw(StatusSnapshot snapshot);

 private:
  struct LogCapture;
  const LabConfig& config_;
  std::unique_ptr<LogCapture> capture_;
};

}  // namespace rms::operator_station
