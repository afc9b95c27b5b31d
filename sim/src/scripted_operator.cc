#include "rms/sim/scripted_operator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <regex>

#include "rms/wire/dcp_mode.h"

namespace rms::sim {

namespace {

constexpr const char* kAxisNames[6] = {"x", "y", "z", "roll", "pitch", "yaw"};
// The default bindings (config/bindings.toml): each axis's "+" and "-" key.
constexpr const char* kPlusKey[6] = {"w", "d", "f", "o", "k", "l"};
constexpr const char* kMinusKey[6] = {"s", "a", "r", "u", "i", "j"};

bool IsMotionKey(const std::string& k) {
  for (int i = 0; i < 6; ++i)
    if (k == kPlusKey[i] || k == kMinusKey[i]) return true;
  return false;
}

int AxisIndex(const std::string& name) {
  for (int i = 0; i < 6; ++i) {
    if (name == kAxisNames[i]) return i;
  }
  return -1;
}

std::string Fmt(const char* f, double a, double b = 0, double c = 0) {
  char buf[160];
  std::snprintf(buf, sizeof buf, f, a, b, c);
  return buf;
}

// "1 2 3 . 5 6": the conditions that hold.
std::string Conditions(const Screen& s) {
  std::string c;
  for (int i = 0; i < 6; ++i) {
    if (i > 0) c.push_back(' ');
    c.push_back(s.condition[i] ? static_cast<char>('1' + i) : '.');
  }
  return c;
}

}  // namespace

Screen ParseScreen(const std::string& text) {
  // Compiled once (a sweep parses a screen a look: thousands a flight).
  static const std::regex kTimeRe(R"(t ([\d.]+) s  frame)");
  static const std::regex kModeRe(R"(MODE (\d))");
  static const std::regex kFrameRe(R"(frame: (end effector|orbiter|payload))");
  static const std::regex kFingerStopRe(R"(the finger would stop at ([\d.]+) ft: (below|NOT))");
  static const std::regex kClearOfBayRe(R"(clear of the bay by ([\d.]+) ft)");
  static const std::regex kInBayRe(R"(in the bay: ([\d.]+) ft to lift it clear)");
  static const std::regex kDockDistanceRe(R"(DOCKING distance ([\d.]+) ft)");
  static const std::regex kDockAngleRe(R"(angle ([\d.]+) deg \(<=)");
  Screen s;
  s.valid = text.find("rmslab operator station") != std::string::npos;
  if (!s.valid) return s;
  std::smatch m;
  if (std::regex_search(text, m, kTimeRe)) s.t_s = std::stod(m[1]);
  if (std::regex_search(text, m, kModeRe)) s.mode = std::stoi(m[1]);
  s.acquired = text.find("acquired YES") != std::string::npos;
  s.docked = text.find("docked YES") != std::string::npos;
  s.held = text.find("arm HELD") != std::string::npos;
  if (std::regex_search(text, m, kFrameRe)) s.frame = m[1];
  static const std::regex kScaleRe(R"(scale: (COARSE|VERNIER|FINE))");
  if (std::regex_search(text, m, kScaleRe)) s.scale = m[1];
  s.vernier = s.scale == "VERNIER" || s.scale == "FINE";
  static const std::regex kAngleRe(R"(angle ([\d.]+) deg(?! \())");
  if (std::regex_search(text, m, kAngleRe)) s.angle = std::stod(m[1]);
  s.squaring = text.find("SQUARING UP") != std::string::npos;
  s.unwinding = text.find("UNWINDING") != std::string::npos;
  s.stowing = text.find("STOWING") != std::string::npos;
  s.near_limit = text.find("WRIST NEAR ITS LIMIT") != std::string::npos;
  s.would_acquire = text.find("CLOSING THE FINGER NOW ACQUIRES") != std::string::npos;
  s.clearance_warning = text.find("CLEARANCE WARNING") != std::string::npos;
  static const std::regex kTurnClearRe(
      R"(over the turn (?:in flight|shown): (above|BELOW) the orbiter's sill line by ([\d.]+) ft)");
  if (std::regex_search(text, m, kTurnClearRe))
    s.turn_clearance = (m[1] == "above" ? 1.0 : -1.0) * std::stod(m[2]);
  static const std::regex kSillRe(
      R"(payload (above|BELOW) the orbiter's sill line by ([\d.]+) ft)");
  if (std::regex_search(text, m, kSillRe))
    s.bay_clearance = (m[1] == "above" ? 1.0 : -1.0) * std::stod(m[2]);
  static const std::regex moving(
      R"(\b(x|y|z|roll|pitch|yaw) ([+-][\d.]+) (?:ft|deg)/s(?: \(([\d.]+) (?:ft|deg) to go\))?( \(to 0\))?)");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), moving);
       it != std::sregex_iterator(); ++it) {
    const int a = AxisIndex((*it)[1]);
    s.rate[a] = std::stod((*it)[2]);
    if ((*it)[3].matched) s.to_go[a] = std::stod((*it)[3]);
    s.nulling[a] = (*it)[4].matched;
  }
  s.guidance = text.find("GUIDANCE") != std::string::npos;
  static const std::regex offset(R"(\b(x|y|z) (forward|back|right|left|down|up) ([\d.]+) ft)");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), offset);
       it != std::sregex_iterator(); ++it) {
    const std::string w = (*it)[2];
    const double sign = w == "forward" || w == "right" || w == "down" ? 1.0 : -1.0;
    s.offset[AxisIndex((*it)[1])] = sign * std::stod((*it)[3]);
  }
  static const std::regex turn(R"(\b(roll|pitch|yaw) (right|left|up|down) ([\d.]+) deg)");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), turn); it != std::sregex_iterator();
       ++it) {
    const std::string w = (*it)[2];
    const double sign = w == "right" || w == "up" ? 1.0 : -1.0;
    s.offset[AxisIndex((*it)[1])] = sign * std::stod((*it)[3]);
  }
  static const std::regex cond(R"(\[([x ])\] ([1-6]) [A-Za-z0-9 :]+?(holds|short) by ([\d.]+) ft)");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), cond); it != std::sregex_iterator();
       ++it) {
    const int i = std::stoi((*it)[2]) - 1;
    s.condition[i] = (*it)[1] == "x";
    s.margin[i] = ((*it)[3] == "holds" ? 1.0 : -1.0) * std::stod((*it)[4]);
  }
  if (std::regex_search(text, m, kFingerStopRe)) {
    s.close_gap = std::stod(m[1]);
    s.close_ok = m[2] == "below";
  }
  if (std::regex_search(text, m, kClearOfBayRe)) s.bay_clearance = std::stod(m[1]);
  if (std::regex_search(text, m, kInBayRe)) {
    s.bay_clearance = -std::stod(m[1]);
  }
  if (std::regex_search(text, m, kDockDistanceRe)) s.dock_distance = std::stod(m[1]);
  if (std::regex_search(text, m, kDockAngleRe)) s.dock_angle = std::stod(m[1]);
  return s;
}

