#pragma once
// The operator's devices' bindings and signal conditioning, from
// config/bindings.toml (docs/operator.md "Bindings" documents every key).
// Every key is required, as in config/rmslab.toml; errors name the file, the
// key and the reason.
#include <array>
#include <map>
#include <string>
#include <string_view>

#include "rms/input_block.h"

namespace rms::op {

// What a key, a button or an axis does.
enum class ActionKind {
  kIncrease,    // an input up (a key: one step; a button: at its max rate while held)
  kDecrease,    // an input down
  kCamera,      // select camera station `camera`
  kCameraNext,  // the next station (8 wraps to 1)
  kCameraPrev,
  kReset,       // the reset pushbutton (one frame)
  kOverlay,     // the overlay switch (toggles)
  kQuit,        // stop the station (keyboard only)
  kFreeze,      // freeze the session, or run it again (RMS_CONTROL)
  kStep,        // while frozen: one frame (RMS_CONTROL)
};
struct Action {
  ActionKind kind = ActionKind::kQuit;
  int input = -1;   // kIncrease / kDecrease: the analog input
  int camera = 0;   // kCamera: 1..8
};
// "shoulder_yaw+", "finger-", "camera_3", "camera_next", "camera_prev",
// "reset", "overlay", "quit", "freeze", "step". Throws rms::InputError naming
// the text.
Action ParseAction(std::string_view text);

// Keys after escape-sequence decoding that are not plain characters.
enum SpecialKey : int { kKeyUp = 256, kKeyDown, kKeyLeft, kKeyRight };
// "q", "1", "+", "space", "up", "down", "left", "right", "plus", "minus":
// the key code, or -1 for a name that is no key.
int KeyCode(std::string_view name);

// An analog axis bound to an input: full deflection moves it at its max rate.
struct AxisBinding {
  int input = -1;
  double sign = 1.0;  // "-shoulder_pitch": pushing the stick up (negative) raises the pitch
};

struct Bindings {
  std::string source;  // the file

  // [conditioning]
  double deadband = 0.1;                                   // analog axes: this fraction of full deflection reads as 0
  std::array<double, kNumAnalogInputs> max_rate{};          // units of each input a second

  // [keyboard]
  std::array<double, kNumAnalogInputs> key_step{};          // what one key press moves each input
  std::map<int, Action> keys;                               // key code -> action

  // [gamepad] (SDL2 game controller names)
  std::map<std::string, AxisBinding> gamepad_axes;          // "leftx" -> input
  std::map<std::string, Action> gamepad_buttons;            // "a" -> action

  // [spacemouse] (resolved rate: the 3D mouse moves System Two)
  double spacemouse_full_scale = 350.0;                     // device counts at full deflection
  double spacemouse_speed_ft_s = 1.0;                       // System Two's speed at full deflection
  double spacemouse_turn_deg_s = 6.0;                       // System Two's turn rate at full deflection
  // Device axes tx, ty, tz -> Reference axes (0 X_R, 1 Y_R, 2 Z_R) with signs;
  // rx, ry, rz -> rotations about System Two's axes (0 X2 roll, 1 Y2, 2 Z2).
  std::array<AxisBinding, 3> spacemouse_translate{};
  std::array<AxisBinding, 3> spacemouse_rotate{};
  std::map<int, Action> spacemouse_buttons;                 // button number -> action
};

std::string DefaultBindingsPath();
Bindings LoadBindings(const std::string& path);
Bindings ParseBindings(std::string_view toml_text, const std::string& source);

}  // namespace rms::op
