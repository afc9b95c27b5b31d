#pragma once
// The operator station's sources of inputs, one per kind (docs/operator.md):
// a timeline file, the hand controllers (a person), the autopilot. The
// station (operator_station.h) asks its one source for each frame's inputs;
// everything a source needs to know of the session comes in the Frame.
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rms/base/config.h"
#include "rms/base/counters.h"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/operator_state_t.hpp"
#include "rms/operator_station/autopilot.h"
#include "rms/operator_station/bindings.h"
#include "rms/operator_station/hand_controllers.h"
#include "rms/operator_station/keyboard.h"
#include "rms/operator_station/timeline.h"
#include "rms/wire/input_block.h"

namespace rms::operator_station {

// What a source knows of this frame.
struct Frame {
  std::int64_t count = 0;  // frames this source has produced so far
  double dt_s = 0.0;       // session time a frame (1 / the frame rate)
  const dcp_telemetry_t* telemetry =
      nullptr;              // the DCP's newest (fresh since a reset or restore), or null
  std::int64_t now_us = 0;  // the station's clock (the transport's)
};

// What a source asks of the session, besides its inputs.
struct Requests {
  bool quit = false;    // stop the station (a person's quit key)
  bool freeze = false;  // freeze the session, or run it again
  int steps = 0;        // frames to step while frozen
};

class InputSource {
 public:
  virtual ~InputSource() = default;
  // For the status screen: "timeline mission.tl", "by hand", "autopilot: approach".
  virtual std::string Describe() const = 0;
  virtual std::int8_t kind() const = 0;  // operator_state_t::SOURCE_*
  // The next frame's inputs; nothing when the source is done.
  virtual std::optional<wire::OperatorInputs> Next(const Frame& f) = 0;
  // Frozen: no frames; only the session's own keys (freeze, step, quit).
  virtual void WhileFrozen() {}
  // Carry on from these inputs: a restored checkpoint, or the telemetry's
  // command after this station was restarted mid-session.
  virtual void Resume(const wire::OperatorInputs& in, bool from_checkpoint) = 0;
  virtual Requests requests() const { return {}; }
  // The station's exit code when the source is done (0: its task is done).
  virtual int exit_code() const { return 0; }
  // Its counters, added to the station's at the end.
  virtual void AddCounters(Counters* c) const { (void)c; }
  // What the hand controllers do (by hand only), for the screen and the
  // operator state message.
  virtual const HandControllers* hand() const { return nullptr; }
  // Devices found and not found, for the screen.
  virtual std::vector<std::string> devices() const { return {}; }
  // Keys to show at the screen's foot, and each action's keys ("thc_x+" ->
  // "w") for the screen's hints.
  virtual std::string help() const { return ""; }
  virtual std::map<std::string, std::string> key_hints() const { return {}; }
  // The live window's keyboard, fed from RMS_WINDOW_KEYS (by hand only).
  virtual WindowKeyboardDevice* window_keyboard() { return nullptr; }
};

class TimelineSource : public InputSource {
 public:
  TimelineSource(const std::string& path, const LabConfig& config, double speed, bool hold);
  std::string Describe() const override { return "timeline " + path_; }
  std::int8_t kind() const override { return operator_state_t::SOURCE_TIMELINE; }
  std::optional<wire::OperatorInputs> Next(const Frame& f) override;
  void Resume(const wire::OperatorInputs&, bool) override {}

 private:
  std::string path_;
  Timeline timeline_;
  double speed_;
  bool hold_;
  double prev_t_ = -1.0;
};

struct HandOptions {
  std::string bindings_path;       // empty: config/bindings.toml
  bool keyboard_required = false;  // --keyboard: this terminal's keyboard or refuse
  bool gamepad = true, spacemouse = true;
  bool window = true;  // listen for the live window's keys (RMS_WINDOW_KEYS)
  // Stop this long (session time, s) after the DCP first says docked: a
  // study's trial ends at docking (docs/studies.md). Negative: never.
  double end_when_docked_s = -1;
};

class HandSource : public InputSource {
 public:
  HandSource(const LabConfig& config, const HandOptions& options);
  std::string Describe() const override { return "by hand"; }
  std::int8_t kind() const override { return operator_state_t::SOURCE_BY_HAND; }
  std::optional<wire::OperatorInputs> Next(const Frame& f) override;
  void WhileFrozen() override;
  void Resume(const wire::OperatorInputs& in, bool from_checkpoint) override;
  Requests requests() const override { return requests_; }
  void AddCounters(Counters* c) const override;
  const HandControllers* hand() const override { return hands_.get(); }
  std::vector<std::string> devices() const override { return device_report_; }
  std::string help() const override { return help_; }
  std::map<std::string, std::string> key_hints() const override;
  WindowKeyboardDevice* window_keyboard() override { return window_; }
  const Bindings& bindings() const { return bindings_; }

 private:
  Bindings bindings_;
  std::unique_ptr<TerminalKeys> terminal_;
  std::unique_ptr<HandControllers> hands_;
  WindowKeyboardDevice* window_ = nullptr;  // owned by hands_
  std::vector<std::string> device_report_;
  std::string help_;
  Requests requests_;
  double end_when_docked_s_ = -1;
  double docked_s_ = 0;  // session time since the DCP first said docked
};

class AutopilotSource : public InputSource {
 public:
  AutopilotSource(const LabConfig& config, const AutopilotOptions& options, bool hold,
                  bool resume_from_telemetry);
  std::string Describe() const override;
  std::int8_t kind() const override { return operator_state_t::SOURCE_AUTOPILOT; }
  std::optional<wire::OperatorInputs> Next(const Frame& f) override;
  void Resume(const wire::OperatorInputs& in, bool from_checkpoint) override;
  int exit_code() const override;
  void AddCounters(Counters* c) const override;
  const Autopilot& autopilot() const { return autopilot_; }

 private:
  const LabConfig& config_;
  Autopilot autopilot_;
  bool hold_;
  bool resume_from_telemetry_;
  std::int64_t docked_frames_ = 0;
};

// The key map in one line: "w/s thc_x  d/a thc_y ... space stop ...".
std::string KeyHelp(const Bindings& b);
// Each action's keys, by the action's name ("thc_x+" -> "w"; several
// comma-separated): the status screen's hints.
std::map<std::string, std::string> KeyHints(const Bindings& b);

}  // namespace rms::operator_station