ScriptedOperator::ScriptedOperator(OperatorTerminal* terminal,
                                   const ScriptedOperatorOptions& options)
    : terminal_(terminal), options_(options), rng_(options.seed) {}

double ScriptedOperator::Reaction() {
  if (options_.seed == 0 || options_.reaction_sd_s <= 0) return options_.reaction_s;
  std::normal_distribution<double> law(options_.reaction_s, options_.reaction_sd_s);
  return std::max(0.05, law(rng_));
}

void ScriptedOperator::Note(const std::string& line) {
  report_.transcript.push_back(Fmt("%6.1f s  ", last_.t_s) + line);
}

Screen ScriptedOperator::Look() {
  last_ = ParseScreen(terminal_->Capture());
  return last_;
}

void ScriptedOperator::ReleaseHeld(const std::vector<std::string>& keys) {
  // A person lets go a reaction time after seeing it get there.
  terminal_->Wait(Reaction());
  terminal_->Release(keys);
  for (const auto& k : keys) held_.erase(std::remove(held_.begin(), held_.end(), k), held_.end());
  std::string t;
  for (const auto& k : keys) t += (t.empty() ? "" : " ") + k;
  Note("let go of " + t);
}

void ScriptedOperator::Press(const std::vector<std::string>& keys, const std::string& why,
                             double pulse_s, const std::vector<std::string>& then, bool hold) {
  // A person acts a reaction time after seeing what they act on.
  terminal_->Wait(Reaction());
  terminal_->Send(keys);
  report_.key_actions += static_cast<int>(keys.size());
  std::string k;
  for (const auto& key : keys) k += (k.empty() ? "" : " ") + key;
  if (terminal_->HoldsKeys()) {
    // A window's keys: a motion key is held -- for the tap's time, until
    // Drive lets go (hold), or as long as a terminal's increment flies --
    // and every other key let go after a few frames. Space lets go of all.
    std::vector<std::string> motion, other;
    for (const auto& key : keys) (IsMotionKey(key) ? motion : other).push_back(key);
    if (std::find(keys.begin(), keys.end(), "Space") != keys.end()) {
      terminal_->Release(held_);
      held_.clear();
    }
    if (!motion.empty() && hold) {
      held_.insert(held_.end(), motion.begin(), motion.end());
    } else if (!motion.empty()) {
      const double held_s = pulse_s > 0 ? pulse_s : 2.5;
      terminal_->Wait(held_s);
      terminal_->Release(motion);
      k += Fmt(" (held %.2f s)", held_s);
    }
    Note("press " + k + ": " + why);
    terminal_->Wait(0.12);
    terminal_->Release(other);
    return;
  }
  if (pulse_s > 0) {
    terminal_->Wait(pulse_s);
    terminal_->Send(then);
    report_.key_actions += static_cast<int>(then.size());
    for (const auto& key : then) k += Fmt(" (%.2f s) ", pulse_s) + key;
  }
  Note("press " + k + ": " + why);
  // And sees it take effect before looking again (a few frames).
  terminal_->Wait(0.12);
}

