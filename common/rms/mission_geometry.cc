#include "rms/mission_geometry.h"

#include <cstdio>
#include <optional>

#include "rms/arm_ik.h"
#include "rms/arm_kinematics.h"
#include "rms/priority.h"

namespace rms::mission {

MissionGeometry PlanGeometry(const LabConfig& c) { return PlanGeometry(c, c.inputs[kShoulderHeight].initial); }

MissionGeometry PlanGeometry(const LabConfig& c, double shoulder_height_ft) {
  const auto& ee = c.end_effector;
  const auto& p = c.payload;
  MissionGeometry g;
  g.shoulder_height_ft = shoulder_height_ft;
  const Eigen::Isometry3d X_RP_bay = MakeIsometry(p.R_RP, p.p_RoPo_R_ft);
  const Eigen::Vector3d yP = p.R_RP.col(1), zP = p.R_RP.col(2);
  const Eigen::Vector3d X2 = -zP, Y2 = -yP;
  const double bar_w = p.bar_size_P_ft.y(), bar_h = p.bar_size_P_ft.z();
  const double clearance = 0.4 * (c.dcp.d3y_ft - bar_w);
  const double y_bar = ee.palm_half_width_ft - ee.finger_thickness_ft - clearance - 0.5 * bar_w;
  const Eigen::Vector3d bar = X_RP_bay * p.p_PoBar_P_ft;
  const Eigen::Vector3d A = bar - y_bar * Y2 - (ee.palm_length_ft + 0.5 * c.dcp.tpob_ft + 0.5 * bar_h) * X2;
  g.X_RS2_grasp = EndEffectorPose(A, X2, Y2);
  g.X_S2P = g.X_RS2_grasp.inverse() * X_RP_bay;
  const Eigen::Vector3d yC = c.cae.R_RC.col(1);
  const Eigen::Vector3d S = c.arm.p_RoB_R_ft + Eigen::Vector3d(0, 0, g.shoulder_height_ft);
  Eigen::Vector3d toward = S - c.cae.p_RoCo_R_ft;
  toward -= toward.dot(yC) * yC;
  const Eigen::Vector3d zD = toward.normalized(), yD = yC, xD = yD.cross(zD);
  Eigen::Matrix3d RD;
  RD.col(0) = xD;
  RD.col(1) = yD;
  RD.col(2) = zD;
  const Eigen::Vector3d tip = c.cae.p_RoCo_R_ft - 0.05 * yC;
  g.X_RP_dock = MakeIsometry(RD, tip - (0.5 * p.length_ft + p.probe_length_ft) * yD);
  return g;
}

std::string Interpenetration(const LabConfig& c, const SceneModel& model, const std::array<double, 6>& angles_deg,
                             double shoulder_height_ft, double finger_gap_ft, const Eigen::Isometry3d& X_RP,
                             PayloadState payload, double margin_ft) {
  EsgFrameData f;
  f.arm = SinCosFromDegrees(angles_deg);
  f.shoulder_height_ft = shoulder_height_ft;
  f.finger_gap_ft = finger_gap_ft;
  f.p_RoPo_R_ft = X_RP.translation();
  f.R_RP = X_RP.linear();
  const ClusterPoses poses = ComputeClusterPoses(c, f);
  std::array<std::optional<PosedHull>, kNumClusters> hulls;
  auto hull = [&](int k) -> const PosedHull& {
    if (!hulls[k]) hulls[k] = PoseHull(model[k], poses.X_RC[k]);
    return *hulls[k];
  };
  if (payload == PayloadState::kInBay) {
    // The DCP tests the end effector against the payload's body as the
    // square prism round the cylinder (docs/collision.md, V11-V18): plan
    // against that, not the rounder picture.
    const double r = c.payload.diameter_ft / 2, hl = c.payload.length_ft / 2;
    Cluster box;
    box.mesh.AddBox(Eigen::Vector3f(-r, -hl, -r), Eigen::Vector3f(r, hl, r), Rgb{0, 0, 0});
    for (const Triangle& t : box.mesh.triangles()) {
      for (const Eigen::Vector3f* v : {&t.a, &t.b, &t.c}) box.points.push_back(v->cast<double>());
    }
    box.normals = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()};
    box.edges = box.normals;
    hulls[kPayloadBody] = PoseHull(box, poses.X_RC[kPayloadBody]);
  }
  // Obstacles: the orbiter and the CAE; the payload too while it sits in the
  // bay (then only the arm moves). Movers: the arm, and the payload it holds.
  auto obstacle = [&](int k) {
    return model[k].is_static() || (payload == PayloadState::kInBay && model[k].group == ClusterGroup::kPayload);
  };
  for (int a = 0; a < kNumClusters; ++a) {
    if (obstacle(a) || !poses.present[a]) continue;
    for (int b = 0; b < kNumClusters; ++b) {
      if (!obstacle(b) || !poses.present[b]) continue;
      // The vertical fixed arm and the shoulder sit on the longeron by
      // design: for them, only interpenetration counts.
      const double m = (a == kPost || a == kShoulder) ? 0.0 : margin_ft;
      const PosedHull &ha = hull(a), &hb = hull(b);
      if ((ha.centroid - hb.centroid).norm() > ha.scale + hb.scale + m) continue;  // spheres apart
      if (!FindSeparatingPlane(ha, hb, m > 0 ? -m : 5e-4, nullptr)) {
        char what[160];
        if (m > 0) {
          std::snprintf(what, sizeof what, "%s comes within %.2f ft of %s", std::string(ClusterName(a)).c_str(), m,
                        std::string(ClusterName(b)).c_str());
        } else {
          std::snprintf(what, sizeof what, "%s runs into %s", std::string(ClusterName(a)).c_str(),
                        std::string(ClusterName(b)).c_str());
        }
        return what;
      }
    }
  }
  return "";
}

}  // namespace rms::mission
