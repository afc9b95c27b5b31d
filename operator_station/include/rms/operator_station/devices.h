#pragma once
// The operator's hand controllers (docs/operator.md "Devices"): the
// keyboard of a terminal, the keyboard of the live window (over LCM from
// esg_renderer), a gamepad or joystick through SDL2, a 3D mouse through
// libspnav (spacenavd). Each is optional, looked for at start and reported;
// what each control does is in config/bindings.toml.
//
// A device reports, each frame, what the operator asks for: deflections of
// the hand controllers' six axes (sticks, the 3D mouse, keys held in the
// window), presses (a terminal's keys, which have no key-up), the direct
// inputs' rates and presses (finger, shoulder height, camera) and discrete
// events. HandControllers (hand_controllers.h) turns them into the inputs.
#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "rms/base/counters.h"
#include "rms/operator_station/bindings.h"
#include "rms/wire/frame_numbers.h"
#include "rms/wire/input_block.h"

namespace rms::operator_station {

struct Press {
  int index = 0;  // the HandAxis, or the analog input
  double sign = 1.0;
};

struct DeviceCommands {
  std::array<double, kNumHandAxes> hand{};  // deflection, [-1, 1] each
  std::vector<Press> hand_presses;          // a terminal's presses, in order
  std::array<double, kNumAnalogInputs>
      input_rate{};                  // direct inputs: fraction of max rate, [-1, 1]
  std::vector<Press> input_presses;  // a terminal's presses of direct inputs
  std::vector<Action> events;        // camera, mode, stop, reset, ...
  int key_actions = 0;               // keys and buttons pressed this frame
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

// A terminal's keyboard: keys from `next_key` (a key code, or -1 when none is
// pending: TerminalKeys::Next for a terminal; tests give their own). Each
// press is one increment (HandControllers merges presses faster than it can
// fly them).
class KeyboardDevice : public InputDevice {
 public:
  KeyboardDevice(const Bindings& bindings, std::function<int()> next_key,
                 std::string where = "this terminal");
  std::string Describe() const override { return "keyboard (" + where_ + ")"; }
  void Poll(DeviceCommands* out) override;
  long unbound_keys() const { return unbound_; }

 private:
  const Bindings& b_;
  std::function<int()> next_key_;
  std::string where_;
  long unbound_ = 0;
  std::set<int> unbound_seen_;
};

// The live window's keyboard (RMS_WINDOW_KEYS from esg_renderer): a held
// key moves its axis at full rate, a released one stops; discrete actions
// fire on key down. Keys not heard about for `timeout_us` are released.
class WindowKeyboardDevice : public InputDevice {
 public:
  struct Message {
    std::int64_t sequence = 0;
    std::vector<int> held, pressed;
    bool focused = true;
    std::int32_t sender_pid =
        0;  // the window's process (sender_t.pid); a new one numbers from 0 again
  };
  explicit WindowKeyboardDevice(const Bindings& bindings, std::int64_t timeout_us = 300000);
  std::string Describe() const override { return "keyboard (the live window)"; }
  // A message from the window, received at now_us. False (and counted by the
  // caller) when it is stale or a duplicate.
  bool Receive(const Message& m, std::int64_t now_us);
  // The time the next Poll is for (the station's clock, us).
  void SetNow(std::int64_t now_us) { now_us_ = now_us; }
  void Poll(DeviceCommands* out) override;
  long timeouts() const { return timeouts_; }
  bool heard() const { return last_sequence_ >= 0; }
  std::int64_t resyncs() const { return sequence_.resyncs(); }
  // Windows heard from after the first (esg_renderer restarted).
  long new_windows() const { return new_windows_; }

 private:
  const Bindings& b_;
  std::int64_t timeout_us_;
  std::int64_t now_us_ = 0, heard_us_ = 0, last_sequence_ = -1;
  // The window's sequence numbers (a restarted window, or a forged far-ahead
  // one, is followed again after a run of refusals: SequenceTracker).
  wire::SequenceTracker sequence_;
  std::int32_t sender_pid_ = 0;
  long new_windows_ = 0;
  std::set<int> held_;
  std::vector<int> pressed_;
  long timeouts_ = 0;
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
// names another socket): both hand controllers in one cap. Open() returns
// nothing, with the reason, when there is no daemon or libspnav was not
// built in.
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

}  // namespace rms::operator_station
