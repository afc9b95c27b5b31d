#include "rms/operator_station/devices.h"

#include <SDL2/SDL.h>
#include <algorithm>
#include <cmath>
#include <spdlog/spdlog.h>

#ifdef RMSLAB_HAVE_SPNAV
#include <spnav.h>
#endif

namespace rms::operator_station {

double ApplyDeadband(double x, double band) {
  const double a = std::abs(x);
  if (a <= band) return 0.0;
  return std::copysign(std::min(1.0, (a - band) / (1.0 - band)), x);
}

namespace {

bool Moves(const Action& a) { return a.kind == ActionKind::kHand || a.kind == ActionKind::kInput; }

// An action that stops every motion (HandControllers::HandleEvents): a
// press before it in the same frame is undone by it, so it is dropped here
// -- the frame's keys act in the order they came.
bool StopsMotion(const Action& a) {
  switch (a.kind) {
    case ActionKind::kStop:
    case ActionKind::kMode:
    case ActionKind::kFrame:
    case ActionKind::kVernier:
    case ActionKind::kJointNext:
    case ActionKind::kJointPrev:
    case ActionKind::kReset:
      return true;
    default:
      return false;
  }
}

void DropEarlierPresses(DeviceCommands* out) {
  out->hand_presses.clear();
  out->input_presses.clear();
}

// A control held down: an axis or an input at full rate.
void AddHeld(const Action& a, DeviceCommands* out) {
  if (a.kind == ActionKind::kHand)
    out->hand[a.index] += a.sign;
  else if (a.kind == ActionKind::kInput)
    out->input_rate[a.index] += a.sign;
}

// A control that went down this frame: a discrete action fires once.
void AddPressed(const Action& a, DeviceCommands* out) {
  ++out->key_actions;
  if (!Moves(a)) out->events.push_back(a);
}

// An analog axis, deadband applied.
void AddAxis(const AxisBinding& b, double deflection, double deadband, DeviceCommands* out) {
  const double v = b.sign * ApplyDeadband(std::clamp(deflection, -1.0, 1.0), deadband);
  if (b.hand)
    out->hand[b.index] += v;
  else
    out->input_rate[b.index] += v;
}

}  // namespace

// ---- a terminal's keyboard ----

KeyboardDevice::KeyboardDevice(const Bindings& bindings, std::function<int()> next_key,
                               std::string where)
    : b_(bindings), next_key_(std::move(next_key)), where_(std::move(where)) {}

void KeyboardDevice::Poll(DeviceCommands* out) {
  for (int k = next_key_(); k >= 0; k = next_key_()) {
    const auto it = b_.keys.find(k);
    if (it == b_.keys.end()) {
      // Said once a key, so a person knows the press did nothing.
      if (unbound_seen_.insert(k).second)
        spdlog::info("key '{}' is not bound to anything ({})", wire::KeyName(k), b_.source);
      ++unbound_;
      continue;
    }
    const Action& a = it->second;
    ++out->key_actions;
    if (StopsMotion(a)) DropEarlierPresses(out);
    if (a.kind == ActionKind::kHand)
      out->hand_presses.push_back({a.index, a.sign});
    else if (a.kind == ActionKind::kInput)
      out->input_presses.push_back({a.index, a.sign});
    else
      out->events.push_back(a);
  }
}

// ---- the live window's keyboard ----

WindowKeyboardDevice::WindowKeyboardDevice(const Bindings& bindings, std::int64_t timeout_us)
    : b_(bindings), timeout_us_(timeout_us) {}

bool WindowKeyboardDevice::Receive(const Message& m, std::int64_t now_us) {
  if (m.sender_pid != 0 && sender_pid_ != 0 && m.sender_pid != sender_pid_) {
    // A new window (esg_renderer restarted): its own numbering, from 0.
    sequence_ = wire::SequenceTracker{};
    held_.clear();
    ++new_windows_;
    spdlog::warn(
        "window keys: a new live window (esg_renderer pid {}, was {}); its keys are taken from now "
        "on",
        m.sender_pid, sender_pid_);
  }
  if (m.sender_pid != 0) sender_pid_ = m.sender_pid;
  const wire::SequenceTracker::Verdict v = sequence_.Accept(m.sequence);
  if (v == wire::SequenceTracker::Verdict::kDuplicate ||
      v == wire::SequenceTracker::Verdict::kStale ||
      v == wire::SequenceTracker::Verdict::kFarAhead) {
    return false;
  }
  if (v == wire::SequenceTracker::Verdict::kResync) {
    spdlog::warn(
        "window keys: sequence numbers resynchronised at {} (the window restarted, or {} was not "
        "real)",
        m.sequence, last_sequence_);
  }
  last_sequence_ = m.sequence;
  heard_us_ = now_us;
  held_.clear();
  if (m.focused) held_.insert(m.held.begin(), m.held.end());
  pressed_.insert(pressed_.end(), m.pressed.begin(), m.pressed.end());
  return true;
}

void WindowKeyboardDevice::Poll(DeviceCommands* out) {
  for (int k : pressed_) {
    const auto it = b_.keys.find(k);
    if (it == b_.keys.end()) continue;
    if (StopsMotion(it->second)) DropEarlierPresses(out);
    AddPressed(it->second, out);
    // A direct input's key down is a terminal's press too (a tap of the
    // finger key closes it all the way); held, it moves on at its rate.
    if (it->second.kind == ActionKind::kInput)
      out->input_presses.push_back({it->second.index, it->second.sign});
  }
  pressed_.clear();
  if (!held_.empty() && now_us_ - heard_us_ > timeout_us_) {
    // The window went quiet with keys held (closed, stalled, the link
    // lost): let go of everything rather than fly on.
    held_.clear();
    ++timeouts_;
  }
  for (int k : held_) {
    const auto it = b_.keys.find(k);
    if (it != b_.keys.end()) AddHeld(it->second, out);
  }
}

// ---- gamepad (SDL2) ----

std::unique_ptr<GamepadDevice> GamepadDevice::Open(const Bindings& bindings, std::string* why) {
  // No window: events must come without focus.
  SDL_SetHint(SDL_HINT_JOYSTICK_ALLOW_BACKGROUND_EVENTS, "1");
  if (SDL_InitSubSystem(SDL_INIT_GAMECONTROLLER) != 0) {
    *why = std::string("SDL cannot start its game controller support: ") + SDL_GetError();
    return nullptr;
  }
  const int n = SDL_NumJoysticks();
  for (int i = 0; i < n; ++i) {
    if (!SDL_IsGameController(i)) continue;
    if (SDL_GameController* c = SDL_GameControllerOpen(i))
      return std::unique_ptr<GamepadDevice>(new GamepadDevice(bindings, c));
  }
  *why = n == 0 ? "no gamepad or joystick found"
                : std::to_string(n) +
                      " joystick(s) found, none with a game controller mapping SDL knows";
  SDL_QuitSubSystem(SDL_INIT_GAMECONTROLLER);
  return nullptr;
}

GamepadDevice::GamepadDevice(const Bindings& bindings, void* controller)
    : b_(bindings), controller_(controller) {}

GamepadDevice::~GamepadDevice() {
  SDL_GameControllerClose(static_cast<SDL_GameController*>(controller_));
  SDL_QuitSubSystem(SDL_INIT_GAMECONTROLLER);
}

std::string GamepadDevice::Describe() const {
  const char* name = SDL_GameControllerName(static_cast<SDL_GameController*>(controller_));
  return std::string("gamepad: ") + (name ? name : "(unnamed)");
}

bool GamepadDevice::connected() const {
  return SDL_GameControllerGetAttached(static_cast<SDL_GameController*>(controller_)) == SDL_TRUE;
}

void GamepadDevice::Poll(DeviceCommands* out) {
  auto* c = static_cast<SDL_GameController*>(controller_);
  SDL_GameControllerUpdate();
  for (const auto& [name, bind] : b_.gamepad_axes) {
    const SDL_GameControllerAxis axis = SDL_GameControllerGetAxisFromString(name.c_str());
    AddAxis(bind, SDL_GameControllerGetAxis(c, axis) / 32767.0, b_.deadband, out);
  }
  for (const auto& [name, action] : b_.gamepad_buttons) {
    const bool down =
        SDL_GameControllerGetButton(c, SDL_GameControllerGetButtonFromString(name.c_str())) != 0;
    if (down && !was_down_[name]) AddPressed(action, out);
    if (down) AddHeld(action, out);
    was_down_[name] = down;
  }
}

// ---- 3D mouse (libspnav) ----

#ifdef RMSLAB_HAVE_SPNAV
std::unique_ptr<SpaceMouseDevice> SpaceMouseDevice::Open(const Bindings& bindings,
                                                         std::string* why) {
  if (spnav_open() == -1) {
    *why =
        "no 3D mouse (spacenavd is not running, or no socket at $SPNAV_SOCKET or "
        "/var/run/spnav.sock)";
    return nullptr;
  }
  return std::unique_ptr<SpaceMouseDevice>(new SpaceMouseDevice(bindings));
}

SpaceMouseDevice::~SpaceMouseDevice() { spnav_close(); }

void SpaceMouseDevice::Poll(DeviceCommands* out) {
  spnav_event ev;
  while (spnav_poll_event(&ev) != 0) {
    if (ev.type == SPNAV_EVENT_MOTION) {
      const int v[6] = {ev.motion.x,  ev.motion.y,  ev.motion.z,
                        ev.motion.rx, ev.motion.ry, ev.motion.rz};
      for (int i = 0; i < 6; ++i) axes_[i] = v[i];
    } else if (ev.type == SPNAV_EVENT_BUTTON) {
      const auto it = b_.spacemouse_buttons.find(ev.button.bnum);
      if (it == b_.spacemouse_buttons.end()) continue;
      const bool was = held_[ev.button.bnum];
      held_[ev.button.bnum] = ev.button.press != 0;
      if (ev.button.press && !was) AddPressed(it->second, out);
    }
  }
  for (const auto& [bnum, down] : held_) {
    const auto it = b_.spacemouse_buttons.find(bnum);
    if (down && it != b_.spacemouse_buttons.end()) AddHeld(it->second, out);
  }
  for (int i = 0; i < 6; ++i)
    AddAxis(b_.spacemouse_axes[i], axes_[i] / b_.spacemouse_full_scale, b_.deadband, out);
}
#else
std::unique_ptr<SpaceMouseDevice> SpaceMouseDevice::Open(const Bindings&, std::string* why) {
  *why = "3D mouse support not built in (libspnav-dev was missing at build time)";
  return nullptr;
}
SpaceMouseDevice::~SpaceMouseDevice() = default;
void SpaceMouseDevice::Poll(DeviceCommands*) {}
#endif

}  // namespace rms::operator_station
