#include "rms/esg_renderer/overlay.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>

#include "rms/arm/kinematics.h"
#include "rms/base/check.h"
#include "rms/mission/mission_geometry.h"
#include "rms/scene_model/scene_model.h"
#include "rms/wire/dcp_mode.h"

namespace rms::esg_renderer {

namespace {

// 5 x 7 dot glyphs, one byte a row, bit 4 the left column.
const std::uint8_t* Glyph(char ch) {
  static const std::uint8_t kDigits[10][7] = {
      {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}, {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E},
      {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}, {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E},
      {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}, {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E},
      {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}, {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08},
      {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}, {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}};
  static const std::uint8_t kLetters[26][7] = {
      {0x0E, 0x11, 0x11, 0x11, 0x1F, 0x11, 0x11}, {0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E},
      {0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E}, {0x1C, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1C},
      {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F}, {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10},
      {0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F}, {0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11},
      {0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}, {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C},
      {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11}, {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F},
      {0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11}, {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11},
      {0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}, {0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10},
      {0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D}, {0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11},
      {0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E}, {0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04},
      {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}, {0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04},
      {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A}, {0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11},
      {0x11, 0x11, 0x11, 0x0A, 0x04, 0x04, 0x04}, {0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F}};
  static const std::uint8_t kDash[7] = {0, 0, 0, 0x1F, 0, 0, 0};
  static const std::uint8_t kColon[7] = {0, 0x0C, 0x0C, 0, 0x0C, 0x0C, 0};
  static const std::uint8_t kDot[7] = {0, 0, 0, 0, 0, 0x0C, 0x0C};
  static const std::uint8_t kSlash[7] = {0, 0x01, 0x02, 0x04, 0x08, 0x10, 0};
  static const std::uint8_t kComma[7] = {0, 0, 0, 0, 0x0C, 0x04, 0x08};
  static const std::uint8_t kPlus[7] = {0, 0x04, 0x04, 0x1F, 0x04, 0x04, 0};
  static const std::uint8_t kOpen[7] = {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02};
  static const std::uint8_t kClose[7] = {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08};
  static const std::uint8_t kLess[7] = {0x02, 0x04, 0x08, 0x10, 0x08, 0x04, 0x02};
  static const std::uint8_t kEqual[7] = {0, 0, 0x1F, 0, 0x1F, 0, 0};
  static const std::uint8_t kBlank[7] = {0, 0, 0, 0, 0, 0, 0};
  const char c = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  if (c >= '0' && c <= '9') return kDigits[c - '0'];
  if (c >= 'A' && c <= 'Z') return kLetters[c - 'A'];
  switch (c) {
    case '-':
      return kDash;
    case ':':
      return kColon;
    case '.':
      return kDot;
    case '/':
      return kSlash;
    case ',':
      return kComma;
    case '+':
      return kPlus;
    case '(':
      return kOpen;
    case ')':
      return kClose;
    case '<':
      return kLess;
    case '=':
      return kEqual;
    default:
      return kBlank;
  }
}

}  // namespace

void FillRect(std::uint8_t* rgba, int w, int h, int x0, int y0, int x1, int y1,
              const scene_model::Rgb& c) {
  x0 = std::max(x0, 0);
  y0 = std::max(y0, 0);
  x1 = std::min(x1, w);
  y1 = std::min(y1, h);
  for (int y = y0; y < y1; ++y) {
    std::uint8_t* p = rgba + (static_cast<std::size_t>(y) * w + x0) * 4;
    for (int x = x0; x < x1; ++x, p += 4) {
      p[0] = c[0];
      p[1] = c[1];
      p[2] = c[2];
      p[3] = 255;
    }
  }
}

void DrawText(std::uint8_t* rgba, int w, int h, int x, int y, std::string_view text,
              const scene_model::Rgb& colour, int scale) {
  for (char ch : text) {
    const std::uint8_t* g = Glyph(ch);
    for (int row = 0; row < 7; ++row) {
      for (int col = 0; col < 5; ++col) {
        if (g[row] & (0x10 >> col)) {
          FillRect(rgba, w, h, x + col * scale, y + row * scale, x + (col + 1) * scale,
                   y + (row + 1) * scale, colour);
        }
      }
    }
    x += 6 * scale;
  }
}

OverlayModel MakeOverlayModel(const LabConfig& config) {
  OverlayModel m;
  for (const auto& cam : config.cameras) {
    m.camera_names.push_back(cam.name);
    m.mounts.push_back(cam.mount);
  }
  m.p_S2oT_S2 =
      mission::PlanGeometry(config).X_S2P * scene_model::GrappleTargetCentre_P(config.payload);
  m.p_RoPort_R = config.cae.p_RoCo_R_ft;
  m.y_port_R = config.cae.R_RC.col(1);
  m.arm = config.arm;
  return m;
}

bool ProjectToImage(const wire::EsgFrameData& f, int w, int h, const Eigen::Vector3d& p_R,
                    double* x, double* y) {
  const Eigen::Vector3d d = f.R_RE.transpose() * (p_R - f.p_RoEye_R_ft);
  if (d.x() < 0.05) return false;
  const double focal = 0.5 * h / std::tan(0.5 * f.fov_deg * M_PI / 180.0);
  *x = 0.5 * w + focal * d.y() / d.x();
  *y = 0.5 * h + focal * d.z() / d.x();
  return true;
}

void DrawLine(std::uint8_t* rgba, int w, int h, int x0, int y0, int x1, int y1,
              const scene_model::Rgb& c, int thick) {
  const int n = std::max({std::abs(x1 - x0), std::abs(y1 - y0), 1});
  if (n > 4 * (w + h)) return;  // far off the image: nothing to draw
  for (int i = 0; i <= n; ++i) {
    const int x = x0 + (x1 - x0) * i / n, y = y0 + (y1 - y0) * i / n;
    FillRect(rgba, w, h, x - thick / 2, y - thick / 2, x - thick / 2 + thick, y - thick / 2 + thick,
             c);
  }
}

void DrawCrosshairs(std::uint8_t* rgba, int w, int h, const wire::EsgFrameData& f,
                    const OverlayModel& m) {
  const int st = f.control.camera_station;
  if (st < 1 || st > static_cast<int>(m.mounts.size())) return;
  const int t = std::max(1, h / 400);
  const scene_model::Rgb green{60, 240, 110};
  double x = 0, y = 0;
  if (m.mounts[st - 1] == CameraMount::kWrist) {
    // Fixed in System Two: where the grapple target's cross is at the grasp.
    const arm::ArmPose arm = arm::ComputeArmPose(m.arm, f.arm, f.shoulder_height_ft);
    if (!ProjectToImage(f, w, h, arm.X_RS2 * m.p_S2oT_S2, &x, &y)) return;
    const int cx = static_cast<int>(std::lround(x)), cy = static_cast<int>(std::lround(y));
    const int arm_px = h / 10, gap = h / 60;
    DrawLine(rgba, w, h, cx - arm_px, cy, cx - gap, cy, green, t);
    DrawLine(rgba, w, h, cx + gap, cy, cx + arm_px, cy, green, t);
    DrawLine(rgba, w, h, cx, cy - arm_px, cx, cy - gap, green, t);
    DrawLine(rgba, w, h, cx, cy + gap, cx, cy + arm_px, green, t);
    return;
  }
  if (m.mounts[st - 1] != CameraMount::kCae) return;
  // The port's axis, out from the port: the probe's tip comes in along it.
  double px = 0, py = 0;
  bool have_prev = false;
  const int s = std::max(1, h / 300);
  for (int k = 2; k <= 24; ++k) {
    const double dist = 0.5 * k;
    if (!ProjectToImage(f, w, h, m.p_RoPort_R - dist * m.y_port_R, &x, &y)) {
      have_prev = false;
      continue;
    }
    if (have_prev) {
      DrawLine(rgba, w, h, static_cast<int>(px), static_cast<int>(py), static_cast<int>(x),
               static_cast<int>(y), green, t);
    }
    if (k % 4 == 0) {
      const int tick = h / 60;
      DrawLine(rgba, w, h, static_cast<int>(x) - tick, static_cast<int>(y),
               static_cast<int>(x) + tick, static_cast<int>(y), green, t);
      char label[12];  // any int
      std::snprintf(label, sizeof label, "%d", k / 2);
      DrawText(rgba, w, h, static_cast<int>(x) + tick + 2 * s, static_cast<int>(y) - 3 * s, label,
               green, s);
    }
    px = x;
    py = y;
    have_prev = true;
  }
}

namespace {

// The rectangle's pixels (clipped to the image) into b.
void SaveCounterBackdrop(const std::uint8_t* rgba, int w, int h, int x0, int y0, int x1, int y1,
                         CounterBackdrop* b) {
  b->x0 = std::clamp(x0, 0, w);
  b->x1 = std::clamp(x1, b->x0, w);
  b->y0 = std::clamp(y0, 0, h);
  b->y1 = std::clamp(y1, b->y0, h);
  const std::size_t row = static_cast<std::size_t>(b->x1 - b->x0) * 4;
  b->rgba.resize(row * static_cast<std::size_t>(b->y1 - b->y0));
  for (int y = b->y0; y < b->y1; ++y) {
    std::copy_n(rgba + (static_cast<std::size_t>(y) * w + b->x0) * 4, row,
                b->rgba.data() + row * static_cast<std::size_t>(y - b->y0));
  }
}

}  // namespace

void RestoreCounterBackdrop(std::uint8_t* rgba, int w, int h, const CounterBackdrop& b) {
  RMS_CHECK(b.x0 >= 0 && b.x1 <= w && b.y0 >= 0 && b.y1 <= h && b.x0 <= b.x1 && b.y0 <= b.y1);
  const std::size_t row = static_cast<std::size_t>(b.x1 - b.x0) * 4;
  RMS_CHECK(b.rgba.size() == row * static_cast<std::size_t>(b.y1 - b.y0));
  for (int y = b.y0; y < b.y1; ++y) {
    std::copy_n(b.rgba.data() + row * static_cast<std::size_t>(y - b.y0), row,
                rgba + (static_cast<std::size_t>(y) * w + b.x0) * 4);
  }
}

void DrawOverlay(std::uint8_t* rgba, int w, int h, const wire::EsgFrameData& f,
                 const OverlayModel& model, CounterBackdrop* backdrop) {
  if (backdrop) {  // none until the counter is drawn (its buffer kept: no allocation a frame)
    backdrop->x0 = backdrop->x1 = backdrop->y0 = backdrop->y1 = 0;
    backdrop->rgba.clear();
  }
  if (f.control.crosshairs && !f.control.no_video) DrawCrosshairs(rgba, w, h, f, model);
  const std::vector<std::string>& names = model.camera_names;
  const int s = std::max(1, h / 300);
  if (f.control.no_video) {
    // A lost station's monitor says so, overlay switch or not.
    const int big = 3 * s;
    const std::string_view msg = "NO VIDEO";
    DrawText(rgba, w, h, (w - static_cast<int>(msg.size()) * 6 * big) / 2, (h - 8 * big) / 2, msg,
             {230, 230, 230}, big);
  }
  if (!f.control.overlay) return;
  const int line = 9 * s, margin = 4 * s;
  const scene_model::Rgb text{230, 230, 120}, dim{90, 90, 90}, black{0, 0, 0};
  char buf[64];
  std::snprintf(buf, sizeof buf, "FRAME %06u", f.frame_count);
  if (backdrop) {  // wide enough for any counter: "FRAME " and ten digits
    constexpr int kWidestCounter = 16;
    SaveCounterBackdrop(rgba, w, h, margin, margin, margin + kWidestCounter * 6 * s, margin + 7 * s,
                        backdrop);
  }
  DrawText(rgba, w, h, margin, margin, buf, text, s);
  const int st = f.control.camera_station;
  std::string name = st >= 1 && st <= static_cast<int>(names.size()) ? names[st - 1] : "";
  if (name.size() > 34) name.resize(34);
  std::snprintf(buf, sizeof buf, "CAM %d %s", st, name.c_str());
  DrawText(rgba, w, h, margin, margin + line, buf, text, s);
  std::snprintf(buf, sizeof buf, "MODE %d", f.control.mode);
  DrawText(rgba, w, h, margin, margin + 2 * line, buf, text, s);
  // Indicators, right to left along the top.
  struct Lamp {
    const char* label;
    bool on;
    scene_model::Rgb colour;
  };
  const Lamp lamps[] = {{"DOCK", f.control.docked, {60, 200, 80}},
                        {"ACQ", f.control.acquired, {60, 200, 80}},
                        {"RECPT", f.control.receptacle_collision, {230, 160, 30}},
                        {"COLL", f.control.collision, {230, 50, 40}}};
  int x = w - margin;
  for (const Lamp& l : lamps) {
    const int tw = static_cast<int>(std::string_view(l.label).size()) * 6 * s + 3 * s;
    x -= tw;
    if (l.on) FillRect(rgba, w, h, x - s, margin - s, x + tw - 2 * s, margin + 8 * s, l.colour);
    DrawText(rgba, w, h, x + s, margin, l.label, l.on ? black : dim, s);
    x -= 2 * s;
  }
}

namespace {

std::string Offset(const char* axis, double v, const char* plus, const char* minus,
                   const char* unit) {
  char b[48];
  std::snprintf(b, sizeof b, "%s %s %.2f%s", axis, v >= 0 ? plus : minus, std::abs(v), unit);
  return b;
}

}  // namespace

void DrawGuidance(std::uint8_t* rgba, int w, int h, const operator_state_t& st) {
  if (!st.show_guidance || !st.guidance_valid) return;
  const int s = std::max(1, h / 300);
  const int line = 9 * s, margin = 4 * s;
  std::vector<std::string> L;
  static const char* kFrames[4] = {"", "END EFFECTOR", "ORBITER", "PAYLOAD"};
  const int frame = st.command_frame >= 1 && st.command_frame <= 3 ? st.command_frame : 1;
  char b[96];
  std::snprintf(b, sizeof b, "%s  %s FRAME  %s", st.target == 1 ? "TO THE GRASP" : "TO THE PORT",
                kFrames[frame],
                st.control_mode == 1                          ? "SINGLE JOINT"
                : st.scale == operator_state_t::SCALE_VERNIER ? "VERNIER"
                : st.scale == operator_state_t::SCALE_FINE    ? "FINE"
                : st.control_mode                             ? "COARSE"
                                                              : "");
  L.push_back(b);
  L.push_back(Offset("X", st.offset_ft[0], "FWD", "BACK", "") + "  " +
              Offset("Y", st.offset_ft[1], "RIGHT", "LEFT", "") + "  " +
              Offset("Z", st.offset_ft[2], "DOWN", "UP", " FT"));
  L.push_back(Offset("ROLL", st.rotation_deg[0], "R", "L", "") + "  " +
              Offset("PITCH", st.rotation_deg[1], "UP", "DN", "") + "  " +
              Offset("YAW", st.rotation_deg[2], "R", "L", " DEG"));
  static const char* kNext[6] = {"X", "Y", "Z", "ROLL", "PITCH", "YAW"};
  if (st.next_axis >= 0 && st.next_axis < 6) {
    std::snprintf(b, sizeof b, "NEXT: %s", kNext[st.next_axis]);
    std::string n = b;
    if (st.automatic & operator_state_t::AUTO_SQUARE_UP) n += "  SQUARING UP";
    for (int i = 0; i < 6; ++i)
      if (st.automatic & (1 << i)) n += std::string("  NULLING ") + kNext[i];
    L.push_back(n);
  }
  if (st.automatic & operator_state_t::AUTO_UNWIND) L.push_back("UNWINDING THE WRIST");
  if (st.automatic & operator_state_t::AUTO_STOW) L.push_back("STOWING THE ARM");
  if (st.joints_near_limit)
    L.push_back(st.mode == wire::DcpMode::kAcquisition
                    ? "WARNING: WRIST NEAR ITS LIMIT: UNWIND IT OR STOW THE ARM"
                    : "WARNING: WRIST NEAR ITS LIMIT: UNWIND IT");
  if (st.mode == wire::DcpMode::kAcquisition) {
    std::string c = "ACQ";
    for (int i = 0; i < 6; ++i) {
      std::snprintf(b, sizeof b, "  %d %s %.2f", i + 1, st.margin_ft[i] >= 0 ? "OK" : "NO",
                    std::abs(st.margin_ft[i]));
      c += b;
    }
    L.push_back(c);
    if (st.close_gap_ft > 0) {
      // close_ok: closing now acquires (every other condition holds too).
      bool others = true;
      for (int i : {0, 1, 2, 4, 5}) others = others && st.conditions[i];
      std::snprintf(b, sizeof b, "CLOSED, THE FINGER WOULD STOP AT %.2f FT: %s", st.close_gap_ft,
                    st.close_ok ? "CLOSING ACQUIRES"
                    : !others   ? "OTHER CONDITIONS SHORT"
                                : "NOT BELOW D3Y");
      L.push_back(b);
    }
  } else if (st.mode == wire::DcpMode::kExtraction) {
    std::snprintf(b, sizeof b, "BAY: %.2f FT TO CLEAR", std::max(0.0, -st.bay_clearance_ft));
    L.push_back(b);
  } else {
    std::snprintf(b, sizeof b, "DOCK: %.2f FT  %.2f DEG", st.dock_distance_ft, st.dock_angle_deg);
    L.push_back(b);
    std::snprintf(b, sizeof b, "SILL: %+.2f FT NOW  %+.2f FT OVER THE TURN", st.bay_clearance_ft,
                  st.turn_clearance_ft);
    L.push_back(b);
    if (st.clearance_warning) L.push_back("CLEARANCE WARNING: GO UP BEFORE TURNING");
  }
  std::size_t longest = 0;
  for (const auto& l : L) longest = std::max(longest, l.size());
  const int panel_w = static_cast<int>(longest) * 6 * s + 2 * margin;
  const int panel_h = static_cast<int>(L.size()) * line + 2 * margin;
  const int x0 = margin, y0 = h - margin - panel_h;
  FillRect(rgba, w, h, x0, y0, x0 + panel_w, y0 + panel_h, {16, 20, 28});
  for (std::size_t i = 0; i < L.size(); ++i) {
    DrawText(rgba, w, h, x0 + margin, y0 + margin + static_cast<int>(i) * line, L[i],
             {120, 230, 255}, s);
  }
}

}  // namespace rms::esg_renderer
