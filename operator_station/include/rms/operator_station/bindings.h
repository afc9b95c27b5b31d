#pragma once
// The operator's devices' bindings, the hand controllers' rates and the
// conditioning, from config/bindings.toml (docs/operator.md "Bindings"
// documents every key). Every key is required, as in config/rmslab.toml;
// errors name the file, the key and the reason.
#include <array>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "rms/operator_station/control_modes.h"
#include "rms/wire/input_block.h"
#include "rms/wire/key_codes.h"

namespace rms::operator_station {

// What a key, a button or an axis does.
enum class ActionKind {
  kHand,        // a hand-controller axis (index: HandAxis) in the direction `sign`
  kInput,       // a direct input (index: finger, shoulder height, camera pan / tilt / zoom), `sign`
  kCamera,      // select camera station `camera`
  kCameraNext,  // the next station (8 wraps to 1)
  kCameraPrev,
  kReset,       // the reset pushbutton (one frame): back to Mode 1
  kOverlay,     // the ESG overlay switch (frame counter, indicators): toggles
  kCrosshairs,  // the crosshairs on the wrist and port cameras: toggles
  kGuidance,    // the guidance overlay in the live window: toggles
  kStop,        // every commanded motion stops at once
  kMode,        // the next control mode (single joint <-> manual augmented)
  kFrame,       // the next command frame (end effector, orbiter, payload once held)
  kVernier,     // the next rate scale: coarse, vernier, fine, coarse ...
  kNull,        // fly hand-controller axis `index` to its guidance's 0, and stop there
  kSquareUp,    // fly the whole turn the guidance shows, in one rotation, and stop
  kUnwind,      // fly the wrist's three joints to the middle of their travel
  kStow,        // Mode 1: fly every joint back to where the session started it
  kJointNext,   // single joint: the next joint (wrist roll wraps to shoulder yaw)
  kJointPrev,
  kQuit,    // stop the station (keyboards only)
  kFreeze,  // freeze the session, or run it again (RMS_CONTROL)
  kStep,    // while frozen: one frame (RMS_CONTROL)
};
struct Action {
  ActionKind kind = ActionKind::kQuit;
  int index = -1;  // kHand, kNull: the HandAxis; kInput: the analog input (kFinger .. kCameraZoom)
  double sign = 1.0;  // kHand, kInput: +1 or -1
  int camera = 0;     // kCamera: 1..8
};
// "thc_x+", "rhc_yaw-", "finger+", "camera_pan-", "camera_3", "camera_next",
// "camera_prev", "reset", "overlay", "crosshairs", "guidance", "stop", "mode",
// "frame", "vernier", "null_thc_x" .. "null_rhc_yaw", "square_up", "unwind",
// "stow", "joint_next", "joint_prev", "quit", "freeze", "step".
// Throws rms::InputError naming the text.
Action ParseAction(std::string_view text);
// The inverse, for help lines and logs.
std::string ActionName(const Action& a);

// An analog axis (gamepad stick or trigger, 3D mouse axis): full deflection
// is a hand-controller axis at full rate, or a direct input at its max rate.
struct AxisBinding {
  bool hand = true;   // a hand-controller axis (else a direct input)
  int index = -1;     // HandAxis, or the analog input
  double sign = 1.0;  // "-thc_x": deflection the other way
};

// The hand controllers' full-scale rates, coarse and vernier (the fine
// scale flies at vernier's; docs/operator.md "Rates").
struct HandRates {
  double coarse_ft_s = 0, coarse_deg_s = 0;  // manual augmented: translation, rotation
  double vernier_ft_s = 0, vernier_deg_s = 0;
  double joint_coarse_deg_s = 0, joint_vernier_deg_s = 0;  // single joint
};

// What one key press of a terminal moves (a terminal has no key-up: each
// press is a fixed increment, flown at the scale's rate).
struct HandIncrements {
  double coarse_ft = 0, coarse_deg = 0;
  double vernier_ft = 0, vernier_deg = 0;
  double joint_coarse_deg = 0, joint_vernier_deg = 0;
  // The fine scale's (optional keys; defaults 0.05 ft, 0.2 deg, 0.1 deg).
  double fine_ft = 0.05, fine_deg = 0.2, joint_fine_deg = 0.1;
};

struct Bindings {
  std::string source;  // the file

  // [control]: how a by-hand session starts.
  ControlMode initial_mode = ControlMode::kManualAugmented;
  CommandFrame initial_frame = CommandFrame::kEndEffector;
  RateScale initial_scale = RateScale::kCoarse;
  // The camera stations this operator may select (1..8, distinct; the first
  // is shown at the start): a study's condition gives a subject a camera
  // set (docs/studies.md "Conditions"). Every station when the key is absent.
  std::vector<int> cameras;

  // [conditioning]
  double deadband = 0.1;  // analog axes: this fraction of full deflection reads as 0
  // Units of each input a second: for the six joints, the fastest any
  // control mode turns them; for the direct inputs, their slew rate.
  std::array<double, kNumAnalogInputs> max_rate{};

  // [rates]
  HandRates rates;

  // [keyboard]
  HandIncrements increments;
  std::array<double, kNumAnalogInputs>
      key_step{};              // the direct inputs' step a press (joints unused)
  std::map<int, Action> keys;  // key code -> action

  // [gamepad] (SDL2 game controller names)
  std::map<std::string, AxisBinding> gamepad_axes;  // "leftx" -> axis
  std::map<std::string, Action> gamepad_buttons;    // "a" -> action

  // [spacemouse]: a 3D mouse is both hand controllers.
  double spacemouse_full_scale = 350.0;          // device counts at full deflection
  std::array<AxisBinding, 6> spacemouse_axes{};  // tx, ty, tz, rx, ry, rz
  std::map<int, Action> spacemouse_buttons;      // button number -> action
};

std::string DefaultBindingsPath();
Bindings LoadBindings(const std::string& path);
Bindings ParseBindings(std::string_view toml_text, const std::string& source);

}  // namespace rms::operator_station