bool ScriptedOperator::SetScale(const std::string& scale, double limit_s) {
  for (int tries = 0; tries < 4 && last_.t_s < limit_s; ++tries) {
    if (Look().scale == scale) return true;
    Press({"v"}, "the scale key, for " + scale);
  }
  return Look().scale == scale;
}

bool ScriptedOperator::FlyAutomatic(const std::vector<std::string>& keys, const std::string& why,
                                    double limit_s) {
  // A window's key still held from Drive is let go of first.
  if (!held_.empty()) ReleaseHeld(std::vector<std::string>(held_));
  // What flies by itself slows as it arrives: coarse is never too fast.
  if (last_.scale != "COARSE") SetScale("COARSE", limit_s);
  Press(keys, why);
  double quiet_since = -1;
  while (true) {
    const Screen s = Look();
    if (s.t_s > limit_s) return false;
    if (s.held || s.docked) return true;
    if (s.mode == wire::DcpMode::kAcquisition && s.near_limit && !s.unwinding && !s.stowing &&
        (s.squaring || s.angle > 1.0)) {
      // The ways out the screen names: unwind, then square up again; where
      // the wrist comes back to its limit after that, stow the arm and
      // start again from where the session started it.
      if (unwinds_ == 0 || (stowed_ && unwinds_ < 2)) {
        ++unwinds_;
        Press({"b"}, "the wrist nears its limit: unwind it");
        continue;
      }
      if (!stowed_) {
        stowed_ = true;
        Press({"z"}, "the wrist is back at its limit after the unwind: stow the arm");
        continue;
      }
    }
    if (s.unwinding || s.stowing) {
      quiet_since = -1;
      terminal_->Wait(0.2);
      continue;
    }
    if (!s.automatic()) {
      // Seen still twice (what was pressed may not have shown yet).
      if (quiet_since < 0) {
        quiet_since = s.t_s;
      } else if (s.t_s - quiet_since > 0.2) {
        return true;
      }
    } else {
      quiet_since = -1;
    }
    terminal_->Wait(0.2);
  }
}

