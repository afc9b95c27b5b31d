#include "rms/operator_station/status_screen.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <spdlog/sinks/base_sink.h>
#include <spdlog/spdlog.h>
#include <sstream>
#include <sys/ioctl.h>

#include "rms/base/text.h"
#include "rms/operator_station/follow_watch.h"
#include "rms/wire/acquisition_conditions.h"
#include "rms/wire/collision_bits.h"
#include "rms/wire/dcp_mode.h"
#include "rms/wire/malfunction.h"

namespace rms::operator_station {

namespace {

std::string ModeName(int m) {
  const wire::DcpModeInfo* info = wire::DcpModeOf(m);
  return info ? std::to_string(m) + " " + info->upper : "?";
}

// Fields packed into lines of at most `width` characters: a field that does
// not fit starts a new line, indented.
class Flow {
 public:
  Flow(std::vector<std::string>* lines, int width) : lines_(lines), width_(width) {}
  Flow& Line(const std::string& first) {
    lines_->push_back(first);
    return *this;
  }
  Flow& Field(const std::string& f) {
    std::string& l = lines_->back();
    if (static_cast<int>(l.size() + 3 + f.size()) > width_ &&
        l.find_first_not_of(' ') != std::string::npos && l.size() > 4) {
      lines_->push_back("    " + f);
    } else {
      l += (l.empty() || l.back() == ' ' ? "" : "   ") + f;
    }
    return *this;
  }

