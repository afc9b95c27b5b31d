#include "rms/dcp_model/dcp_models.h"

#include <cmath>
#include <cstdio>

#include "rms/scene_model/scene_model.h"

namespace rms::dcp_model {

EndEffectorModel MakeEndEffector(const EndEffectorConfig& ee, const Eigen::Isometry3d& X_RS2,
                                 double gap) {
  // The Reference coordinates of the three System-Two unit vectors.
  const Eigen::Vector3d UX2 = X_RS2.linear().col(0), UY2 = X_RS2.linear().col(1),
                        UZ2 = X_RS2.linear().col(2);
  const Eigen::Vector3d A = X_RS2.translation();
  const double L = ee.palm_length_ft, W = ee.palm_half_width_ft, H = ee.palm_half_height_ft;
  const double fl = ee.finger_length_ft, t = ee.finger_thickness_ft;
  EndEffectorModel m;
  m.hex[0] = MakeBox(A, UX2, UY2, UZ2, L, W, H);
  const Eigen::Vector3d palm_bottom = A + L * UX2;
  m.hex[1] = MakeBox(palm_bottom + (W - 0.5 * t) * UY2, UX2, UY2, UZ2, fl, 0.5 * t, H);
  m.hex[2] = MakeBox(palm_bottom + (W - t - gap - 0.5 * t) * UY2, UX2, UY2, UZ2, fl, 0.5 * t, H);
  return m;
}

Hexahedron MakeBar(const PayloadConfig& p, const Eigen::Isometry3d& X_RP) {
  const Eigen::Matrix3d& R = X_RP.linear();
  const Eigen::Vector3d u = R.col(0), v = -R.col(1), w = -R.col(2);
  const Eigen::Vector3d centre = X_RP * p.p_PoBar_P_ft;
  const Eigen::Vector3d& size = p.bar_size_P_ft;
  return MakeBox(centre - 0.5 * size.x() * u, u, v, w, size.x(), 0.5 * size.y(), 0.5 * size.z());
}

int MakeBarPosts(const PayloadConfig& p, const Eigen::Isometry3d& X_RP,
                 std::array<Hexahedron, 2>* posts) {
  const scene_model::BarPostBoxes b = scene_model::BarPosts_P(p);
  const Eigen::Matrix3d& R = X_RP.linear();
  for (int k = 0; k < b.count; ++k) {
    const Eigen::Vector3d centre = X_RP * b.centre_P[k];
    (*posts)[k] = MakeBox(centre - b.half_P.x() * R.col(0), R.col(0), R.col(1), R.col(2),
                          2 * b.half_P.x(), b.half_P.y(), b.half_P.z());
  }
  return b.count;
}

PayloadShape MakePayloadShape(const PayloadConfig& p) {
  PayloadShape s;
  s.half_len = 0.5 * p.length_ft;
  s.probe_length = p.probe_length_ft;
  s.probe_radius = 0.5 * p.probe_diameter_ft;
  const double r = 0.5 * p.diameter_ft;
  // The 16-gon's vertex levels from the top: level j at angle (2j + 1) pi/16
  // from +z_P, z = r cos, half-width r sin (scene_model.cc draws the same).
  for (int j = 0; j < 8; ++j) {
    const double a = (2 * j + 1) * M_PI / kBodySides;
    s.level_z[j] = r * std::cos(a);
    s.level_hx[j] = r * std::sin(a);
  }
  // The rings: vertex k at angle (2k + 1) pi/16 round y_P from +z_P toward +x_P.
  for (int k = 0; k < kBodySides; ++k) {
    const double a = (2 * k + 1) * M_PI / kBodySides;
    s.ring_x[k] = r * std::sin(a);
    s.ring_z[k] = r * std::cos(a);
  }
  for (int j = 0; j < 6; ++j) {
    const double a = j * M_PI / 3.0;
    s.tip_cos[j] = std::cos(a);
    s.tip_sin[j] = std::sin(a);
  }
  return s;
}

PayloadModel MakePayload(const PayloadShape& s, const Eigen::Isometry3d& X_RP, bool with_body) {
  const Eigen::Matrix3d& R = X_RP.linear();
  const Eigen::Vector3d xP = R.col(0), yP = R.col(1), zP = R.col(2);
  const Eigen::Vector3d centre = X_RP.translation();
  const double half_len = s.half_len, pr = s.probe_radius;
  PayloadModel m;
  auto at = [&](double x, double y, double zz) {
    return Eigen::Vector3d(centre + x * xP + y * yP + zz * zP);
  };
  for (int end = 0; end < 2; ++end) {
    const double y = end ? half_len : -half_len;
    for (int k = 0; k < kBodySides; ++k)
      m.v[end * kBodySides + k] = at(s.ring_x[k], y, s.ring_z[k]);
  }
  // The strips, each from its eight vertices in the standard numbering
  // (generators' signs: u from a to d, v from b to e, w from c to f).
  static constexpr int kSigns[8][3] = {{-1, -1, -1}, {-1, -1, 1}, {1, -1, -1}, {-1, 1, 1},
                                       {-1, 1, -1},  {1, -1, 1},  {1, 1, 1},   {1, 1, -1}};
  m.has_body = with_body;
  for (int j = 0; j < kBodyStrips && with_body; ++j) {
    std::array<Eigen::Vector3d, 8> v;
    for (int i = 0; i < 8; ++i) {
      const int level = kSigns[i][2] < 0 ? j : j + 1;  // w = -z_P: the c side is the top
      v[i] = at(kSigns[i][1] * s.level_hx[level], kSigns[i][0] * half_len, s.level_z[level]);
    }
    m.body[j] = FromVertices(v);
  }
  const Eigen::Vector3d root = centre + half_len * yP;
  const Eigen::Vector3d tip = root + s.probe_length * yP;
  int k = kProbeFirst;
  for (double sx : {-1.0, 1.0})
    for (double sz : {-1.0, 1.0}) m.v[k++] = root + pr * (sx * xP + sz * zP);
  for (int j = 0; j < 6; ++j) m.v[k++] = tip + pr * (s.tip_cos[j] * xP + s.tip_sin[j] * zP);
  m.probe_tip_centre = tip;
  m.probe_axis = yP;
  return m;
}

PayloadModel MakePayload(const PayloadConfig& p, const Eigen::Isometry3d& X_RP) {
  return MakePayload(MakePayloadShape(p), X_RP);
}

std::string PayloadVertexName(int i) {
  char name[8] = "?";
  if (i >= 0 && i < kBodyVertices)
    std::snprintf(name, sizeof name, "B%d", i + 1);
  else if (i >= kProbeFirst && i < kProbeTipFirst)
    std::snprintf(name, sizeof name, "V2%d", i - kProbeFirst + 1);
  else if (i >= kProbeTipFirst && i < kPayloadVertices)
    std::snprintf(name, sizeof name, "V3%d", i - kProbeTipFirst + 1);
  return name;
}

Hexahedron MakeCargoBay(const ShuttleConfig& s) {
  const Eigen::Vector3d A(0.0, 0.0,
                          -0.5 * s.bay_depth_ft);  // centre of face a, the forward bulkhead
  return MakeBox(A, Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitY(), -Eigen::Vector3d::UnitZ(),
                 s.bay_length_ft, 0.5 * s.bay_width_ft, 0.5 * s.bay_depth_ft);
}

Hexahedron MakeCaeFrontHalf(const CaeConfig& c) {
  const double F = c.across_flats_ft, s = F / std::sqrt(3.0), hl = 0.5 * c.length_ft;
  // In the CAE frame (x_C, y_C, z_C); the port's face c is y_C = 0.
  const std::array<Eigen::Vector3d, 8> v_C = {{
      {-0.5 * s, 0, -hl},
      {-s, 0.5 * F, -hl},
      {-0.5 * s, 0, hl},
      {s, 0.5 * F, -hl},
      {0.5 * s, 0, -hl},
      {-s, 0.5 * F, hl},
      {s, 0.5 * F, hl},
      {0.5 * s, 0, hl},
  }};
  std::array<Eigen::Vector3d, 8> v;
  for (int i = 0; i < 8; ++i) v[i] = c.p_RoCo_R_ft + c.R_RC * v_C[i];
  return FromVertices(v);
}

}  // namespace rms::dcp_model
