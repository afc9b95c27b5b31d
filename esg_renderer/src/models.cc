#include "models.h"

#include <cmath>

#include "rms/check.h"

namespace rms::esg {

using V = Eigen::Vector3f;

std::string_view PartName(PartId id) {
  static constexpr std::array<std::string_view, static_cast<int>(PartId::kCount)> kNames = {
      "none", "shuttle", "vertical_arm", "shoulder", "upper_boom", "elbow", "lower_boom", "wrist",
      "eff_hex_1", "eff_hex_2", "eff_hex_3", "payload", "receptacle", "probe", "cae"};
  return kNames[static_cast<int>(id)];
}

Rgb IdColor(PartId id) {
  const int i = static_cast<int>(id);
  return {static_cast<std::uint8_t>(i * 16), static_cast<std::uint8_t>(255 - i * 16), 128};
}

double MovingFingerCentreY2(const EndEffectorConfig& ee, double gap) {
  // Face b of EFF HEX 2 is at Y2 = W - t; face e of EFF HEX 3 is `gap` below it.
  const double t = ee.finger_thickness_ft;
  return ee.palm_half_width_ft - t - gap - 0.5 * t;
}

namespace {

constexpr Rgb kWhite{232, 232, 226}, kBayFloor{150, 150, 146}, kBayWall{178, 178, 172},
    kBulkhead{160, 158, 150}, kTile{34, 34, 36}, kRadiator{214, 222, 236}, kWindow{20, 26, 40},
    kEngine{70, 70, 74}, kBoom{238, 238, 238}, kJoint{96, 96, 100}, kPalm{120, 122, 132},
    kFinger{214, 170, 40}, kGold{206, 164, 64}, kBar{36, 36, 36}, kProbeRgb{186, 188, 196},
    kCaeRgb{200, 202, 212}, kPort{24, 24, 28}, kPanel{44, 56, 120};

V F(const Eigen::Vector3d& v) { return v.cast<float>(); }

// Quads of a convex body wound outward from the body's centre.
struct Hull {
  Mesh* mesh;
  V centre;
  void Quad(const V& a, const V& b, const V& c, const V& d, const Rgb& rgb) const {
    const V out = (a + b + c + d) * 0.25f - centre;
    mesh->AddQuad(a, b, c, d, out, rgb);
  }
};

Mesh Shuttle(const LabConfig& cfg) {
  const auto& s = cfg.shuttle;
  const float L = static_cast<float>(s.bay_length_ft);
  const float hw = static_cast<float>(s.bay_width_ft / 2);
  const float D = static_cast<float>(s.bay_depth_ft);
  const float sill = hw + 2.0f;        // outer edge of the longeron / sill
  const float belly = -(D + 5.0f);     // orbiter belly
  Mesh m;
  // Cargo bay interior (top face c open).
  m.AddBoxInterior(V(0, -hw, -D), V(L, hw, 0),
                   {kBulkhead, kBulkhead, kBayWall, kBayWall, kBayFloor, kBayFloor}, 32);
  // Sills and fuselage sides of the mid fuselage.
  for (float sg : {-1.0f, 1.0f}) {
    m.AddQuad(V(0, sg * hw, 0), V(L, sg * hw, 0), V(L, sg * sill, 0), V(0, sg * sill, 0), V(0, 0, 1), kWhite);
    m.AddQuad(V(0, sg * sill, 0), V(L, sg * sill, 0), V(L, sg * sill, belly), V(0, sg * sill, belly),
              V(0, sg, 0), kWhite);
  }
  // Crew cabin and nose.
  {
    const float x0 = -28.0f, xa = -0.05f, top = 6.0f, cw = hw + 1.5f;
    Mesh& mm = m;
    mm.AddBox(V(x0, -cw, belly), V(xa, cw, top), kWhite);
    // Aft flight deck windows on the cabin's aft face.
    for (float sg : {-1.0f, 1.0f}) {
      const float y0 = sg * 0.6f, y1 = sg * 3.2f;
      mm.AddQuad(V(xa + 0.02f, y0, 1.2f), V(xa + 0.02f, y1, 1.2f), V(xa + 0.02f, y1, 4.2f),
                 V(xa + 0.02f, y0, 4.2f), V(1, 0, 0), kWindow);
    }
    const float xn = -44.0f;
    const V c0(x0, 0, (belly + top) / 2), cn(xn, 0, -9.0f);
    Hull h{&mm, (c0 + cn) * 0.5f};
    const V a(x0, -cw, belly), b(x0, cw, belly), c(x0, cw, top), d(x0, -cw, top);
    const V an(xn, -2.5f, -12.0f), bn(xn, 2.5f, -12.0f), cnn(xn, 2.5f, -6.0f), dn(xn, -2.5f, -6.0f);
    h.Quad(a, b, bn, an, kTile);
    h.Quad(b, c, cnn, bn, kWhite);
    h.Quad(c, d, dn, cnn, kWhite);
    h.Quad(d, a, an, dn, kWhite);
    h.Quad(an, bn, cnn, dn, kTile);
    // Forward windows.
    const V w0 = d + 0.35f * (dn - d), w1 = c + 0.35f * (cnn - c);
    h.Quad(w0 + V(0, 1.0f, -0.9f), w1 + V(0, -1.0f, -0.9f), w1 + V(2.0f, -1.0f, -0.3f),
           w0 + V(2.0f, 1.0f, -0.3f), kWindow);
  }
  // Belly under the mid fuselage.
  m.AddQuad(V(0, -sill, belly), V(L, -sill, belly), V(L, sill, belly), V(0, sill, belly), V(0, 0, -1), kTile);
  // Aft fuselage, OMS pods, tail, engines.
  {
    const float xa = L + 0.05f, xe = L + 18.0f;
    m.AddBox(V(xa, -sill, belly), V(xe, sill, 2.0f), kWhite);
    for (float sg : {-1.0f, 1.0f}) {
      const float y0 = sg * 4.5f, y1 = sg * sill;
      m.AddBox(V(L + 2.0f, std::min(y0, y1), 2.0f), V(xe + 2.0f, std::max(y0, y1), 6.0f), kWhite);
    }
    m.AddExtrusion({V(L + 4, -0.8f, 2), V(xe + 4, -0.8f, 2), V(xe + 10, -0.8f, 30), V(xe + 2, -0.8f, 30)},
                   V(0, 1.6f, 0), kWhite);
    m.AddCylinder(V(xe, 0, -3), V(xe + 6, 0, -3), 2.6f, 10, kEngine);
    m.AddCylinder(V(xe, -4.5f, -10), V(xe + 6, -4.5f, -10), 2.6f, 10, kEngine);
    m.AddCylinder(V(xe, 4.5f, -10), V(xe + 6, 4.5f, -10), 2.6f, 10, kEngine);
  }
  // Wings (delta), white above, tiles below.
  for (float sg : {-1.0f, 1.0f}) {
    const float z0 = belly + 1.0f, z1 = belly + 2.6f;
    const V p0(15, sg * sill, 0), p1(L + 15, sg * sill, 0), p2(L + 15, sg * 39, 0), p3(L + 6, sg * 39, 0);
    const auto at = [](V p, float z) { p.z() = z; return p; };
    m.AddQuad(at(p0, z1), at(p1, z1), at(p2, z1), at(p3, z1), V(0, 0, 1), kWhite);
    m.AddQuad(at(p0, z0), at(p1, z0), at(p2, z0), at(p3, z0), V(0, 0, -1), kTile);
    m.AddQuad(at(p0, z0), at(p3, z0), at(p3, z1), at(p0, z1), V(-1, sg * 0.6f, 0), kWhite);
    m.AddQuad(at(p1, z0), at(p2, z0), at(p2, z1), at(p1, z1), V(1, 0, 0), kTile);
    m.AddQuad(at(p2, z0), at(p3, z0), at(p3, z1), at(p2, z1), V(0, sg, 0), kWhite);
  }
  // Payload bay doors, open by door_open_deg about the hinge at each sill.
  {
    const float phi = static_cast<float>(s.door_open_deg * M_PI / 180.0);
    const float width = hw + 2.5f;
    for (float sg : {-1.0f, 1.0f}) {
      const V dir(0, -sg * std::cos(phi), std::sin(phi));  // closed: inboard
      const V a(0, sg * sill, 0.05f), b(L, sg * sill, 0.05f);
      const V c = b + width * dir, d = a + width * dir;
      // AddPanel's front face is (b - a) x (c - a); starboard's front is the
      // inner (radiator) side, port's the outer.
      if (sg > 0) m.AddPanel(a, b, c, d, kRadiator, kWhite);
      else m.AddPanel(a, b, c, d, kWhite, kRadiator);
    }
  }
  return m;
}

Mesh Box(const V& lo, const V& hi, const Rgb& rgb) {
  Mesh m;
  m.AddBox(lo, hi, rgb);
  return m;
}

Mesh Payload(const PayloadConfig& p, Mesh* receptacle, Mesh* probe) {
  const float r = static_cast<float>(p.diameter_ft / 2), hl = static_cast<float>(p.length_ft / 2);
  Mesh body;
  const float phase = static_cast<float>(M_PI / 16);  // a flat on top (+z_P)
  body.AddCylinder(V(0, -hl, 0), V(0, hl, 0), r, 16, kGold, true, phase);
  // Bar receptacle and two posts down to the body's top flat.
  const V bc = F(p.p_PoBar_P_ft), bs = F(p.bar_size_P_ft);
  receptacle->AddBox(bc - 0.5f * bs, bc + 0.5f * bs, kBar);
  const float top = r * std::cos(phase) - 0.1f;
  const float post = std::min(0.3f, 0.4f * bs.x());
  for (float sg : {-1.0f, 1.0f}) {
    const float x = bc.x() + sg * (0.5f * bs.x() - 0.5f * post);
    const float z1 = bc.z() - 0.5f * bs.z();
    if (z1 > top) {
      receptacle->AddBox(V(x - 0.5f * post, bc.y() - 0.5f * post, top),
                         V(x + 0.5f * post, bc.y() + 0.5f * post, z1), kBar);
    }
  }
  const float pr = static_cast<float>(p.probe_diameter_ft / 2);
  const float pl = static_cast<float>(p.probe_length_ft);
  probe->AddCylinder(V(0, hl, 0), V(0, hl + 0.8f * pl, 0), pr, 10, kProbeRgb);
  probe->AddCylinder(V(0, hl + 0.8f * pl, 0), V(0, hl + pl, 0), 0.6f * pr, 10, kProbeRgb);
  return body;
}

Mesh Cae(const CaeConfig& c) {
  const float fl = static_cast<float>(c.across_flats_ft);
  const float rc = fl / std::sqrt(3.0f);
  const float hl = static_cast<float>(c.length_ft / 2);
  std::vector<V> hex;
  for (int k = 0; k < 6; ++k) {
    const float a = static_cast<float>(k * M_PI / 3);
    hex.push_back(V(rc * std::cos(a), fl / 2 + rc * std::sin(a), -hl));
  }
  Mesh m;
  m.AddExtrusion(hex, V(0, 0, 2 * hl), kCaeRgb);
  // Docking port on face c (y_C = 0), protruding outward (-y_C).
  m.AddCylinder(V(0, 0.02f, 0), V(0, -0.4f, 0), static_cast<float>(c.port_diameter_ft / 2), 12, kPort);
  // Solar arrays on the far side.
  for (float sg : {-1.0f, 1.0f}) {
    const float x0 = sg * (rc + 1.0f), x1 = sg * (rc + 31.0f);
    m.AddBox(V(std::min(x0, x1), fl / 2 - 0.1f, -8), V(std::max(x0, x1), fl / 2 + 0.1f, 8), kPanel);
  }
  return m;
}

}  // namespace

StaticModels BuildStaticModels(const LabConfig& cfg) {
  const auto& arm = cfg.arm;
  const auto& ee = cfg.end_effector;
  const float r = static_cast<float>(arm.boom_diameter_ft / 2);
  StaticModels s;
  s.parts.resize(static_cast<int>(PartId::kCount) - 1);
  auto put = [&](PartId id, Mesh m) { s.parts[static_cast<int>(id) - 1] = {id, std::move(m)}; };

  put(PartId::kShuttle, Shuttle(cfg));
  put(PartId::kVerticalArm, Box(V(-0.6f, -0.6f, 0), V(0.6f, 0.6f, 1), kWhite));  // unit height
  put(PartId::kShoulder, Box(V(-0.9f, -0.9f, -0.9f), V(0.9f, 0.9f, 0.9f), kJoint));
  {
    Mesh m;
    m.AddCylinder(V(0.9f, 0, 0), V(static_cast<float>(arm.upper_boom_ft) - 0.7f, 0, 0), r, 12, kBoom);
    put(PartId::kUpperBoom, std::move(m));
  }
  put(PartId::kElbow, Box(V(-0.7f, -0.7f, -0.7f), V(0.7f, 0.7f, 0.7f), kJoint));
  {
    Mesh m;
    m.AddCylinder(V(0.7f, 0, 0), V(static_cast<float>(arm.lower_boom_ft) - 0.6f, 0, 0), r * 0.9f, 12, kBoom);
    put(PartId::kLowerBoom, std::move(m));
  }
  {
    Mesh m;
    m.AddBox(V(-0.6f, -0.6f, -0.6f), V(0.6f, 0.6f, 0.6f), kJoint);
    m.AddCylinder(V(0.6f, 0, 0), V(static_cast<float>(arm.wrist_to_palm_ft), 0, 0), 0.45f, 10, kJoint);
    put(PartId::kWrist, std::move(m));
  }
  const float L = static_cast<float>(ee.palm_length_ft), W = static_cast<float>(ee.palm_half_width_ft),
              H = static_cast<float>(ee.palm_half_height_ft), fl = static_cast<float>(ee.finger_length_ft),
              t = static_cast<float>(ee.finger_thickness_ft);
  put(PartId::kEffHex1, Box(V(0, -W, -H), V(L, W, H), kPalm));
  put(PartId::kEffHex2, Box(V(L, W - t, -H), V(L + fl, W, H), kFinger));
  put(PartId::kEffHex3, Box(V(L, -t / 2, -H), V(L + fl, t / 2, H), kFinger));
  {
    Mesh receptacle, probe;
    Mesh body = Payload(cfg.payload, &receptacle, &probe);
    put(PartId::kPayload, std::move(body));
    put(PartId::kReceptacle, std::move(receptacle));
    put(PartId::kProbe, std::move(probe));
  }
  put(PartId::kCae, Cae(cfg.cae));
  for (int i = 0; i < static_cast<int>(PartId::kCount) - 1; ++i) {
    RMS_CHECK(static_cast<int>(s.parts[i].id) == i + 1);
  }
  return s;
}

}  // namespace rms::esg
