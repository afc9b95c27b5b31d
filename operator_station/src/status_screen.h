#pragma once
// The operator's live status screen in the terminal (docs/operator.md
// "The status screen"): mode, active collisions, the six acquisition
// conditions, docking distance and angle, the camera station with pan /
// tilt / zoom, the arm's angles, shoulder height and finger, the frame
// rates and the end-to-end latency, the devices and the last log lines;
// redrawn every frame. While it is up, log lines go to the screen (and are
// written out when it closes, so none is lost).
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rms/config.h"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/input_block.h"

namespace rms::op {

struct StatusSnapshot {
  std::string source;                  // "keyboard", "autopilot: approach", "timeline mission.tl"
  std::int64_t frame = 0;              // the operator frame just published
  OperatorInputs inputs;               // as published
  std::optional<dcp_telemetry_t> telemetry;  // the newest from the DCP
  double publish_hz = 0.0;             // operator frames a second, measured
  double telemetry_hz = 0.0;           // DCP telemetry frames a second, measured
  double input_to_dcp_ms = -1.0;       // this block's round trip through the DCP (-1: none yet)
  double render_hz = -1.0;             // esg_renderer's frames a second (from RMS_STATUS; -1: not heard)
  double input_to_render_p50_ms = -1.0, input_to_render_p99_ms = -1.0;  // esg_renderer's end to end
  long clamped_inputs = 0;             // inputs clamped to their range so far
  std::vector<std::string> devices;    // what is connected
  std::vector<std::string> log;        // the last log lines
  std::string help;                    // the key map, one line
};

// The screen as text: lines of at most `width` characters.
std::string RenderStatusScreen(const StatusSnapshot& s, const LabConfig& config, int width = 100);

// Draws the screen on the terminal (alternate screen, cursor hidden) and
// captures the log meanwhile. Restores both on destruction.
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

}  // namespace rms::op