bool ScriptedOperator::Drive(const Screen& s, const std::vector<Goal>& goals,
                             const std::string& why) {
  // Coarse for the long way, vernier for the last foot or so; changing the
  // scale stops every motion, so it is a press of its own. (With
  // hysteresis: coarse covers 0.9 ft and 3.4 deg while a press is on its
  // way, vernier a tenth of that.)
  double worst_ft = 0.0, worst_deg = 0.0;
  bool any_moving = false;
  for (const Goal& g : goals) {
    any_moving = any_moving || s.rate[g.axis] != 0.0;
    if (std::abs(g.error) <= g.tol) continue;
    double& worst = g.axis < 3 ? worst_ft : worst_deg;
    worst = std::max(worst, std::abs(g.error));
  }
  const bool done = worst_ft == 0.0 && worst_deg == 0.0;
  const bool want_vernier =
      s.vernier ? (worst_ft < 2.5 && worst_deg < 12.0) : (worst_ft < 1.2 && worst_deg < 5.0);
  if (!done && (want_vernier ? s.scale != "VERNIER" : s.scale != "COARSE")) {
    Press({"v"}, want_vernier ? "vernier for the last of it" : "the scale key, for coarse");
    return false;
  }
  // How far an axis goes while a press is on its way: the reaction, the
  // key's way to the station, a frame, the telemetry back, the look.
  const double latency = options_.reaction_s + 0.15;
  // A terminal stops an axis with a press the other way; a window by
  // letting go of the key held (and a held key keeps going by itself).
  const bool window = terminal_->HoldsKeys();
  std::vector<std::string> keys, release;
  auto stop = [&](int axis, double m) {
    if (window)
      release.push_back(m > 0 ? kPlusKey[axis] : kMinusKey[axis]);
    else
      keys.push_back(m > 0 ? kMinusKey[axis] : kPlusKey[axis]);
  };
  const Goal* pulse = nullptr;
  double pulse_rate = 0.0;
  for (const Goal& g : goals) {
    const double m = s.rate[g.axis], e = g.error, left = s.to_go[g.axis];
    const char* toward = e > 0 ? kPlusKey[g.axis] : kMinusKey[g.axis];
    if (std::abs(e) <= g.tol) {
      if (m != 0.0) stop(g.axis, m);  // there: stop it
      continue;
    }
    if (m != 0.0 && (m > 0) != (e > 0)) {
      stop(g.axis, m);  // going the wrong way: stop it, start again next time
    } else if (m != 0.0) {
      const double travel = std::abs(m) * latency;
      if (std::abs(e) <= travel + 0.5 * g.tol)
        stop(g.axis, m);  // stop it in time
      else if (!window && left < 1.2 * travel && std::abs(e) > left + g.tol)
        keys.push_back(toward);  // keep it going
    } else {
      // Still. Far: start it (and stop it when it gets there). Near: a
      // tap and its stop, timed, one axis at a time.
      const double rate = g.axis < 3 ? (s.vernier ? 0.2 : 2.0) : (s.vernier ? 0.8 : 8.0);
      if (std::abs(e) > 3 * rate * latency)
        keys.push_back(toward);
      else if (!pulse || std::abs(e) / g.tol > std::abs(pulse->error) / pulse->tol)
        pulse = &g, pulse_rate = rate;
    }
  }
  if (!release.empty()) ReleaseHeld(release);
  if (!keys.empty()) {
    Press(keys, why, 0, {}, /*hold=*/true);
  } else if (!release.empty()) {
    terminal_->Wait(0.12);
  } else if (pulse && !any_moving) {
    const char* toward = pulse->error > 0 ? kPlusKey[pulse->axis] : kMinusKey[pulse->axis];
    const char* against = pulse->error > 0 ? kMinusKey[pulse->axis] : kPlusKey[pulse->axis];
    Press({toward}, why + " (" + kAxisNames[pulse->axis] + Fmt(" %.2f, a tap)", pulse->error),
          options_.tap_gain * std::abs(pulse->error) / pulse_rate, {against});
  } else {
    terminal_->Wait(0.05);
  }
  return done;
}