 private:
  std::vector<std::string>* lines_;
  int width_;
};

// "above the orbiter's sill line by 3.20 ft" / "BELOW the orbiter's sill
// line by 1.54 ft" (the bay's top: docs/operator.md "Clearance in Mode 3").
std::string SillText(double ft) {
  return ft >= 0 ? Sprintf("above the orbiter's sill line by %.2f ft", ft)
                 : Sprintf("BELOW the orbiter's sill line by %.2f ft", -ft);
}

// "short by 12.345 ft" / "holds by 0.050 ft": a margin as an unsigned distance.
std::string Margin(double m) {
  return m >= 0 ? Sprintf("holds by %.3f ft", m) : Sprintf("short by %.3f ft", -m);
}

// The key that moves `action`, for hints: "(w)", or "" when unbound.
// The keys bound to an action ("h"), in any control mode; "" if none.
std::string KeysOf(const StatusSnapshot& s, const std::string& action) {
  const auto it = s.keys.find(action);
  return it == s.keys.end() ? "" : it->second;
}

std::string KeyHint(const StatusSnapshot& s, const std::string& action) {
  // In single joint control the hand-controller keys drive a joint: no hint.
  if (s.hand && s.hand->mode == ControlMode::kSingleJoint && action.rfind("finger", 0) != 0)
    return "";
  const std::string keys = KeysOf(s, action);
  return keys.empty() ? "" : " (" + keys + ")";
}

// "x forward 3.25 ft (w)   y left 0.50 ft (a)   z down 1.00 ft (f)": each
// offset unsigned, with the direction that closes it and its key.
void OffsetFields(const StatusSnapshot& s, const Eigen::Vector3d& d_ft, Flow& flow) {
  static const char* kAxis[3] = {"x", "y", "z"};
  static const char* kWord[3][2] = {{"forward", "back"}, {"right", "left"}, {"down", "up"}};
  flow.Line(" ");
  for (int i = 0; i < 3; ++i) {
    const double d = d_ft[i];
    const std::string action = std::string(kHandAxisNames[i]) + (d >= 0 ? "+" : "-");
    flow.Field(Sprintf("%s %s %.2f ft", kAxis[i], kWord[i][d >= 0 ? 0 : 1], std::abs(d)) +
               KeyHint(s, action));
  }
}

// What to fly next, one axis at a time, and the keys that fly it by itself:
// "next: roll left 12.0 deg (u; U nulls it)   h squares up (one turn)".
void NextLine(const StatusSnapshot& s, Flow& flow) {
  const Guidance& g = *s.guidance;
  static const char* kName[6] = {"x", "y", "z", "roll", "pitch", "yaw"};
  static const char* kWord[6][2] = {{"forward", "back"}, {"right", "left"}, {"down", "up"},
                                    {"right", "left"},   {"up", "down"},    {"right", "left"}};
  const int a = g.next_axis;
  if (s.telemetry && s.telemetry->docked) {
    flow.Line(" next: nothing -- docked");
    return;
  }
  if (a < 0) {
    flow.Line(" next: nothing -- at the target");
    return;
  }
  const bool in_bay = g.leave_bay && g.leave_bay_ft.norm() > 1e-9;
  const double e = a < 3 ? (in_bay ? g.leave_bay_ft[a] : g.offset_ft[a]) : g.rotation_deg[a - 3];
  const std::string move = std::string(kHandAxisNames[a]) + (e >= 0 ? "+" : "-");
  std::string hint = KeyHint(s, move);
  const std::string null_key = KeyHint(s, "null_" + std::string(kHandAxisNames[a]));
  if (!null_key.empty())  // in the bay, the way out's 0
    hint = hint.substr(0, hint.size() - 1) + "; " + null_key.substr(2, null_key.size() - 3) +
           " flies it to 0)";
  flow.Line(Sprintf(" next: %s %s %.*f %s", kName[a], kWord[a][e >= 0 ? 0 : 1], a < 3 ? 2 : 1,
                    std::abs(e), a < 3 ? "ft" : "deg") +
            hint);
  const std::string square = KeyHint(s, "square_up");
  if (g.angle_deg > 0.5 && !square.empty() && !in_bay)
    flow.Field(Sprintf("%s squares up the whole %.1f deg turn at once",
                       square.substr(2, square.size() - 3).c_str(), g.angle_deg));
}

void GuidanceLines(const StatusSnapshot& s, Flow& flow) {
  const Guidance& g = *s.guidance;
  const std::string axes = std::string(CommandFrameName(g.frame)) + " axes";
  if (g.leave_bay) {
    const bool out = g.leave_bay_ft.norm() < 1e-9;
    if (out) {
      flow.Line("GUIDANCE out of the cargo bay: clear");
    } else {
      flow.Line("GUIDANCE out of the cargo bay first:")
          .Field(Sprintf("straight up to %.0f ft above it,", kLeaveBayMarginFt))
          .Field(axes + ":");
      OffsetFields(s, g.leave_bay_ft, flow);
    }
  }
  flow.Line(std::string(g.leave_bay ? "then " : "GUIDANCE ") +
            (g.target == GuidanceTarget::kGrasp ? "to the grasp on the bar receptacle,"
                                                : "to the CAE's docking port,"))
      .Field(g.target == GuidanceTarget::kGrasp ? "from the grasp point," : "from the probe's tip,")
      .Field(axes + ":");
  OffsetFields(s, g.offset_ft, flow);
  flow.Field(Sprintf("distance %.2f ft", g.distance_ft));
  static const char* kRot[3] = {"roll", "pitch", "yaw"};
  static const char* kRotWord[3][2] = {{"right", "left"}, {"up", "down"}, {"right", "left"}};
  flow.Line(" ");
  for (int i = 0; i < 3; ++i) {
    const double d = g.rotation_deg[i];
    const std::string action = std::string(kHandAxisNames[3 + i]) + (d >= 0 ? "+" : "-");
    flow.Field(Sprintf("%s %s %.1f deg", kRot[i], kRotWord[i][d >= 0 ? 0 : 1], std::abs(d)) +
               KeyHint(s, action));
  }
  flow.Field(Sprintf("angle %.1f deg", g.angle_deg));
  NextLine(s, flow);
}

void ControlLines(const StatusSnapshot& s, Flow& flow) {
  const HandStatus& h = *s.hand;
  flow.Line("CONTROL " + std::string(ControlModeName(h.mode)));
  if (h.mode == ControlMode::kManualAugmented)
    flow.Field("frame: " + std::string(CommandFrameName(h.frame)));
  else
    flow.Field(Sprintf("joint: %s", std::string(kAnalogInputNames[h.joint]).c_str()));
  std::string scale(RateScaleName(h.scale));
  std::transform(scale.begin(), scale.end(), scale.begin(), ::toupper);
  flow.Field("scale: " + scale);
  // What each axis does: "moving x +2.00 ft/s (1.20 ft to go)".
  static const char* kAxis[6] = {"x", "y", "z", "roll", "pitch", "yaw"};
  static const char* kUnit[6] = {"ft", "ft", "ft", "deg", "deg", "deg"};
  bool moving = false;
  for (int i = 0; i < kNumHandAxes; ++i) {
    if (h.rate[i] == 0.0) continue;
    const bool joint = h.mode == ControlMode::kSingleJoint;
    std::string m = Sprintf("%s %s %+.2f %s/s", moving ? "" : "moving", joint ? "joint" : kAxis[i],
                            h.rate[i], joint ? "deg" : kUnit[i]);
    if (h.pending[i] != 0.0)
      m += Sprintf(" (%.2f %s to go)", std::abs(h.pending[i]), joint ? "deg" : kUnit[i]);
    if (h.automatic & (1u << i)) m += " (to 0)";
    // What the arm does of it, where that is less (a joint at its rate, a
    // singular pose): the real rate.
    if (std::abs(h.achieved[i]) < 0.95 * std::abs(h.rate[i]))
      m += Sprintf(" [arm %+.2f]", h.achieved[i]);
    flow.Field(moving ? m.substr(1) : m);
    moving = true;
  }
  if (h.automatic & kAutoSquareUp) flow.Field("SQUARING UP (one turn)");
  if (h.automatic & kAutoUnwind) {
    flow.Field("UNWINDING the wrist to the middle of its travel");
    moving = true;
  }
  if (h.automatic & kAutoStow) {
    flow.Field("STOWING the arm: every joint back to its start");
    moving = true;
  }
  if (!moving) flow.Field("still");
  if (h.near_limit) {
    std::string j;
    for (int i = 0; i < kNumJoints; ++i) {
      if (h.near_limit & (1u << i))
        j += std::string(j.empty() ? "" : ", ") + std::string(kAnalogInputNames[i]) +
             Sprintf(" %+.1f", s.inputs.value[i]);
    }
    // The ways out: the unwind, and in Mode 1 the stow (where the wrist
    // comes back to its limit after an unwind: docs/operator.md "Nulling an
    // axis, squaring up, unwinding"), in either control mode (so not
    // KeyHint, which names no hand-controller key in single joint).
    const std::string unwind = KeysOf(s, "unwind"), stow = KeysOf(s, "stow");
    std::string out = unwind.empty() ? "" : "; " + unwind + " unwinds it";
    if (!stow.empty() && s.telemetry && s.telemetry->mode == wire::DcpMode::kAcquisition)
      out += (out.empty() ? "; " : ", ") + stow + " stows the arm";
    flow.Field(Sprintf("WRIST NEAR ITS LIMIT (within %.0f deg): ", kNearLimitDeg) + j + out);
  }
  if (h.at_limit) {
    std::string j;
    for (int i = 0; i < kNumJoints; ++i) {
      if (h.at_limit & (1u << i))
        j += std::string(j.empty() ? "" : ", ") + std::string(kAnalogInputNames[i]);
    }
    flow.Field("AT JOINT LIMIT: " + j);
  }
  if (h.singular)
    flow.Field("NEAR A SINGULAR POSE: some motions slowed")
        .Field("(the arm straight, or the wrist yaw near 90 deg)");
  if (h.rate_limited) flow.Field("slowed: a joint at its rate");
  if (h.held_at_port) {
    flow.Field("DOCKED: the port holds the payload and the arm; open the finger" +
               KeyHint(s, "finger-") + " to let go");
  }
}

void ModeLines(const StatusSnapshot& s, Flow& flow) {
  const dcp_telemetry_t& t = *s.telemetry;
  flow.Line(Sprintf("MODE %s", ModeName(t.mode).c_str()))
      .Field(Sprintf("acquired %s", t.acquired ? "YES" : "no"))
      .Field(Sprintf("docked %s", t.docked ? "YES" : "no"))
      .Field(std::string("arm ") + (t.held          ? "HELD: the command collides"
                                    : t.finger_held ? "follows, finger held on the bar"
                                                    : "follows"));
}

void CollisionLines(const StatusSnapshot& s, Flow& flow) {
  const dcp_telemetry_t& t = *s.telemetry;
  if (s.not_following) {
    // docs/operator.md "A joint that does not follow".
    std::string parts;
    for (int p = 0; p <= FollowWatch::kArm; ++p) {
      if (!((s.not_following >> p) & 1u)) continue;
      parts += (parts.empty() ? "" : ", ") +
               (p < FollowWatch::kFinger ? Sprintf("joint %d (%s)", p + 1, wire::JointName(p + 1))
                : p == FollowWatch::kFinger
                    ? std::string("the finger")
                    : std::string("the arm (held, though commanded where it is)"));
    }
    flow.Line("FAILURE? NOT FOLLOWING ITS COMMAND: " + parts);
  }
  flow.Line("collisions: " +
            wire::CollisionNames(static_cast<std::uint32_t>(t.collisions), ", ", "none"));
}

void ConditionLines(const StatusSnapshot& s, const LabConfig& config, int width, Flow& flow) {
  const dcp_telemetry_t& t = *s.telemetry;
  if (t.mode == wire::DcpMode::kAcquisition) {
    flow.Line("ACQUISITION (each condition's margin):");
    // Two a line, named in full on a wide screen; three, by tag, on a narrow one.
    const bool wide = width >= 110;
    for (int i = 0; i < wire::kNumAcquisitionConditions; ++i) {
      if (i % (wide ? 2 : 3) == 0) flow.Line(" ");
      flow.Field(Sprintf(wide ? "[%c] %d %-24s %-20s" : "[%c] %d %s: %s",
                         t.acquisition_conditions[i] ? 'x' : ' ', i + 1,
                         wide ? wire::kAcquisitionConditionNames[i].brief
                              : wire::kAcquisitionConditionNames[i].tag,
                         Margin(t.acquisition_margin_ft[i]).c_str()));
    }
    flow.Line(Sprintf("  finger gap %.3f ft (D3Y %.3f)", t.finger_gap_ft, config.dcp.d3y_ft))
        .Field(Sprintf("palm to BAR %.3f ft (TPOB %.3f)", std::abs(t.palm_to_bar_ft),
                       config.dcp.tpob_ft));
    if (s.guidance && s.guidance->close_gap_ft > 0) {
      const double g = s.guidance->close_gap_ft;
      flow.Field(Sprintf(
          "closed, the finger would stop at %.3f ft: %s", g,
          g < config.dcp.d3y_ft ? "below D3Y" : "NOT below D3Y (the BAR nearer the fixed finger)"));
    }
    // Closing now acquires only where every other condition holds too.
    std::string short_of;
    for (int i : {0, 1, 2, 4, 5})
      if (!t.acquisition_conditions[i])
        short_of += (short_of.empty() ? "" : " ") + std::to_string(i + 1);
    if (s.guidance && WouldAcquire(t, *s.guidance, config.dcp.d3y_ft))
      flow.Line("  CLOSING THE FINGER NOW ACQUIRES" + KeyHint(s, "finger+"));
    else if (s.guidance && s.guidance->close_gap_ft > 0)
      flow.Line("  closing now would not acquire" +
                (short_of.empty() ? std::string(": the finger would not stop below D3Y")
                                  : ": conditions " + short_of + " short"));
  } else if (t.mode == wire::DcpMode::kExtraction) {
    flow.Line("ACQUISITION: acquired; the payload is held")
        .Field(t.bay_clearance_ft > 0
                   ? Sprintf("clear of the bay by %.2f ft", t.bay_clearance_ft)
                   : Sprintf("in the bay: %.2f ft to lift it clear", -t.bay_clearance_ft));
  } else {
    flow.Line("ACQUISITION: acquired; the payload is held, out of the bay")
        .Field("payload " + SillText(t.bay_clearance_ft));
    if (s.guidance && !std::isnan(s.guidance->turn_clearance_ft)) {
      const Guidance& g = *s.guidance;
      const bool in_flight = s.hand && TurnInFlight(*s.hand, g);
      flow.Field(std::string(in_flight ? "over the turn in flight: " : "over the turn shown: ") +
                 SillText(g.turn_clearance_ft));
      if (g.clearance_warning)
        flow.Line(
            Sprintf("CLEARANCE WARNING: under %.0f ft above the orbiter's sill line; go up "
                    "(orbiter frame) before turning",
                    kClearanceMarginFt));
    }
  }
  flow.Line(Sprintf("DOCKING distance %.3f ft (<= %.2f)", t.dock_distance_ft,
                    config.dcp.dock_distance_ft))
      .Field(Sprintf("angle %.2f deg (<= %.2f)", t.dock_angle_deg, config.dcp.dock_angle_deg))
      .Field(t.probe_in_envelope
                 ? Sprintf("probe in the envelope (by %.2f ft)", t.envelope_margin_ft)
                 : Sprintf("probe outside the envelope by %.2f ft", -t.envelope_margin_ft));
}

void CameraLines(const StatusSnapshot& s, const LabConfig& config, Flow& flow) {
  const wire::OperatorInputs& in = s.inputs;
  const int st = in.camera_station;
  flow.Line(Sprintf("camera %d %s", st,
                    st >= 1 && st <= static_cast<int>(config.cameras.size())
                        ? config.cameras[st - 1].name.c_str()
                        : "?"))
      .Field(Sprintf("pan %+6.1f  tilt %+6.1f  zoom %.2f", in.value[kCameraPan],
                     in.value[kCameraTilt], in.value[kCameraZoom]))
      .Field(std::string("crosshairs ") + (in.crosshairs ? "on" : "off"))
      .Field(std::string("overlay ") + (in.overlay ? "on" : "off"));
  if (s.hand) flow.Field(std::string("window guidance ") + (s.show_guidance ? "on" : "off"));
  if (s.hand && s.hand->camera_refused != 0) {
    std::string set;
    for (int c : s.hand->cameras) {
      if (!set.empty()) set += ' ';
      set += std::to_string(c);
    }
    flow.Line(Sprintf("camera %d is not in this session's camera set (%s)", s.hand->camera_refused,
                      set.c_str()));
  }
}

void ArmLines(const StatusSnapshot& s, Flow& flow) {
  const wire::OperatorInputs& in = s.inputs;
  flow.Line(Sprintf("arm, deg: yaw %+7.2f", in.value[0]))
      .Field(Sprintf("pitch %+7.2f", in.value[1]))
      .Field(Sprintf("elbow %+7.2f", in.value[2]))
      .Field(Sprintf("wrist pitch %+7.2f", in.value[3]))
      .Field(Sprintf("yaw %+7.2f", in.value[4]))
      .Field(Sprintf("roll %+7.2f", in.value[5]))
      .Field(Sprintf("shoulder height %.2f ft", in.value[kShoulderHeight]))
      .Field(Sprintf("finger %.2f (0 open, 1 closed)", in.value[kFinger]));
}

void RateLines(const StatusSnapshot& s, Flow& flow) {
  flow.Line(Sprintf("rates: published %.1f Hz", s.publish_hz))
      .Field(Sprintf("DCP %.1f Hz", s.telemetry_hz))
      .Field(s.render_hz >= 0 ? Sprintf("rendered %.1f Hz", s.render_hz)
                              : "rendered ? (no status from esg_renderer)");
  flow.Line("latency: input to DCP " +
            (s.input_to_dcp_ms >= 0 ? Sprintf("%.1f ms", s.input_to_dcp_ms) : "?"))
      .Field("input to rendered frame " +
             (s.input_to_render_p50_ms >= 0
                  ? Sprintf("p50 %.1f ms, p99 %.1f ms", s.input_to_render_p50_ms,
                            s.input_to_render_p99_ms)
                  : std::string("? (no status from esg_renderer)")));
  flow.Line(Sprintf("inputs clamped to their range: %ld", s.clamped_inputs));
  if (s.key_actions >= 0) flow.Field(Sprintf("keys pressed: %ld", s.key_actions));
}

void DeviceLines(const StatusSnapshot& s, Flow& flow) {
  flow.Line(s.devices.empty() ? "devices: none" : "devices: " + s.devices[0] + ";");
  for (std::size_t i = 1; i < s.devices.size(); ++i) flow.Field(s.devices[i] + ";");
}

void HelpLines(const StatusSnapshot& s, Flow& flow) {
  if (s.help.empty()) return;
  flow.Line("");
  // Groups are two spaces apart ("w/s fwd/back  d/a right/left ...").
  std::size_t from = 0;
  while (from < s.help.size()) {
    std::size_t to = s.help.find("  ", from);
    if (to == std::string::npos) to = s.help.size();
    if (to > from) flow.Field(s.help.substr(from, to - from));
    from = to + 2;
  }
}

// Too small for the screen: say so, in what room there is.
std::string TooSmallScreen(const StatusSnapshot& s, int width, int height) {
  std::vector<std::string> L = {
      "rmslab operator station",
      Sprintf("terminal %dx%d: needs %dx%d", width, height, kMinWidth, kMinHeight)};
  if (s.telemetry)
    L.push_back(Sprintf("MODE %d%s%s", s.telemetry->mode, s.telemetry->acquired ? " ACQ" : "",
                        s.telemetry->docked ? " DOCK" : ""));
  if (s.guidance)
    L.push_back(Sprintf("to go %.2f ft %.1f deg", s.guidance->distance_ft, s.guidance->angle_deg));
  std::string out;
  for (int i = 0; i < std::min<int>(height, static_cast<int>(L.size())); ++i) {
    out += L[i].substr(0, static_cast<std::size_t>(std::max(width, 1))) + "\n";
  }
  return out;
}

// A section of the screen, and how soon it goes on a short terminal: 0
// always; then 1 (conditions, docking), 2 (camera), 3 (rates), 4 (arm), 5
// (devices), 6 (the keys' help, shown under the events pane).
struct Section {
  int priority;
  std::vector<std::string> lines;
};

// The sections in the order shown.
std::vector<Section> BuildSections(const StatusSnapshot& s, const LabConfig& config, int width) {
  std::vector<Section> sections;
  const std::string title = "rmslab operator station -- " + s.source;
  const std::string right =
      Sprintf("t %.1f s  frame %06lld", s.session_s, static_cast<long long>(s.frame));
  sections.push_back(
      {0,
       {title +
        std::string(std::max<int>(1, width - static_cast<int>(title.size() + right.size())), ' ') +
        right}});
  // Each section's lines are written while it is the last one (a Flow
  // points into it).
  auto add = [&](int priority, const auto& lines) {
    sections.push_back({priority, {}});
    Flow flow(&sections.back().lines, width);
    lines(flow);
  };
  add(0, [&](Flow& f) {
    if (s.telemetry)
      ModeLines(s, f);
    else
      f.Line(
          "MODE ?  (no telemetry from dynamics_proc since the start, the last reset or restore)");
  });
  if (s.telemetry) add(s.telemetry->collisions ? 0 : 1, [&](Flow& f) { CollisionLines(s, f); });
  if (s.hand) add(0, [&](Flow& f) { ControlLines(s, f); });
  if (s.guidance) add(0, [&](Flow& f) { GuidanceLines(s, f); });
  if (s.telemetry) add(1, [&](Flow& f) { ConditionLines(s, config, width, f); });
  add(2, [&](Flow& f) { CameraLines(s, config, f); });
  add(4, [&](Flow& f) { ArmLines(s, f); });
  add(3, [&](Flow& f) { RateLines(s, f); });
  add(5, [&](Flow& f) { DeviceLines(s, f); });
  add(6, [&](Flow& f) { HelpLines(s, f); });
  return sections;
}

// The lines the sections take, with the events pane's heading.
int LinesUsed(const std::vector<Section>& sections) {
  int n = 1;
  for (const Section& sec : sections) n += static_cast<int>(sec.lines.size());
  return n;
}

}  // namespace

std::string RenderStatusScreen(const StatusSnapshot& s, const LabConfig& config, int width,
                               int height) {
  if (width < kMinWidth || height < kMinHeight) return TooSmallScreen(s, width, height);
  std::vector<Section> sections = BuildSections(s, config, width);
  // Drop the least important sections until the events pane has 3 lines.
  constexpr int kMinPane = 3;
  for (int p = 6; p >= 1 && LinesUsed(sections) + kMinPane > height; --p) {
    for (Section& sec : sections) {
      if (sec.priority == p) sec.lines.clear();
    }
  }
  const int pane = std::max(kMinPane, height - LinesUsed(sections));
  std::vector<std::string> L;
  const Section* help = nullptr;
  for (const Section& sec : sections) {
    if (sec.priority == 6) {
      help = &sec;
      continue;
    }
    L.insert(L.end(), sec.lines.begin(), sec.lines.end());
  }
  L.push_back("--- events and log ---");
  const std::size_t first = s.log.size() > static_cast<std::size_t>(pane) ? s.log.size() - pane : 0;
  for (std::size_t i = first; i < s.log.size(); ++i) L.push_back(s.log[i]);
  for (std::size_t i = s.log.size() - first; i < static_cast<std::size_t>(pane); ++i)
    L.push_back("");
  if (help) L.insert(L.end(), help->lines.begin(), help->lines.end());
  std::string out;
  for (auto& l : L) {
    if (static_cast<int>(l.size()) > width) l.resize(width);
    out += l + "\n";
  }
  return out;
}

namespace {
// Keeps every formatted line (all are written out when the screen closes)
// and a short form for the pane ("12:03:04 warn: ..." without the date and
// the process).
class LineSink : public spdlog::sinks::base_sink<std::mutex> {
 public:
  std::vector<std::string> Last(std::size_t n) {
    std::lock_guard<std::mutex> lock(mutex_);
    const std::size_t k = std::min(n, brief_.size());
    return {brief_.end() - static_cast<long>(k), brief_.end()};
  }
  std::vector<std::string> All() {
    std::lock_guard<std::mutex> lock(mutex_);
    return lines_;
  }

