#include "bindings.h"

#include <SDL2/SDL_gamecontroller.h>

#include <fstream>
#include <sstream>

#include "rms/check.h"
#include "rms/toml_reader.h"

#ifndef RMSLAB_DEFAULT_BINDINGS
#error "RMSLAB_DEFAULT_BINDINGS must be defined by the build"
#endif

namespace rms::op {

std::string DefaultBindingsPath() { return RMSLAB_DEFAULT_BINDINGS; }

Action ParseAction(std::string_view t) {
  Action a;
  if (t == "camera_next") a.kind = ActionKind::kCameraNext;
  else if (t == "camera_prev") a.kind = ActionKind::kCameraPrev;
  else if (t == "reset") a.kind = ActionKind::kReset;
  else if (t == "overlay") a.kind = ActionKind::kOverlay;
  else if (t == "quit") a.kind = ActionKind::kQuit;
  else if (t == "freeze") a.kind = ActionKind::kFreeze;
  else if (t == "step") a.kind = ActionKind::kStep;
  else if (t.size() == 8 && t.substr(0, 7) == "camera_" && t[7] >= '1' && t[7] <= '8') {
    a.kind = ActionKind::kCamera;
    a.camera = t[7] - '0';
  } else if (!t.empty() && (t.back() == '+' || t.back() == '-') && AnalogInputIndex(t.substr(0, t.size() - 1)) >= 0) {
    a.kind = t.back() == '+' ? ActionKind::kIncrease : ActionKind::kDecrease;
    a.input = AnalogInputIndex(t.substr(0, t.size() - 1));
  } else {
    throw InputError("unknown action \"" + std::string(t) +
                     "\" (INPUT+ / INPUT- for an analog input, camera_1..camera_8, camera_next, camera_prev, reset, "
                     "overlay, quit, freeze, step)");
  }
  return a;
}

int KeyCode(std::string_view n) {
  if (n == "space") return ' ';
  if (n == "plus") return '+';
  if (n == "minus") return '-';
  if (n == "up") return kKeyUp;
  if (n == "down") return kKeyDown;
  if (n == "left") return kKeyLeft;
  if (n == "right") return kKeyRight;
  if (n.size() == 1 && n[0] > ' ' && n[0] < 127) return static_cast<unsigned char>(n[0]);
  return -1;
}

namespace {

// An action from a string value, the error naming the key.
Action ActionAt(TomlReader& r, std::string_view key) {
  const std::string text = r.String(key);
  try {
    return ParseAction(text);
  } catch (const InputError& e) {
    r.Fail(key, e.what());
  }
}

AxisBinding AxisTo(TomlReader& r, std::string_view key, const std::array<std::string_view, 3>* names) {
  std::string text = r.String(key);
  AxisBinding b;
  if (!text.empty() && text[0] == '-') {
    b.sign = -1.0;
    text.erase(0, 1);
  }
  if (names) {
    for (int i = 0; i < 3; ++i) {
      if (text == (*names)[i]) b.input = i;
    }
    if (b.input < 0) {
      r.Fail(key, "must be one of " + std::string((*names)[0]) + ", " + std::string((*names)[1]) + ", " +
                      std::string((*names)[2]) + " (a leading '-' reverses it)");
    }
  } else {
    b.input = AnalogInputIndex(text);
    if (b.input < 0) r.Fail(key, "must name an analog input (a leading '-' reverses it), got \"" + text + "\"");
  }
  return b;
}

}  // namespace

Bindings ParseBindings(std::string_view text, const std::string& source) {
  toml::table root = ParseToml(text, source);
  Bindings b;
  b.source = source;
  const std::string doc = "docs/operator.md";
  TomlReader top(&root, "", &b.source, doc);
  {
    TomlReader r = top.Sub("conditioning");
    b.deadband = r.Number("deadband", 0.0, 0.9);
    TomlReader m = r.Sub("max_rate");
    for (int i = 0; i < kNumAnalogInputs; ++i) b.max_rate[i] = m.Positive(kAnalogInputNames[i]);
    m.Finish();
    r.Finish();
  }
  {
    TomlReader r = top.Sub("keyboard");
    TomlReader s = r.Sub("step");
    for (int i = 0; i < kNumAnalogInputs; ++i) b.key_step[i] = s.Positive(kAnalogInputNames[i]);
    s.Finish();
    TomlReader k = r.Sub("keys");
    for (auto&& [key, node] : k.table()) {
      const std::string name(key.str());
      const int code = KeyCode(name);
      if (code < 0) k.Fail(name, "is not a key (a printable character, space, up, down, left, right, plus, minus)");
      if (b.keys.count(code)) k.Fail(name, "is bound twice");
      b.keys[code] = ActionAt(k, name);
    }
    k.Finish();
    r.Finish();
  }
  {
    TomlReader r = top.Sub("gamepad");
    TomlReader ax = r.Sub("axes");
    for (auto&& [key, node] : ax.table()) {
      const std::string name(key.str());
      if (SDL_GameControllerGetAxisFromString(name.c_str()) == SDL_CONTROLLER_AXIS_INVALID) {
        ax.Fail(name, "is not an SDL game controller axis (leftx, lefty, rightx, righty, lefttrigger, righttrigger)");
      }
      b.gamepad_axes[name] = AxisTo(ax, name, nullptr);
    }
    ax.Finish();
    TomlReader bt = r.Sub("buttons");
    for (auto&& [key, node] : bt.table()) {
      const std::string name(key.str());
      if (SDL_GameControllerGetButtonFromString(name.c_str()) == SDL_CONTROLLER_BUTTON_INVALID) {
        bt.Fail(name, "is not an SDL game controller button (a, b, x, y, back, guide, start, leftstick, rightstick, "
                      "leftshoulder, rightshoulder, dpup, dpdown, dpleft, dpright)");
      }
      b.gamepad_buttons[name] = ActionAt(bt, name);
      if (b.gamepad_buttons[name].kind == ActionKind::kQuit) bt.Fail(name, "quit is for the keyboard only");
    }
    bt.Finish();
    r.Finish();
  }
  {
    TomlReader r = top.Sub("spacemouse");
    b.spacemouse_full_scale = r.Positive("full_scale", 1e5);
    b.spacemouse_speed_ft_s = r.Positive("speed_ft_s", 100.0);
    b.spacemouse_turn_deg_s = r.Positive("turn_deg_s", 360.0);
    static constexpr std::array<std::string_view, 3> kR = {"X", "Y", "Z"}, kS2 = {"X2", "Y2", "Z2"};
    TomlReader t = r.Sub("translate");
    const char* dev[3] = {"tx", "ty", "tz"};
    for (int i = 0; i < 3; ++i) b.spacemouse_translate[i] = AxisTo(t, dev[i], &kR);
    t.Finish();
    TomlReader o = r.Sub("rotate");
    const char* rdev[3] = {"rx", "ry", "rz"};
    for (int i = 0; i < 3; ++i) b.spacemouse_rotate[i] = AxisTo(o, rdev[i], &kS2);
    o.Finish();
    TomlReader bt = r.Sub("buttons");
    for (auto&& [key, node] : bt.table()) {
      const std::string name(key.str());
      int n = -1;
      try {
        std::size_t used = 0;
        n = std::stoi(name, &used);
        if (used != name.size()) n = -1;
      } catch (const std::exception&) {
      }
      if (n < 0 || n > 63) bt.Fail(name, "must be a button number 0..63");
      b.spacemouse_buttons[n] = ActionAt(bt, name);
    }
    bt.Finish();
    r.Finish();
  }
  top.Finish();
  return b;
}

Bindings LoadBindings(const std::string& path) { return ParseBindings(ReadTextFile(path, "the bindings file"), path); }

}  // namespace rms::op