bool ScriptedOperator::WaitForFrame(const std::string& frame, double limit_s) {
  for (int tries = 0; tries < 8 && last_.t_s < limit_s; ++tries) {
    const Screen s = Look();
    if (s.frame == frame) return true;
    Press({"n"}, "the " + frame + " frame");
    terminal_->Wait(0.15);
  }
  return Look().frame == frame;
}

bool ScriptedOperator::Acquire(double limit_s) {
  // docs/operator.md "How to fly the task by hand": square up in one turn
  // (h), back to 3 ft above the grasp if nearer, y and z to 0 (shift-d,
  // shift-f), down to the grasp (shift-w), close when the screen says
  // closing acquires.
  constexpr double kHoverFt = 3.0;
  int retries = 0;
  while (true) {
    const Screen s = Look();
    if (!s.valid || !s.guidance || s.mode == 0) {
      terminal_->Wait(0.1);
      continue;
    }
    if (s.t_s > limit_s)
      return report_.failure = "no acquisition by " + Fmt("%.0f s", limit_s), false;
    if (s.mode >= wire::DcpMode::kExtraction) {
      Note("acquired");
      return true;
    }
    if (s.held) {
      Press({"Space", "s"}, "held by a collision: stop, and back off");
      continue;
    }
    const auto& o = s.offset;
    if (s.angle > 0.5) {
      FlyAutomatic({"h"}, Fmt("square up: the whole %.1f deg turn at once", s.angle), limit_s);
      continue;
    }
    if (o[0] < kHoverFt - 0.5 && (std::abs(o[1]) > 0.02 || std::abs(o[2]) > 0.02)) {
      if (s.scale == "FINE") SetScale("COARSE", limit_s);
      Drive(s, {{0, o[0] - kHoverFt, 0.3}}, "back to 3 ft above the grasp before moving across");
      continue;
    }
    if (s.rate[0] != 0.0) {  // an increment of x still on its way: stop it first
      Press({"Space"}, "over the bar: stop");
      continue;
    }
    if (std::abs(o[1]) > 0.02 || std::abs(o[2]) > 0.02) {
      FlyAutomatic({"D", "F"}, "over the bar: y and z to 0", limit_s);
      continue;
    }
    if (std::abs(o[0]) > 0.02) {
      FlyAutomatic({"W"}, "descend: x to 0", limit_s);
      continue;
    }
    if (!s.would_acquire) {
      if (++retries > 3)
        return report_.failure =
                   "at the grasp, and closing would not acquire (conditions " + Conditions(s) + ")",
               false;
      FlyAutomatic(
          {"h", "D", "F", "W"},
          "closing would not acquire yet (conditions " + Conditions(s) + "): every axis to 0 again",
          limit_s);
      continue;
    }
    Press({"c"}, "the screen says closing the finger now acquires: close it");
    const double closed_at = Look().t_s;
    while (Look().mode < wire::DcpMode::kExtraction && last_.t_s - closed_at < 4.0)
      terminal_->Wait(0.1);
    if (last_.mode < wire::DcpMode::kExtraction)
      Press({"x"}, "closed and not acquired (conditions " + Conditions(last_) + "): open it");
  }
}

bool ScriptedOperator::Extract(double limit_s) {
  if (!WaitForFrame("orbiter", limit_s))
    return report_.failure = "the orbiter frame would not come", false;
  while (true) {
    const Screen s = Look();
    if (s.t_s > limit_s)
      return report_.failure = "not out of the bay by " + Fmt("%.0f s", limit_s), false;
    if (s.mode == wire::DcpMode::kManoeuvring && s.bay_clearance > 2.0) {
      Note("clear of the bay");
      return true;
    }
    // Straight up (the orbiter's -z), until 3 ft clear.
    Drive(s, {{2, -(3.0 - s.bay_clearance), 0.3}, {0, 0.0, 1.0}, {1, 0.0, 1.0}},
          "lift it out of the bay");
  }
}