 protected:
  void sink_it_(const spdlog::details::log_msg& msg) override {
    spdlog::memory_buf_t buf;
    formatter_->format(msg, buf);
    std::string line(buf.data(), buf.size());
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
    lines_.push_back(std::move(line));
    const std::time_t t = std::chrono::system_clock::to_time_t(msg.time);
    std::tm tm{};
    localtime_r(&t, &tm);
    char hms[16];
    std::strftime(hms, sizeof hms, "%H:%M:%S", &tm);
    const std::string level =
        msg.level == spdlog::level::info
            ? ""
            : std::string(spdlog::level::to_string_view(msg.level).data()) + ": ";
    brief_.push_back(std::string(hms) + " " + level +
                     std::string(msg.payload.data(), msg.payload.size()));
  }
  void flush_() override {}

 private:
  std::vector<std::string> lines_, brief_;
};

// The terminal's size (columns, rows), or 100 x 48 when it cannot be asked.
std::pair<int, int> TerminalSize() {
  winsize ws{};
  if (ioctl(STDOUT_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0 && ws.ws_row > 0)
    return {ws.ws_col, ws.ws_row};
  return {100, 48};
}
}  // namespace

struct StatusScreen::LogCapture {
  std::shared_ptr<spdlog::logger> logger;
  std::vector<spdlog::sink_ptr> saved;
  std::shared_ptr<LineSink> lines;
};

StatusScreen::StatusScreen(const LabConfig& config)
    : config_(config), capture_(std::make_unique<LogCapture>()) {
  capture_->logger = spdlog::default_logger();
  capture_->saved = capture_->logger->sinks();
  capture_->lines = std::make_shared<LineSink>();
  capture_->lines->set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%n] [%l] %v");
  capture_->logger->sinks() = {capture_->lines};
  std::fputs("\x1b[?1049h\x1b[?25l\x1b[H\x1b[2J", stdout);
  std::fflush(stdout);
}

StatusScreen::~StatusScreen() {
  std::fputs("\x1b[?25h\x1b[?1049l", stdout);
  std::fflush(stdout);
  capture_->logger->sinks() = capture_->saved;
  // Nothing is lost: the lines the screen showed go to the log now.
  for (const std::string& line : capture_->lines->All()) std::fprintf(stderr, "%s\n", line.c_str());
}

void StatusScreen::Draw(StatusSnapshot s) {
  const auto [width, height] = TerminalSize();
  for (std::string& line : capture_->lines->Last(static_cast<std::size_t>(height)))
    s.log.push_back(std::move(line));
  const std::string text = RenderStatusScreen(s, config_, width, height);
  std::string frame = "\x1b[H";
  std::istringstream is(text);
  int rows = 0;
  for (std::string line; std::getline(is, line) && rows < height; ++rows) {
    frame += line + "\x1b[K" + (rows + 1 < height ? "\n" : "");
  }
  frame += "\x1b[J";
  std::fwrite(frame.data(), 1, frame.size(), stdout);
  std::fflush(stdout);
}

}  // namespace rms::operator_station
