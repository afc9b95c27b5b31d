#pragma once
// The operator's hand controllers (docs/operator.md "Devices"): the keyboard
// of a terminal, a gamepad or joystick through SDL2, a 3D mouse through
// libspnav (spacenavd). Each is optional, looked for at start and reported;
// what each control does is in config/bindings.toml.
//
// A device reports, each frame, what the operator asks for: steps (a key
// press moves an input by its step), rates (a deflected axis or a held
// button moves an input at up to its max rate), a velocity of System Two
// (the 3D mouse, resolved rate) and discrete events (camera, reset,
// overlay). ManualControl (manual_control.h) conditions and combines them.
#include <array>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "bindings.h"
#include "rms/input_block.h"

namespace rms::op {

struct DeviceCommands {
  std::array<double, kNumAnalogInputs> step{};  // units of each input, this frame
  std::array<double, kNumAnalogInputs> rate{};  // units a second
  Eigen::Vector3d v_R_ft_s = Eigen::Vector3d::Zero();    // System Two's translation, Reference frame
  Eigen::Vector3d w_S2_deg_s = Eigen::Vector3d::Zero();  // System Two's rotation about its own axes
  std::vector<Action> events;                    // camera, reset, overlay, quit
};

class InputDevice {
 public:
  virtual ~InputDevice() = default;
  // "keyboard (this terminal)", "gamepad: Xbox 360 Controller", ...
  virtual std::string Describe() const = 0;
  // Adds this frame's commands.
  virtual void Poll(DeviceCommands* out) = 0;
  // False once the device went away (unplugged); the station reports it.
  virtual bool connected() const { return true; }
};

// Deadband: |x| below `band` reads 0; beyond it the rest of the travel is
// rescaled so full deflection still reads 1.
double ApplyDeadband(double x, double band);

// The keyboard: keys from `next_key` (a key code, or -1 when none is
// pending: TerminalKeys::Next for a terminal; tests give their own).
class KeyboardDevice : public InputDevice {
 public:
  KeyboardDevice(const Bindings& bindings, std::function<int()> next_key, std::string where = "this terminal");
  std::string Describe() const override { return "keyboard (" + where_ + ")"; }
  void Poll(DeviceCommands* out) override;
  long unbound_keys() const { return unbound_; }

 private:
  const Bindings& b_;
  std::function<int()> next_key_;
  std::string where_;
  long unbound_ = 0;
};

// The first SDL2 game controller (a gamepad or a joystick SDL knows a
// mapping for). Open() returns nothing, with the reason in *why, when SDL
// finds none.
class GamepadDevice : public InputDevice {
 public:
  static std::unique_ptr<GamepadDevice> Open(const Bindings& bindings, std::string* why);
  ~GamepadDevice() override;
  std::string Describe() const override;
  void Poll(DeviceCommands* out) override;
  bool connected() const override;

 private:
  GamepadDevice(const Bindings& bindings, void* controller);
  const Bindings& b_;
  void* controller_;  // SDL_GameController*
  std::map<std::string, bool> was_down_;
};

// A 3D mouse through spacenavd (libspnav's AF_UNIX protocol; SPNAV_SOCKET
// names another socket). Open() returns nothing, with the reason, when
// there is no daemon or libspnav was not built in.
class SpaceMouseDevice : public InputDevice {
 public:
  static std::unique_ptr<SpaceMouseDevice> Open(const Bindings& bindings, std::string* why);
  ~SpaceMouseDevice() override;
  std::string Describe() const override { return "3D mouse (spacenavd)"; }
  void Poll(DeviceCommands* out) override;

 private:
  explicit SpaceMouseDevice(const Bindings& bindings) : b_(bindings) {}
  const Bindings& b_;
  std::array<double, 6> axes_{};  // tx, ty, tz, rx, ry, rz: the last motion event, counts
  std::map<int, bool> held_;
};

}  // namespace rms::op