bool ScriptedOperator::Dock(double limit_s) {
  // Under the port (orbiter frame: x and y to 0, z to kBelowFt below it,
  // higher while the turn's clearance over the sill line is short), the
  // probe turned up in one rotation (h), then in the payload frame onto
  // the port's axis (x, z to 0) and in (y to 0).
  enum Stage { kBelow, kTurn, kAlign, kIn } stage = kBelow;
  constexpr double kBelowFt = 12.0, kClearanceFt = 2.5;
  while (true) {
    const Screen s = Look();
    if (s.t_s > limit_s) return report_.failure = "not docked by " + Fmt("%.0f s", limit_s), false;
    if (s.docked) {
      report_.dock_distance_ft = s.dock_distance;
      report_.dock_angle_deg = s.dock_angle;
      Note("docked");
      return true;
    }
    if (s.held) {
      Press({"Space"}, "held by a collision: stop");
      if (stage == kIn) {
        Press({"a"}, "back off along the probe");
        stage = kAlign;
      }
      continue;
    }
    const auto& o = s.offset;
    switch (stage) {
      case kBelow: {
        if (std::abs(o[0]) > 0.3 || std::abs(o[1]) > 0.3) {
          FlyAutomatic({"W", "D"}, "under the port: x and y to 0", limit_s);
          continue;
        }
        // Low enough to turn under the CAE, high enough that the turn keeps
        // the payload above the sill line (the screen's "over the turn shown").
        const double below = s.turn_clearance < kClearanceFt
                                 ? -o[2] - (kClearanceFt + 0.5 - s.turn_clearance)
                                 : std::min(kBelowFt, -o[2]);
        if (Drive(s, {{2, o[2] + below, 0.5}}, Fmt("%.1f ft below the port", below))) {
          Note(Fmt("below the port (the turn keeps the payload %.2f ft above the sill line)",
                   s.turn_clearance));
          stage = kTurn;
        }
        continue;
      }
      case kTurn:
        if (s.angle > 0.5) {
          FlyAutomatic({"h"}, Fmt("turn the probe up: the whole %.1f deg at once", s.angle),
                       limit_s);
          continue;
        }
        if (!WaitForFrame("payload", limit_s))
          return report_.failure = "the payload frame would not come", false;
        stage = kAlign;
        continue;
      case kAlign:
        if (std::abs(o[0]) > 0.03 || std::abs(o[2]) > 0.03 || s.angle > 0.5) {
          FlyAutomatic({"h", "W", "F"}, "onto the port's axis: x and z to 0", limit_s);
          continue;
        }
        stage = kIn;
        continue;
      case kIn:
        FlyAutomatic({"D"}, "in along the probe: y to 0", limit_s);
        if (!Look().docked) stage = kAlign;
        continue;
    }
  }
}

FlightReport ScriptedOperator::FlyAgainAfterReset(double limit_s) {
  Press({"BSpace"}, "reset: a new attempt from where the arm is");
  for (int i = 0; i < 100; ++i) {
    const Screen s = Look();
    if (s.mode == wire::DcpMode::kAcquisition && !s.docked && !s.acquired) break;
    terminal_->Wait(0.1);
  }
  // The finger is still closed from the docking: open it for the new grasp.
  Press({"x"}, "open the finger for the new attempt");
  FlightReport r = Fly(false, limit_s);
  r.key_actions += 2;  // the reset and the finger
  r.key_actions_acquire += 2;
  report_ = r;
  return r;
}

FlightReport ScriptedOperator::Fly(bool acquire_only, double limit_s) {
  report_ = {};
  unwinds_ = 0;
  stowed_ = false;
  // The screen up, with guidance.
  for (int i = 0; i < 200; ++i) {
    const Screen s = Look();
    if (s.valid && s.guidance && s.mode == wire::DcpMode::kAcquisition) break;
    terminal_->Wait(0.1);
  }
  Note("start");
  report_.acquired = Acquire(limit_s);
  report_.key_actions_acquire = report_.key_actions;
  report_.acquired_t_s = report_.acquired ? last_.t_s : -1;
  if (!report_.acquired || acquire_only) return report_;
  if (!Extract(limit_s)) return report_;
  report_.docked = Dock(limit_s);
  report_.docked_t_s = report_.docked ? last_.t_s : -1;
  return report_;
}

}  // namespace rms::sim
