#include "rms/scene_model/scene_model.h"

#include <algorithm>
#include <cmath>

#include "rms/arm/kinematics.h"
#include "rms/base/check.h"

namespace rms::scene_model {

using V = Eigen::Vector3f;

std::string_view ClusterName(int id) {
  static constexpr std::array<std::string_view, kNumClusters> kNames = {
      "floor",       "wall_port",  "wall_stbd", "bulkhead_fwd",  "bulkhead_aft", "sill_port",
      "sill_stbd",   "side_port",  "side_stbd", "cabin",         "aft_fuselage", "tail",
      "wing_port",   "wing_stbd",  "door_port", "door_stbd",     "cae_module",   "cae_array",
      "dock_target", "post",       "shoulder",  "upper_boom",    "elbow",        "lower_boom",
      "wrist",       "eff_hex_1",  "eff_hex_2", "eff_hex_3",     "payload_body", "bar",
      "bar_post_a",  "bar_post_b", "probe",     "grapple_target"};
  return id >= 0 && id < kNumClusters ? kNames[id] : "?";
}

Eigen::Vector3d GrappleTargetCentre_P(const PayloadConfig& p) {
  // Half a foot beyond the bar's -x_P end, its top 0.1 ft below the bar's bottom.
  return {p.p_PoBar_P_ft.x() - 0.5 * p.bar_size_P_ft.x() - 0.5, p.p_PoBar_P_ft.y(),
          p.p_PoBar_P_ft.z() - 0.5 * p.bar_size_P_ft.z() - 0.1};
}

double PayloadTopFlat_P(const PayloadConfig& p) {
  return 0.5 * p.diameter_ft * std::cos(M_PI / 16);
}

BarPostBoxes BarPosts_P(const PayloadConfig& p) {
  BarPostBoxes b;
  const Eigen::Vector3d& bc = p.p_PoBar_P_ft;
  const Eigen::Vector3d& bs = p.bar_size_P_ft;
  const double post = std::min(0.3, 0.4 * bs.x());
  const double z0 = PayloadTopFlat_P(p), z1 = bc.z() - 0.5 * bs.z();
  if (!(z1 - z0 > 2 * kClusterClearanceFt)) return b;
  b.count = 2;
  b.half_P = Eigen::Vector3d(0.5 * post, 0.5 * post, 0.5 * (z1 - z0));
  for (int k = 0; k < 2; ++k) {
    const double x = bc.x() + (k ? 1.0 : -1.0) * (0.5 * bs.x() - 0.5 * post);
    b.centre_P[k] = Eigen::Vector3d(x, bc.y(), 0.5 * (z0 + z1));
  }
  return b;
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
    kFinger{214, 170, 40}, kGold{206, 164, 64}, kBarRgb{36, 36, 36}, kProbeRgb{186, 188, 196},
    kCaeRgb{200, 202, 212}, kPort{24, 24, 28}, kPanel{44, 56, 120}, kTargetWhite{246, 246, 240},
    kTargetBlack{12, 12, 12};

constexpr float kDecalOffset = 0.02f;  // ft off the face a decal marks
constexpr float kGap = static_cast<float>(kClusterClearanceFt);

V F(const Eigen::Vector3d& v) { return v.cast<float>(); }

// Quads of a convex body wound outward from the body's centre.
struct Hull {
  Mesh* mesh;
  V centre;
  void Quad(const V& a, const V& b, const V& c, const V& d, const Rgb& rgb) const {
    mesh->AddQuad(a, b, c, d, (a + b + c + d) * 0.25f - centre, rgb);
  }
};

// A regular polygon decal on the plane through `centre` with normal `n`.
void Disc(Mesh* m, const V& centre, const V& n, float radius, int sides, const Rgb& rgb) {
  const V helper = std::abs(n.x()) < 0.9f ? V::UnitX() : V::UnitY();
  const V u = n.cross(helper).normalized(), v = n.cross(u);
  for (int i = 0; i < sides; ++i) {
    const float a0 = 2.0f * static_cast<float>(M_PI) * i / sides,
                a1 = 2.0f * static_cast<float>(M_PI) * (i + 1) / sides;
    m->AddTri(centre, centre + radius * (std::cos(a0) * u + std::sin(a0) * v),
              centre + radius * (std::cos(a1) * u + std::sin(a1) * v), n, rgb);
  }
}

struct ShuttleDims {
  float L, hw, D, sill, belly;
};

// The cargo bay's interior faces (its top face c is open), the longerons'
// tops and the mid fuselage's sides.
void BuildBay(const ShuttleDims& d, std::array<Cluster, kNumClusters>* c) {
  auto quad = [&](ClusterId id, const V& a, const V& b, const V& cc, const V& dd, const V& out,
                  Rgb rgb) { (*c)[id].mesh.AddQuad(a, b, cc, dd, out, rgb); };
  quad(kFloor, V(0, -d.hw, -d.D), V(d.L, -d.hw, -d.D), V(d.L, d.hw, -d.D), V(0, d.hw, -d.D),
       V(0, 0, 1), kBayFloor);
  quad(kWallPort, V(0, -d.hw, -d.D), V(d.L, -d.hw, -d.D), V(d.L, -d.hw, 0), V(0, -d.hw, 0),
       V(0, 1, 0), kBayWall);
  quad(kWallStbd, V(0, d.hw, -d.D), V(d.L, d.hw, -d.D), V(d.L, d.hw, 0), V(0, d.hw, 0), V(0, -1, 0),
       kBayWall);
  quad(kBulkheadFwd, V(0, -d.hw, -d.D), V(0, d.hw, -d.D), V(0, d.hw, 0), V(0, -d.hw, 0), V(1, 0, 0),
       kBulkhead);
  quad(kBulkheadAft, V(d.L, -d.hw, -d.D), V(d.L, d.hw, -d.D), V(d.L, d.hw, 0), V(d.L, -d.hw, 0),
       V(-1, 0, 0), kBulkhead);
  // The longerons' tops and the mid fuselage's sides.
  quad(kSillPort, V(0, -d.sill, 0), V(d.L, -d.sill, 0), V(d.L, -d.hw, 0), V(0, -d.hw, 0),
       V(0, 0, 1), kWhite);
  quad(kSillStbd, V(0, d.hw, 0), V(d.L, d.hw, 0), V(d.L, d.sill, 0), V(0, d.sill, 0), V(0, 0, 1),
       kWhite);
  quad(kSidePort, V(0, -d.sill, 0), V(d.L, -d.sill, 0), V(d.L, -d.sill, d.belly),
       V(0, -d.sill, d.belly), V(0, -1, 0), kWhite);
  quad(kSideStbd, V(0, d.sill, 0), V(d.L, d.sill, 0), V(d.L, d.sill, d.belly),
       V(0, d.sill, d.belly), V(0, 1, 0), kWhite);
}

void BuildCabin(const ShuttleDims& d, std::array<Cluster, kNumClusters>* c) {
  // The crew cabin and its nose: one convex solid (a box and the frustum on
  // its front face); the aft flight deck windows and the forward windows are
  // decals.
  Mesh& m = (*c)[kCabin].mesh;
  const float x0 = -28.0f, xa = -0.05f, top = 6.0f, cw = d.hw + 1.5f, xn = -44.0f;
  const V a(x0, -cw, d.belly), b(x0, cw, d.belly), cc(x0, cw, top), dd(x0, -cw, top);
  const V ea(xa, -cw, d.belly), eb(xa, cw, d.belly), ec(xa, cw, top), ed(xa, -cw, top);
  const V an(xn, -2.5f, -12.0f), bn(xn, 2.5f, -12.0f), cn(xn, 2.5f, -6.0f), dn(xn, -2.5f, -6.0f);
  Hull h{&m, V((x0 + xa + 2 * xn) / 4, 0, (d.belly + top) / 2)};
  h.Quad(ea, eb, ec, ed, kWhite);  // aft face
  h.Quad(a, b, eb, ea, kTile);     // belly
  h.Quad(dd, cc, ec, ed, kWhite);  // roof
  h.Quad(a, dd, ed, ea, kWhite);   // port side
  h.Quad(b, cc, ec, eb, kWhite);   // starboard side
  h.Quad(a, b, bn, an, kTile);     // nose, underside
  h.Quad(b, cc, cn, bn, kWhite);
  h.Quad(cc, dd, dn, cn, kWhite);
  h.Quad(dd, a, an, dn, kWhite);
  h.Quad(an, bn, cn, dn, kTile);  // nose tip
  m.SetDecal(true);
  for (float sg : {-1.0f, 1.0f}) {  // aft flight deck windows
    const float y0 = sg * 0.6f, y1 = sg * 3.2f, x = xa + kDecalOffset;
    m.AddQuad(V(x, y0, 1.2f), V(x, y1, 1.2f), V(x, y1, 4.2f), V(x, y0, 4.2f), V(1, 0, 0), kWindow);
  }
  // Forward windows on the sloping roof of the nose.
  V up = (cn - cc).cross(dd - cc).normalized();
  if (up.z() < 0) up = -up;  // the sloping roof's outward normal
  const V side = (dd - cc).normalized(), fwd = (cn - cc).normalized();
  const V w0 = cc + 0.15f * (cn - cc) + kDecalOffset * up;
  m.AddQuad(w0 + 1.0f * side, w0 + 1.0f * side + 2.5f * fwd,
            w0 + (2 * cw - 1.0f) * side + 2.5f * fwd, w0 + (2 * cw - 1.0f) * side, up, kWindow);
  m.SetDecal(false);
}

void BuildAftFuselage(const ShuttleDims& d, std::array<Cluster, kNumClusters>* c) {
  // Aft fuselage with the main engines' bells as decals on its aft face.
  Mesh& m = (*c)[kAftFuselage].mesh;
  const float xa = d.L + 0.05f, xe = d.L + 18.0f;
  m.AddBox(V(xa, -d.sill, d.belly), V(xe, d.sill, 2.0f), kWhite);
  m.SetDecal(true);
  for (const V& e : {V(xe + kDecalOffset, 0, -3), V(xe + kDecalOffset, -4.5f, -10),
                     V(xe + kDecalOffset, 4.5f, -10)}) {
    Disc(&m, e, V(1, 0, 0), 2.6f, 10, kEngine);
  }
  m.SetDecal(false);
  (*c)[kTail].mesh.AddExtrusion({V(d.L + 4, -0.8f, 2 + kGap), V(xe + 4, -0.8f, 2 + kGap),
                                 V(xe + 10, -0.8f, 30), V(xe + 2, -0.8f, 30)},
                                V(0, 1.6f, 0), kWhite);
}

void BuildWings(const ShuttleDims& d, std::array<Cluster, kNumClusters>* c) {
  // Wings (delta): white above, tiles below; the root lies against the side.
  for (float sg : {-1.0f, 1.0f}) {
    Mesh& m = (*c)[sg < 0 ? kWingPort : kWingStbd].mesh;
    const float z0 = d.belly + 1.0f, z1 = d.belly + 2.6f;
    const float root = d.sill + kGap;
    const V p0(15, sg * root, 0), p1(d.L + 15, sg * root, 0), p2(d.L + 15, sg * 39, 0),
        p3(d.L + 6, sg * 39, 0);
    const auto at = [](V p, float z) {
      p.z() = z;
      return p;
    };
    m.AddQuad(at(p0, z1), at(p1, z1), at(p2, z1), at(p3, z1), V(0, 0, 1), kWhite);
    m.AddQuad(at(p0, z0), at(p1, z0), at(p2, z0), at(p3, z0), V(0, 0, -1), kTile);
    m.AddQuad(at(p0, z0), at(p3, z0), at(p3, z1), at(p0, z1), V(-1, sg * 0.6f, 0), kWhite);
    m.AddQuad(at(p1, z0), at(p2, z0), at(p2, z1), at(p1, z1), V(1, 0, 0), kTile);
    m.AddQuad(at(p2, z0), at(p3, z0), at(p3, z1), at(p2, z1), V(0, sg, 0), kWhite);
  }
}

void BuildDoors(const ShuttleConfig& s, const ShuttleDims& d,
                std::array<Cluster, kNumClusters>* c) {
  // The payload bay doors, open by door_open_deg about the hinge at each
  // longeron: thin slabs. Closed, a door reaches inboard with its radiators
  // facing down; opening turns it up and over, so at 175 deg the radiators
  // face (almost) straight up.
  const float phi = static_cast<float>(s.door_open_deg * M_PI / 180.0);
  const float width = d.hw + 2.5f, thick = 0.1f;
  for (float sg : {-1.0f, 1.0f}) {
    Mesh& m = (*c)[sg < 0 ? kDoorPort : kDoorStbd].mesh;
    const V dir(0, -sg * std::cos(phi), std::sin(phi));    // from the hinge across the door
    const V n_in(0, -sg * std::sin(phi), -std::cos(phi));  // the radiator side's normal
    const V a(0, sg * d.sill, 0.1f), b(d.L, sg * d.sill, 0.1f), cc = b + width * dir,
                                                                dd = a + width * dir;
    const V back = -thick * n_in;  // the outer skin, one thickness behind the radiators
    Hull h{&m, (a + cc) * 0.5f + 0.5f * back};
    h.Quad(a, b, cc, dd, kRadiator);
    h.Quad(a + back, b + back, cc + back, dd + back, kWhite);
    h.Quad(a, b, b + back, a + back, kWhite);
    h.Quad(b, cc, cc + back, b + back, kWhite);
    h.Quad(cc, dd, dd + back, cc + back, kWhite);
    h.Quad(dd, a, a + back, dd + back, kWhite);
  }
}

void BuildShuttle(const ShuttleConfig& s, std::array<Cluster, kNumClusters>* c) {
  const ShuttleDims d{static_cast<float>(s.bay_length_ft), static_cast<float>(s.bay_width_ft / 2),
                      static_cast<float>(s.bay_depth_ft),
                      static_cast<float>(s.bay_width_ft / 2) + 2.0f,
                      -static_cast<float>(s.bay_depth_ft) - 5.0f};
  BuildBay(d, c);
  BuildCabin(d, c);
  BuildAftFuselage(d, c);
  BuildWings(d, c);
  BuildDoors(s, d, c);
}

void BuildCae(const CaeConfig& cae, std::array<Cluster, kNumClusters>* c) {
  const float fl = static_cast<float>(cae.across_flats_ft);
  const float rc = fl / std::sqrt(3.0f);
  const float hl = static_cast<float>(cae.length_ft / 2);
  std::vector<V> hex;
  for (int k = 0; k < 6; ++k) {
    const float a = static_cast<float>(k * M_PI / 3);
    hex.push_back(V(rc * std::cos(a), fl / 2 + rc * std::sin(a), -hl));
  }
  Mesh& m = (*c)[kCaeModule].mesh;
  m.AddExtrusion(hex, V(0, 0, 2 * hl), kCaeRgb);
  m.SetDecal(true);  // the docking port on face c (y_C = 0), facing out (-y_C)
  const float pr = static_cast<float>(cae.port_diameter_ft / 2);
  Disc(&m, V(0, -kDecalOffset, 0), V(0, -1, 0), 1.25f * pr, 16,
       kTargetWhite);  // a white rim round the port
  Disc(&m, V(0, -2 * kDecalOffset, 0), V(0, -1, 0), pr, 16, kPort);
  // The docking target beside the port (docs/scene.md "Targets"): a black
  // disc with a white rim on face c, and a white cross standing off it, so
  // seen from off its axis the cross moves off the disc's centre.
  const V at(0, 0, static_cast<float>(kDockTargetAlongFt));
  Disc(&m, at + V(0, -kDecalOffset, 0), V(0, -1, 0), 0.9f, 16, kTargetWhite);
  Disc(&m, at + V(0, -2 * kDecalOffset, 0), V(0, -1, 0), 0.75f, 16, kTargetBlack);
  m.SetDecal(false);
  // Its standoff: a white plate with a black cross, kDockTargetStandoffFt
  // out from face c (the post that would hold it is left out).
  Mesh& t = (*c)[kDockTarget].mesh;
  const float so = static_cast<float>(kDockTargetStandoffFt), half = 0.3f, thick = 0.05f,
              arm = 0.25f, bar = 0.04f;
  t.AddBox(at + V(-half, -so - thick, -half), at + V(half, -so, half), kTargetWhite);
  t.SetDecal(true);
  const float y = -so - thick - kDecalOffset;
  t.AddQuad(at + V(-arm, y, -bar), at + V(arm, y, -bar), at + V(arm, y, bar), at + V(-arm, y, bar),
            V(0, -1, 0), kTargetBlack);
  t.AddQuad(at + V(-bar, y - kDecalOffset, -arm), at + V(bar, y - kDecalOffset, -arm),
            at + V(bar, y - kDecalOffset, arm), at + V(-bar, y - kDecalOffset, arm), V(0, -1, 0),
            kTargetBlack);
  t.SetDecal(false);
  // The solar array on a boom above the module's far side.
  (*c)[kCaeArray].mesh.AddBox(V(-35, fl + 0.6f, -6), V(35, fl + 0.8f, 6), kPanel);
}

void BuildArm(const LabConfig& cfg, std::array<Cluster, kNumClusters>* c) {
  const auto& arm = cfg.arm;
  const auto& ee = cfg.end_effector;
  const float r = static_cast<float>(arm.boom_diameter_ft / 2);
  const float rs = static_cast<float>(kShoulderRadiusFt), re = static_cast<float>(kElbowRadiusFt),
              rw = static_cast<float>(kWristRadiusFt);
  (*c)[kPost].mesh.AddBox(V(-0.6f, -0.6f, 0), V(0.6f, 0.6f, 1),
                          kWhite);  // unit height, placed with clearances
  (*c)[kShoulder].mesh.AddCylinder(V(0, -rs, 0), V(0, rs, 0), rs, 12, kJoint);
  (*c)[kUpperBoom].mesh.AddCylinder(
      V(rs + kGap, 0, 0), V(static_cast<float>(arm.upper_boom_ft) - re - kGap, 0, 0), r, 12, kBoom);
  (*c)[kElbow].mesh.AddCylinder(V(0, -re, 0), V(0, re, 0), re, 12, kJoint);
  (*c)[kLowerBoom].mesh.AddCylinder(
      V(re + kGap, 0, 0), V(static_cast<float>(arm.lower_boom_ft - kWristClearanceFt), 0, 0),
      0.9f * r, 12, kBoom);
  (*c)[kWrist].mesh.AddCylinder(
      V(-rw, 0, 0), V(static_cast<float>(arm.wrist_to_palm_ft) - kGap, 0, 0), rw, 10, kJoint);
  const float L = static_cast<float>(ee.palm_length_ft),
              W = static_cast<float>(ee.palm_half_width_ft),
              H = static_cast<float>(ee.palm_half_height_ft),
              fl = static_cast<float>(ee.finger_length_ft),
              t = static_cast<float>(ee.finger_thickness_ft);
  (*c)[kEffHex1].mesh.AddBox(V(0, -W, -H), V(L, W, H), kPalm);
  (*c)[kEffHex2].mesh.AddBox(V(L + kGap, W - t, -H), V(L + fl, W, H), kFinger);
  (*c)[kEffHex3].mesh.AddBox(V(L + kGap, -t / 2, -H), V(L + fl, t / 2, H), kFinger);
}

void BuildPayload(const PayloadConfig& p, std::array<Cluster, kNumClusters>* c) {
  const float r = static_cast<float>(p.diameter_ft / 2), hl = static_cast<float>(p.length_ft / 2);
  const float phase = static_cast<float>(M_PI / 16);  // a flat on top (+z_P)
  (*c)[kPayloadBody].mesh.AddCylinder(V(0, -hl, 0), V(0, hl, 0), r, 16, kGold, true, phase);
  const V bc = F(p.p_PoBar_P_ft), bs = F(p.bar_size_P_ft);
  (*c)[kBar].mesh.AddBox(bc - 0.5f * bs, bc + 0.5f * bs, kBarRgb);
  // The grapple target (docs/scene.md "Targets"): a white plate with a black
  // cross standing off the body beside the bar's end, over a black disc with
  // a white rim on the body: from the wrist camera at the grasp the cross
  // sits on the crosshair, centred in the disc; off, it moves off both.
  {
    const V at = F(GrappleTargetCentre_P(p));
    const float half = 0.25f, thick = 0.05f, arm = 0.2f, bar = 0.035f;
    Mesh& t = (*c)[kGrappleTarget].mesh;
    t.AddBox(at + V(-half, -half, -thick), at + V(half, half, 0), kTargetWhite);
    t.SetDecal(true);
    const float z = at.z() + kDecalOffset;
    t.AddQuad(V(at.x() - arm, at.y() - bar, z), V(at.x() + arm, at.y() - bar, z),
              V(at.x() + arm, at.y() + bar, z), V(at.x() - arm, at.y() + bar, z), V(0, 0, 1),
              kTargetBlack);
    t.AddQuad(V(at.x() - bar, at.y() - arm, z + kDecalOffset),
              V(at.x() + bar, at.y() - arm, z + kDecalOffset),
              V(at.x() + bar, at.y() + arm, z + kDecalOffset),
              V(at.x() - bar, at.y() + arm, z + kDecalOffset), V(0, 0, 1), kTargetBlack);
    t.SetDecal(false);
    // The disc on the body's facet under it (the facet next to the top flat).
    Mesh& body = (*c)[kPayloadBody].mesh;
    const float a =
        static_cast<float>(M_PI / 2 + 2 * phase);  // the facet's middle: 22.5 deg from the top
    const V n(std::cos(a) * (at.x() < 0 ? 1.0f : -1.0f), 0, std::sin(a));
    const float facet_r = r * std::cos(phase);  // the facets' distance from the axis
    // Where the line from the plate straight down (-z_P) meets the facet.
    const float z_on = (facet_r - n.x() * at.x()) / n.z();
    const V on(at.x(), at.y(), z_on);
    body.SetDecal(true);
    Disc(&body, on + kDecalOffset * n, n, 0.45f, 16, kTargetWhite);
    Disc(&body, on + 2 * kDecalOffset * n, n, 0.35f, 16, kTargetBlack);
    body.SetDecal(false);
  }
  // The posts, drawn clear of the body's flat and of the bar by the clusters' clearance.
  const BarPostBoxes posts = BarPosts_P(p);
  for (int k = 0; k < posts.count; ++k) {
    const V lo = F(posts.centre_P[k] - posts.half_P), hi = F(posts.centre_P[k] + posts.half_P);
    (*c)[k ? kBarPostB : kBarPostA].mesh.AddBox(V(lo.x(), lo.y(), lo.z() + kGap),
                                                V(hi.x(), hi.y(), hi.z() - kGap), kBarRgb);
  }
  const float pr = static_cast<float>(p.probe_diameter_ft / 2);
  (*c)[kProbe].mesh.AddFrustum(V(0, hl + kGap, 0),
                               V(0, hl + static_cast<float>(p.probe_length_ft), 0), pr, 0.6f * pr,
                               10, kProbeRgb);
}

// Unique (within tolerance) unit directions, up to sign when `signless`.
void AddUnique(std::vector<Eigen::Vector3d>* set, Eigen::Vector3d d, bool signless) {
  const double n = d.norm();
  if (!(n > 1e-9)) return;
  d /= n;
  for (const auto& e : *set) {
    if ((e - d).norm() < 1e-7 || (signless && (e + d).norm() < 1e-7)) return;
  }
  set->push_back(d);
}

void FillHullData(Cluster* c) {
  for (const Triangle& t : c->mesh.triangles()) {
    for (const V* v : {&t.a, &t.b, &t.c}) {
      const Eigen::Vector3d p = v->cast<double>();
      if (std::none_of(c->points.begin(), c->points.end(),
                       [&](const auto& q) { return (q - p).norm() < 1e-6; })) {
        c->points.push_back(p);
      }
    }
    AddUnique(&c->normals, t.n.cast<double>(), false);
    AddUnique(&c->edges, (t.b - t.a).cast<double>(), true);
    AddUnique(&c->edges, (t.c - t.b).cast<double>(), true);
    AddUnique(&c->edges, (t.a - t.c).cast<double>(), true);
  }
  c->flat = c->normals.size() == 1;
  if (c->flat) {  // a flat polygon also separates along its edges' in-plane normals
    const Eigen::Vector3d n = c->normals[0];
    const std::vector<Eigen::Vector3d> edges = c->edges;
    for (const auto& e : edges) AddUnique(&c->normals, n.cross(e), true);
  }
}

}  // namespace

SceneModel BuildSceneModel(const LabConfig& cfg) {
  SceneModel s;
  auto& c = s.clusters;
  for (int i = 0; i < kNumClusters; ++i) c[i].id = static_cast<ClusterId>(i);
  BuildShuttle(cfg.shuttle, &c);
  BuildCae(cfg.cae, &c);
  BuildArm(cfg, &c);
  BuildPayload(cfg.payload, &c);
  for (int i = 0; i < kNumClusters; ++i) {
    Cluster& k = c[i];
    if (i <= kDoorStbd) {
      k.frame = ClusterFrame::kReference;
      k.group = ClusterGroup::kShuttle;
    } else if (i <= kDockTarget) {
      k.frame = ClusterFrame::kCae;
      k.group = ClusterGroup::kCae;
    } else if (i <= kEffHex3) {
      k.group = ClusterGroup::kArm;
    } else {
      k.frame = ClusterFrame::kPayload;
      k.group = ClusterGroup::kPayload;
    }
  }
  c[kPost].frame = ClusterFrame::kPost;
  c[kShoulder].frame = ClusterFrame::kF1;
  c[kUpperBoom].frame = ClusterFrame::kF2;
  c[kElbow].frame = ClusterFrame::kF3;
  c[kLowerBoom].frame = ClusterFrame::kF3;
  c[kWrist].frame = ClusterFrame::kF6;
  c[kEffHex1].frame = ClusterFrame::kSystemTwo;
  c[kEffHex2].frame = ClusterFrame::kSystemTwo;
  c[kEffHex3].frame = ClusterFrame::kFinger3;
  for (Cluster& k : c) FillHullData(&k);
  return s;
}

ClusterPoses ComputeClusterPoses(const LabConfig& config, const ScenePose& f) {
  const arm::ArmPose arm = arm::ComputeArmPose(config.arm, f.arm, f.shoulder_height_ft);
  auto aff = [](const Eigen::Isometry3d& X) { return Eigen::Affine3d(X.matrix()); };
  ClusterPoses p;
  p.present.fill(true);
  const Eigen::Affine3d X_RC = aff(arm::MakeIsometry(config.cae.R_RC, config.cae.p_RoCo_R_ft));
  const Eigen::Affine3d X_RP = aff(arm::MakeIsometry(f.R_RP, f.p_RoPo_R_ft));
  Eigen::Affine3d post = Eigen::Affine3d::Identity();
  post.translation() = arm.p_RoB_R + Eigen::Vector3d(0, 0, kClusterClearanceFt);
  const double post_len = f.shoulder_height_ft - kShoulderRadiusFt - 2 * kClusterClearanceFt;
  post.linear() = Eigen::Vector3d(1, 1, std::max(post_len, 1e-6)).asDiagonal();
  p.present[kPost] = post_len > 0;
  const Eigen::Affine3d X_RF3 = aff(arm.X_RF3), X_RS2 = aff(arm.X_RS2);
  for (int i = 0; i < kNumClusters; ++i) {
    if (i <= kDoorStbd)
      p.X_RC[i] = Eigen::Affine3d::Identity();
    else if (i <= kDockTarget)
      p.X_RC[i] = X_RC;
    else if (i >= kPayloadBody)
      p.X_RC[i] = X_RP;
  }
  p.X_RC[kPost] = post;
  p.X_RC[kShoulder] = aff(arm.X_RF1);
  p.X_RC[kUpperBoom] = aff(arm.X_RF2);
  p.X_RC[kElbow] = X_RF3;
  p.X_RC[kLowerBoom] = X_RF3;
  p.X_RC[kWrist] = aff(arm.X_RF6);
  p.X_RC[kEffHex1] = X_RS2;
  p.X_RC[kEffHex2] = X_RS2;
  p.X_RC[kEffHex3] = X_RS2 * Eigen::Translation3d(
                                 0, MovingFingerCentreY2(config.end_effector, f.finger_gap_ft), 0);
  return p;
}

}  // namespace rms::scene_model
