#include "devices.h"

#include <SDL2/SDL.h>

#include <cmath>

#ifdef RMSLAB_HAVE_SPNAV
#include <spnav.h>
#endif

namespace rms::op {

double ApplyDeadband(double x, double band) {
  const double a = std::abs(x);
  if (a <= band) return 0.0;
  return std::copysign(std::min(1.0, (a - band) / (1.0 - band)), x);
}

namespace {

// A held control bound to INPUT+ / INPUT- moves the input at its max rate;
// other actions fire once, when pressed.
void Apply(const Bindings& b, const Action& a, bool down, bool was_down, DeviceCommands* out) {
  if (a.kind == ActionKind::kIncrease || a.kind == ActionKind::kDecrease) {
    if (down) out->rate[a.input] += (a.kind == ActionKind::kIncrease ? 1.0 : -1.0) * b.max_rate[a.input];
  } else if (down && !was_down) {
    out->events.push_back(a);
  }
}

}  // namespace

// ---- keyboard ----

KeyboardDevice::KeyboardDevice(const Bindings& bindings, std::function<int()> next_key, std::string where)
    : b_(bindings), next_key_(std::move(next_key)), where_(std::move(where)) {}

void KeyboardDevice::Poll(DeviceCommands* out) {
  for (int k = next_key_(); k >= 0; k = next_key_()) {
    const auto it = b_.keys.find(k);
    if (it == b_.keys.end()) {
      ++unbound_;
      continue;
    }
    const Action& a = it->second;
    if (a.kind == ActionKind::kIncrease) out->step[a.input] += b_.key_step[a.input];
    else if (a.kind == ActionKind::kDecrease) out->step[a.input] -= b_.key_step[a.input];
    else out->events.push_back(a);
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
    if (SDL_GameController* c = SDL_GameControllerOpen(i)) return std::unique_ptr<GamepadDevice>(new GamepadDevice(bindings, c));
  }
  *why = n == 0 ? "no gamepad or joystick found"
                : std::to_string(n) + " joystick(s) found, none with a game controller mapping SDL knows";
  SDL_QuitSubSystem(SDL_INIT_GAMECONTROLLER);
  return nullptr;
}

GamepadDevice::GamepadDevice(const Bindings& bindings, void* controller) : b_(bindings), controller_(controller) {}

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
    const double raw = SDL_GameControllerGetAxis(c, axis) / 32767.0;
    out->rate[bind.input] += bind.sign * ApplyDeadband(std::clamp(raw, -1.0, 1.0), b_.deadband) * b_.max_rate[bind.input];
  }
  for (const auto& [name, action] : b_.gamepad_buttons) {
    const bool down = SDL_GameControllerGetButton(c, SDL_GameControllerGetButtonFromString(name.c_str())) != 0;
    Apply(b_, action, down, was_down_[name], out);
    was_down_[name] = down;
  }
}

// ---- 3D mouse (libspnav) ----

#ifdef RMSLAB_HAVE_SPNAV
std::unique_ptr<SpaceMouseDevice> SpaceMouseDevice::Open(const Bindings& bindings, std::string* why) {
  if (spnav_open() == -1) {
    *why = "no 3D mouse (spacenavd is not running, or no socket at $SPNAV_SOCKET or /var/run/spnav.sock)";
    return nullptr;
  }
  return std::unique_ptr<SpaceMouseDevice>(new SpaceMouseDevice(bindings));
}

SpaceMouseDevice::~SpaceMouseDevice() { spnav_close(); }

void SpaceMouseDevice::Poll(DeviceCommands* out) {
  spnav_event ev;
  while (spnav_poll_event(&ev) != 0) {
    if (ev.type == SPNAV_EVENT_MOTION) {
      const int v[6] = {ev.motion.x, ev.motion.y, ev.motion.z, ev.motion.rx, ev.motion.ry, ev.motion.rz};
      for (int i = 0; i < 6; ++i) axes_[i] = v[i];
    } else if (ev.type == SPNAV_EVENT_BUTTON) {
      const auto it = b_.spacemouse_buttons.find(ev.button.bnum);
      if (it == b_.spacemouse_buttons.end()) continue;
      const bool was = held_[ev.button.bnum];
      held_[ev.button.bnum] = ev.button.press != 0;
      if (ev.button.press && !was && it->second.kind != ActionKind::kIncrease &&
          it->second.kind != ActionKind::kDecrease) {
        out->events.push_back(it->second);
      }
    }
  }
  for (const auto& [bnum, down] : held_) {
    const auto it = b_.spacemouse_buttons.find(bnum);
    if (down && it != b_.spacemouse_buttons.end()) Apply(b_, it->second, true, true, out);
  }
  for (int i = 0; i < 3; ++i) {
    const double t = ApplyDeadband(std::clamp(axes_[i] / b_.spacemouse_full_scale, -1.0, 1.0), b_.deadband);
    const double r = ApplyDeadband(std::clamp(axes_[3 + i] / b_.spacemouse_full_scale, -1.0, 1.0), b_.deadband);
    out->v_R_ft_s[b_.spacemouse_translate[i].input] += b_.spacemouse_translate[i].sign * t * b_.spacemouse_speed_ft_s;
    out->w_S2_deg_s[b_.spacemouse_rotate[i].input] += b_.spacemouse_rotate[i].sign * r * b_.spacemouse_turn_deg_s;
  }
}
#else
std::unique_ptr<SpaceMouseDevice> SpaceMouseDevice::Open(const Bindings&, std::string* why) {
  *why = "3D mouse support not built in (libspnav-dev was missing at build time)";
  return nullptr;
}
SpaceMouseDevice::~SpaceMouseDevice() = default;
void SpaceMouseDevice::Poll(DeviceCommands*) {}
#endif

}  // namespace rms::op
