#pragma once
// The scene's static model data (docs/scene.md): 34 convex clusters, each a
// flat-shaded mesh in its own frame, posed every frame from the ESG frame's
// words. The Visual Scene Program (scene_proc) uses the clusters' geometry
// to place the separating planes of visual priority; the Electronic Scene
// Generator (esg_renderer) draws them. Convex clusters draw correctly alone
// with back faces culled; decals (windows, the port, engine bells) lie just
// off a face and are drawn after the faces they mark.
#include <Eigen/Geometry>
#include <array>
#include <string_view>
#include <vector>

#include "rms/arm/kinematics.h"
#include "rms/base/config.h"
#include "rms/scene_model/mesh.h"

namespace rms::scene_model {

enum ClusterId : int {
  // The orbiter (fixed in R): the cargo bay's faces, the longerons' tops, the
  // fuselage sides, the cabin with its nose, the aft fuselage, tail, wings, doors.
  kFloor = 0,
  kWallPort,
  kWallStbd,
  kBulkheadFwd,
  kBulkheadAft,
  kSillPort,
  kSillStbd,
  kSidePort,
  kSideStbd,
  kCabin,
  kAftFuselage,
  kTail,
  kWingPort,
  kWingStbd,
  kDoorPort,
  kDoorStbd,
  // The CAE (fixed in C): the module with its docking port, the solar array,
  // the docking target's standoff plate beside the port.
  kCaeModule,
  kCaeArray,
  kDockTarget,
  // The arm.
  kPost,
  kShoulder,
  kUpperBoom,
  kElbow,
  kLowerBoom,
  kWrist,
  kEffHex1,
  kEffHex2,
  kEffHex3,
  // The payload (frame P), with the grapple target's standoff plate beside the bar.
  kPayloadBody,
  kBar,
  kBarPostA,
  kBarPostB,
  kProbe,
  kGrappleTarget,
  kNumClusters
};

std::string_view ClusterName(int id);

// The frame each cluster's mesh is given in.
enum class ClusterFrame {
  kReference,  // R
  kCae,        // C
  kPost,       // the foot B of the vertical fixed arm, scaled along Z to its length
  kF1,         // after shoulder yaw, at S
  kF2,         // the upper boom's frame
  kF3,         // the lower boom's frame, at E
  kF6,         // after wrist roll, at W
  kSystemTwo,  // System Two, at A
  kFinger3,    // System Two shifted along Y2 to the movable finger
  kPayload,    // P
};

enum class ClusterGroup { kShuttle, kCae, kArm, kPayload };

struct Cluster {
  ClusterId id;
  ClusterFrame frame;
  ClusterGroup group;
  Mesh mesh;
  // For separating planes, in the cluster's frame: the vertices, the unit
  // face normals and edge directions (each once), and for a flat cluster its
  // edges' in-plane normals.
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> normals;
  std::vector<Eigen::Vector3d> edges;
  bool flat = false;
  bool is_static() const {
    return frame == ClusterFrame::kReference || frame == ClusterFrame::kCae;
  }
};

struct SceneModel {
  std::array<Cluster, kNumClusters> clusters;
  const Cluster& operator[](int id) const { return clusters[id]; }
};

SceneModel BuildSceneModel(const LabConfig& config);

// Each cluster's pose in R for a frame (affine: the vertical fixed arm is
// scaled to its length), and whether it exists this frame (the vertical
// fixed arm vanishes below 0.8 ft, where the shoulder sits on the deck).
struct ClusterPoses {
  std::array<Eigen::Affine3d, kNumClusters> X_RC;
  std::array<bool, kNumClusters> present;
};
// What poses the moving clusters: the arm's joints (as the sines and cosines
// the frames carry), the vertical fixed arm's length, the finger gap and the
// payload. The ESG frame carries exactly these (EsgFrameData::scene_pose);
// a planner poses its candidates the same way.
struct ScenePose {
  arm::ArmSinCos arm{};
  double shoulder_height_ft = 0.0;
  double finger_gap_ft = 0.0;
  Eigen::Vector3d p_RoPo_R_ft = Eigen::Vector3d::Zero();  // the payload body's centre
  Eigen::Matrix3d R_RP = Eigen::Matrix3d::Identity();
};
ClusterPoses ComputeClusterPoses(const LabConfig& config, const ScenePose& pose);

// Where EFF HEX 3 (built centred on Y2 = 0) sits along Y2 for a finger gap.
double MovingFingerCentreY2(const EndEffectorConfig& ee, double finger_gap_ft);

// The joint housings' radii (docs/scene.md): the booms end where the
// housings begin, so no link can cut into another at any joint angle.
inline constexpr double kShoulderRadiusFt = 0.8;
inline constexpr double kElbowRadiusFt = 1.0;  // the booms clear each other down to a 56 deg elbow
inline constexpr double kWristRadiusFt = 0.5;
inline constexpr double kWristClearanceFt = 0.75;  // lower boom's end to W
// The grapple target (docs/scene.md "Targets"): its standoff plate's top
// face, centred here in the payload frame P, beyond the bar's end on the
// side the wrist camera looks from at the grasp.
Eigen::Vector3d GrappleTargetCentre_P(const PayloadConfig& p);
// The bar's two posts (docs/scene.md, docs/collision.md "The models"): boxes
// in the payload frame P under the bar's ends, from the body's top flat up
// to the bar's bottom face. Drawn by the scene (kBarPostA, kBarPostB) and
// tested by the DCP in Mode 1 (collision bit eff_hex-bar_post). `count` is 0
// when the bar sits on the body (no room for posts).
struct BarPostBoxes {
  int count = 0;
  std::array<Eigen::Vector3d, 2> centre_P{};
  Eigen::Vector3d half_P = Eigen::Vector3d::Zero();
};
BarPostBoxes BarPosts_P(const PayloadConfig& p);
// The payload body's top flat (the drawn 16-sided body has a flat on top at
// this height above its axis, r cos(pi/16)), payload frame z_P, ft.
double PayloadTopFlat_P(const PayloadConfig& p);
// The docking target beside the CAE's port (docs/scene.md "Targets"): this
// far from the port's centre along z_C, its cross this far out from face c.
inline constexpr double kDockTargetAlongFt = 3.5;
inline constexpr double kDockTargetStandoffFt = 1.0;
// Clusters that would touch are built this far apart (a well-formed scene
// for visual priority: no two clusters share a surface; docs/scene.md).
inline constexpr double kClusterClearanceFt = 0.01;

}  // namespace rms::scene_model
