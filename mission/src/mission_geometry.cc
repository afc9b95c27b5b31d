#include "rms/mission/mission_geometry.h"

#include <cstdio>
#include <optional>

#include "rms/arm/kinematics.h"
#include "rms/mission/arm_ik.h"
#include "rms/scene_model/separating_plane.h"

namespace rms::mission {

double GraspPalmAboveBarFt(const LabConfig& c) { return kGraspTpobShare * c.dcp.tpob_ft; }

MissionGeometry PlanGeometry(const LabConfig& c) {
  return PlanGeometry(c, c.inputs[kShoulderHeight].initial);
}

MissionGeometry PlanGeometry(const LabConfig& c, double shoulder_height_ft) {
  const auto& ee = c.end_effector;
  const auto& p = c.payload;
  MissionGeometry g;
  g.shoulder_height_ft = shoulder_height_ft;
  const Eigen::Isometry3d X_RP_bay = arm::MakeIsometry(p.R_RP, p.p_RoPo_R_ft);
  const Eigen::Vector3d yP = p.R_RP.col(1), zP = p.R_RP.col(2);
  const Eigen::Vector3d X2 = -zP, Y2 = -yP;
  const double bar_w = p.bar_size_P_ft.y(), bar_h = p.bar_size_P_ft.z();
  const double clearance = kGraspD3yMarginShare * (c.dcp.d3y_ft - bar_w);
  const double y_bar = ee.palm_half_width_ft - ee.finger_thickness_ft - clearance - 0.5 * bar_w;
  const Eigen::Vector3d bar = X_RP_bay * p.p_PoBar_P_ft;
  const Eigen::Vector3d A =
      bar - y_bar * Y2 - (ee.palm_length_ft + GraspPalmAboveBarFt(c) + 0.5 * bar_h) * X2;
  g.X_RS2_grasp = EndEffectorPose(A, X2, Y2);
  g.X_S2P = g.X_RS2_grasp.inverse() * X_RP_bay;
  const Eigen::Vector3d yC = c.cae.R_RC.col(1);
  const Eigen::Vector3d S = c.arm.p_RoB_R_ft + Eigen::Vector3d(0, 0, g.shoulder_height_ft);
  Eigen::Vector3d toward = S - c.cae.p_RoCo_R_ft;
  toward -= toward.dot(yC) * yC;
  const Eigen::Vector3d& yD = yC;  // D keeps the CAE's Y
  const Eigen::Vector3d zD = toward.normalized(), xD = yD.cross(zD);
  Eigen::Matrix3d RD;
  RD.col(0) = xD;
  RD.col(1) = yD;
  RD.col(2) = zD;
  const Eigen::Vector3d tip = c.cae.p_RoCo_R_ft - 0.05 * yC;
  g.X_RP_dock = arm::MakeIsometry(RD, tip - (0.5 * p.length_ft + p.probe_length_ft) * yD);
  return g;
}

std::string Interpenetration(const LabConfig& c, const scene_model::SceneModel& model,
                             const std::array<double, 6>& angles_deg, double shoulder_height_ft,
                             double finger_gap_ft, const Eigen::Isometry3d& X_RP,
                             PayloadState payload, double margin_ft) {
  const scene_model::ScenePose pose{arm::SinCosFromDegrees(angles_deg), shoulder_height_ft,
                                    finger_gap_ft, X_RP.translation(), X_RP.linear()};
  const scene_model::ClusterPoses poses = scene_model::ComputeClusterPoses(c, pose);
  std::array<std::optional<scene_model::PosedHull>, scene_model::kNumClusters> hulls;
  auto hull = [&](int k) -> const scene_model::PosedHull& {
    if (!hulls[k]) hulls[k] = scene_model::PoseHull(model[k], poses.X_RC[k]);
    return *hulls[k];
  };
  if (payload == PayloadState::kInBay) {
    // The DCP tests the end effector against the payload's body as the
    // square prism round the cylinder (docs/collision.md, V11-V18): plan
    // against that, not the rounder picture.
    const double r = c.payload.diameter_ft / 2, hl = c.payload.length_ft / 2;
    scene_model::Cluster box;
    box.mesh.AddBox(Eigen::Vector3f(-r, -hl, -r), Eigen::Vector3f(r, hl, r),
                    scene_model::Rgb{0, 0, 0});
    for (const scene_model::Triangle& t : box.mesh.triangles()) {
      for (const Eigen::Vector3f* v : {&t.a, &t.b, &t.c}) box.points.push_back(v->cast<double>());
    }
    box.normals = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()};
    box.edges = box.normals;
    hulls[scene_model::kPayloadBody] =
        scene_model::PoseHull(box, poses.X_RC[scene_model::kPayloadBody]);
  }
  // Obstacles: the orbiter and the CAE; the payload too while it sits in the
  // bay (then only the arm moves). Movers: the arm, and the payload it holds.
  auto obstacle = [&](int k) {
    return model[k].is_static() || (payload == PayloadState::kInBay &&
                                    model[k].group == scene_model::ClusterGroup::kPayload);
  };
  for (int a = 0; a < scene_model::kNumClusters; ++a) {
    if (obstacle(a) || !poses.present[a]) continue;
    for (int b = 0; b < scene_model::kNumClusters; ++b) {
      if (!obstacle(b) || !poses.present[b]) continue;
      // The vertical fixed arm and the shoulder sit on the longeron by
      // design: for them, only interpenetration counts.
      const double m = (a == scene_model::kPost || a == scene_model::kShoulder) ? 0.0 : margin_ft;
      const scene_model::PosedHull &ha = hull(a), &hb = hull(b);
      if ((ha.centroid_R - hb.centroid_R).norm() > ha.scale_ft + hb.scale_ft + m)
        continue;  // spheres apart
      if (!scene_model::FindSeparatingPlane(ha, hb, m > 0 ? -m : 5e-4, nullptr)) {
        char what[160];
        if (m > 0) {
          std::snprintf(what, sizeof what, "%s comes within %.2f ft of %s",
                        std::string(scene_model::ClusterName(a)).c_str(), m,
                        std::string(scene_model::ClusterName(b)).c_str());
        } else {
          std::snprintf(what, sizeof what, "%s runs into %s",
                        std::string(scene_model::ClusterName(a)).c_str(),
                        std::string(scene_model::ClusterName(b)).c_str());
        }
        return what;
      }
    }
  }
  return "";
}

}  // namespace rms::mission
