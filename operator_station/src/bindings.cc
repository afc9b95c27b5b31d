#include "rms/operator_station/bindings.h"

#include <SDL2/SDL_gamecontroller.h>
#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>

#include "rms/base/check.h"
#include "rms/base/config.h"
#include "rms/base/toml_reader.h"

#ifndef RMSLAB_DEFAULT_BINDINGS
#error "RMSLAB_DEFAULT_BINDINGS must be defined by the build"
#endif

namespace rms::operator_station {

std::string DefaultBindingsPath() { return RMSLAB_DEFAULT_BINDINGS; }

namespace {

// The direct inputs: the analog inputs a device moves itself (the six arm
// joints move only through the control modes).
bool IsDirectInput(int input) { return input >= kFinger && input < kNumAnalogInputs; }

struct Named {
  std::string_view name;
  ActionKind kind;
};
constexpr Named kNamedActions[] = {
    {"camera_next", ActionKind::kCameraNext},
    {"camera_prev", ActionKind::kCameraPrev},
    {"reset", ActionKind::kReset},
    {"overlay", ActionKind::kOverlay},
    {"crosshairs", ActionKind::kCrosshairs},
    {"guidance", ActionKind::kGuidance},
    {"stop", ActionKind::kStop},
    {"mode", ActionKind::kMode},
    {"frame", ActionKind::kFrame},
    {"vernier", ActionKind::kVernier},
    {"square_up", ActionKind::kSquareUp},
    {"unwind", ActionKind::kUnwind},
    {"stow", ActionKind::kStow},
    {"joint_next", ActionKind::kJointNext},
    {"joint_prev", ActionKind::kJointPrev},
    {"quit", ActionKind::kQuit},
    {"freeze", ActionKind::kFreeze},
    {"step", ActionKind::kStep},
};

}  // namespace

Action ParseAction(std::string_view t) {
  Action a;
  for (const Named& n : kNamedActions) {
    if (t == n.name) {
      a.kind = n.kind;
      return a;
    }
  }
  if (t.size() == 8 && t.substr(0, 7) == "camera_" && t[7] >= '1' &&
      t[7] < '1' + kNumCameraStations) {
    a.kind = ActionKind::kCamera;
    a.camera = t[7] - '0';
    return a;
  }
  if (t.substr(0, 5) == "null_" && (a.index = HandAxisIndex(t.substr(5))) >= 0) {
    a.kind = ActionKind::kNull;
    return a;
  }
  if (!t.empty() && (t.back() == '+' || t.back() == '-')) {
    const std::string_view base = t.substr(0, t.size() - 1);
    a.sign = t.back() == '+' ? 1.0 : -1.0;
    if ((a.index = HandAxisIndex(base)) >= 0) {
      a.kind = ActionKind::kHand;
      return a;
    }
    const int input = AnalogInputIndex(base);
    if (IsDirectInput(input)) {
      a.kind = ActionKind::kInput;
      a.index = input;
      return a;
    }
    if (input >= 0) {
      throw InputError(
          "\"" + std::string(t) +
          "\": the arm's joints move through the control modes (thc_x+ / thc_x- drive the joint "
          "joint_next and joint_prev select in single joint mode; docs/operator.md)");
    }
  }
  throw InputError(
      "unknown action \"" + std::string(t) +
      "\" (thc_x, thc_y, thc_z, rhc_roll, rhc_pitch, rhc_yaw, finger, shoulder_height, camera_pan, "
      "camera_tilt, camera_zoom with + or -; camera_1..camera_8, camera_next, camera_prev, reset, "
      "overlay, crosshairs, guidance, stop, mode, frame, vernier, null_ and an axis (null_thc_x .. "
      "null_rhc_yaw), square_up, unwind, stow, joint_next, joint_prev, quit, freeze, step)");
}

std::string ActionName(const Action& a) {
  const std::string sign = a.sign > 0 ? "+" : "-";
  switch (a.kind) {
    case ActionKind::kHand:
      return std::string(kHandAxisNames[a.index]) + sign;
    case ActionKind::kInput:
      return std::string(kAnalogInputNames[a.index]) + sign;
    case ActionKind::kCamera:
      return "camera_" + std::to_string(a.camera);
    case ActionKind::kNull:
      return "null_" + std::string(kHandAxisNames[a.index]);
    default:
      break;
  }
  for (const Named& n : kNamedActions) {
    if (n.kind == a.kind) return std::string(n.name);
  }
  return "?";
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

// "thc_x", "-rhc_yaw", "camera_pan": a hand-controller axis or a direct
// input, a leading '-' reversing it. hand_only: a 3D mouse axis.
AxisBinding AxisAt(TomlReader& r, std::string_view key, bool hand_only) {
  std::string text = r.String(key);
  AxisBinding b;
  if (!text.empty() && text[0] == '-') {
    b.sign = -1.0;
    text.erase(0, 1);
  }
  if ((b.index = HandAxisIndex(text)) >= 0) return b;
  const int input = AnalogInputIndex(text);
  if (!hand_only && IsDirectInput(input)) {
    b.hand = false;
    b.index = input;
    return b;
  }
  r.Fail(
      key,
      std::string(
          "must name a hand-controller axis (thc_x, thc_y, thc_z, rhc_roll, rhc_pitch, rhc_yaw)") +
          (hand_only ? ""
                     : " or a direct input (finger, shoulder_height, camera_pan, camera_tilt, "
                       "camera_zoom)") +
          ", a leading '-' reversing it; got \"" + text + "\"");
}

void ReadControl(TomlReader& top, Bindings* b) {
  TomlReader r = top.Sub("control");
  const std::string mode = r.String("mode");
  const auto m = ParseControlMode(mode);
  if (!m) r.Fail("mode", "must be \"manual_augmented\" or \"single_joint\", got \"" + mode + "\"");
  b->initial_mode = *m;
  const std::string frame = r.String("frame");
  const auto f = ParseCommandFrame(frame);
  if (!f || *f == CommandFrame::kPayload) {
    r.Fail("frame",
           "must be \"end_effector\" or \"orbiter\" (the payload's frame needs a payload held), "
           "got \"" +
               frame + "\"");
  }
  b->initial_frame = *f;
  const std::string scale = r.String("scale");
  const auto sc = ParseRateScale(scale);
  if (!sc) r.Fail("scale", "must be \"coarse\", \"vernier\" or \"fine\", got \"" + scale + "\"");
  b->initial_scale = *sc;
  b->cameras.clear();
  if (r.Has("cameras")) {
    const toml::array* a = r.Get("cameras")->as_array();
    if (a == nullptr) r.Fail("cameras", "must be an array of camera stations (e.g. [4, 7, 8])");
    for (const toml::node& n : *a) {
      const std::optional<std::int64_t> v = n.value<std::int64_t>();
      if (!n.is_integer() || !v || *v < 1 || *v > kNumCameraStations) {
        r.Fail("cameras", "must be camera stations, whole numbers 1.." +
                              std::to_string(kNumCameraStations) + " (e.g. [4, 7, 8])");
      }
      const int st = static_cast<int>(*v);
      if (std::find(b->cameras.begin(), b->cameras.end(), st) != b->cameras.end())
        r.Fail("cameras", "names station " + std::to_string(st) + " twice");
      b->cameras.push_back(st);
    }
    if (b->cameras.empty()) r.Fail("cameras", "must name at least one station (absent: all eight)");
  } else {
    for (int st = 1; st <= kNumCameraStations; ++st) b->cameras.push_back(st);
  }
  r.Finish();
}

void ReadRates(TomlReader& top, Bindings* b) {
  TomlReader r = top.Sub("rates");
  HandRates& h = b->rates;
  h.coarse_ft_s = r.Positive("coarse_ft_s", 100.0);
  h.coarse_deg_s = r.Positive("coarse_deg_s", 360.0);
  h.vernier_ft_s = r.Positive("vernier_ft_s", 100.0);
  h.vernier_deg_s = r.Positive("vernier_deg_s", 360.0);
  h.joint_coarse_deg_s = r.Positive("joint_coarse_deg_s", 360.0);
  h.joint_vernier_deg_s = r.Positive("joint_vernier_deg_s", 360.0);
  if (h.vernier_ft_s >= h.coarse_ft_s)
    r.Fail("vernier_ft_s", "must be less than rates.coarse_ft_s");
  if (h.vernier_deg_s >= h.coarse_deg_s)
    r.Fail("vernier_deg_s", "must be less than rates.coarse_deg_s");
  if (h.joint_vernier_deg_s >= h.joint_coarse_deg_s) {
    r.Fail("joint_vernier_deg_s", "must be less than rates.joint_coarse_deg_s");
  }
  r.Finish();
}

void ReadKeyboard(TomlReader& top, Bindings* b) {
  TomlReader r = top.Sub("keyboard");
  {
    TomlReader s = r.Sub("increment");
    HandIncrements& h = b->increments;
    h.coarse_ft = s.Positive("coarse_ft", 100.0);
    h.coarse_deg = s.Positive("coarse_deg", 180.0);
    h.vernier_ft = s.Positive("vernier_ft", 100.0);
    h.vernier_deg = s.Positive("vernier_deg", 180.0);
    h.joint_coarse_deg = s.Positive("joint_coarse_deg", 180.0);
    h.joint_vernier_deg = s.Positive("joint_vernier_deg", 180.0);
    if (s.Has("fine_ft")) h.fine_ft = s.Positive("fine_ft", 100.0);
    if (s.Has("fine_deg")) h.fine_deg = s.Positive("fine_deg", 180.0);
    if (s.Has("joint_fine_deg")) h.joint_fine_deg = s.Positive("joint_fine_deg", 180.0);
    s.Finish();
  }
  {
    TomlReader s = r.Sub("step");
    for (int i = kFinger; i < kNumAnalogInputs; ++i)
      b->key_step[i] = s.Positive(kAnalogInputNames[i]);
    s.Finish();
  }
  TomlReader k = r.Sub("keys");
  for (auto&& [key, node] : k.table()) {
    const std::string name(key.str());
    const int code = wire::KeyCode(name);
    if (code < 0) {
      k.Fail(name,
             "is not a key (a printable character, space, up, down, left, right, pageup, pagedown, "
             "backspace, tab, enter, plus, minus)");
    }
    if (b->keys.count(code)) k.Fail(name, "is bound twice");
    b->keys[code] = ActionAt(k, name);
  }
  k.Finish();
  // What a person needs to fly and to end the session has a key: every
  // hand-controller axis both ways, the finger, stop, the scale, the mode,
  // the frame and quit (docs/operator.md "Bindings: config/bindings.toml").
  std::set<std::string> bound;
  for (const auto& [code, a] : b->keys) bound.insert(ActionName(a));
  std::string missing;
  for (int i = 0; i < kNumHandAxes; ++i) {
    for (const char* sign : {"+", "-"}) {
      const std::string n = std::string(kHandAxisNames[i]) + sign;
      if (!bound.count(n)) missing += (missing.empty() ? "" : ", ") + n;
    }
  }
  for (const char* n : {"finger+", "finger-", "stop", "vernier", "mode", "frame", "quit"}) {
    if (!bound.count(n)) missing += (missing.empty() ? "" : ", ") + std::string(n);
  }
  if (!missing.empty()) {
    r.Fail("keys", "no key is bound to " + missing +
                       " (every one needs a key, e.g. Q = \"quit\"; see config/bindings.toml)");
  }
  r.Finish();
}

void ReadGamepad(TomlReader& top, Bindings* b) {
  TomlReader r = top.Sub("gamepad");
  TomlReader ax = r.Sub("axes");
  for (auto&& [key, node] : ax.table()) {
    const std::string name(key.str());
    if (SDL_GameControllerGetAxisFromString(name.c_str()) == SDL_CONTROLLER_AXIS_INVALID) {
      ax.Fail(name,
              "is not an SDL game controller axis (leftx, lefty, rightx, righty, lefttrigger, "
              "righttrigger)");
    }
    b->gamepad_axes[name] = AxisAt(ax, name, false);
  }
  ax.Finish();
  TomlReader bt = r.Sub("buttons");
  for (auto&& [key, node] : bt.table()) {
    const std::string name(key.str());
    if (SDL_GameControllerGetButtonFromString(name.c_str()) == SDL_CONTROLLER_BUTTON_INVALID) {
      bt.Fail(name,
              "is not an SDL game controller button (a, b, x, y, back, guide, start, leftstick, "
              "rightstick, "
              "leftshoulder, rightshoulder, dpup, dpdown, dpleft, dpright)");
    }
    b->gamepad_buttons[name] = ActionAt(bt, name);
    if (b->gamepad_buttons[name].kind == ActionKind::kQuit)
      bt.Fail(name, "quit is for the keyboards only");
  }
  bt.Finish();
  r.Finish();
}

void ReadSpaceMouse(TomlReader& top, Bindings* b) {
  TomlReader r = top.Sub("spacemouse");
  b->spacemouse_full_scale = r.Positive("full_scale", 1e5);
  TomlReader ax = r.Sub("axes");
  const char* dev[6] = {"tx", "ty", "tz", "rx", "ry", "rz"};
  for (int i = 0; i < 6; ++i) b->spacemouse_axes[i] = AxisAt(ax, dev[i], true);
  ax.Finish();
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
    b->spacemouse_buttons[n] = ActionAt(bt, name);
    if (b->spacemouse_buttons[n].kind == ActionKind::kQuit)
      bt.Fail(name, "quit is for the keyboards only");
  }
  bt.Finish();
  r.Finish();
}

}  // namespace

Bindings ParseBindings(std::string_view text, const std::string& source) {
  toml::table root = ParseToml(text, source);
  Bindings b;
  b.source = source;
  TomlReader top(&root, "", &b.source, "docs/operator.md");
  ReadControl(top, &b);
  {
    TomlReader r = top.Sub("conditioning");
    b.deadband = r.Number("deadband", 0.0, 0.9);
    TomlReader m = r.Sub("max_rate");
    for (int i = 0; i < kNumAnalogInputs; ++i) b.max_rate[i] = m.Positive(kAnalogInputNames[i]);
    m.Finish();
    r.Finish();
  }
  ReadRates(top, &b);
  ReadKeyboard(top, &b);
  ReadGamepad(top, &b);
  ReadSpaceMouse(top, &b);
  top.Finish();
  return b;
}

Bindings LoadBindings(const std::string& path) {
  return ParseBindings(ReadTextFile(path, "the bindings file"), path);
}

}  // namespace rms::operator_station
