// The DCP right at the edges (docs/collision.md "Collision response",
// "Nothing passes through", "The essential contact"): motion between
// frames, resets, the finger against the bar, Mode 3 over the bay, refused
// inputs and checkpoints. Each of these failed before the motion test, the
// edge-triggered reset and the essential contact were built.
#include <cmath>
#include <fstream>
#include <gtest/gtest.h>
#include <sstream>

#include "rms/base/check.h"
#include "rms/base/config.h"
#include "rms/dcp_model/dcp_models.h"
#include "rms/dcp_model/dynamic_collision_program.h"
#include "rms/mission/arm_ik.h"
#include "rms/mission/mission_plan.h"
#include "rms/scene_model/scene_model.h"
#include "rms/wire/dcp_mode.h"

#include "dcp_fixture.h"

namespace rms::dcp_model {
namespace {

using Eigen::Isometry3d;
using Eigen::Vector3d;

class DcpEdges : public testing::DcpFixture {
 protected:
  double Lever(double gap_ft) const {
    const auto& e = config.end_effector;
    return (e.finger_gap_open_ft - gap_ft) / (e.finger_gap_open_ft - e.finger_gap_closed_ft);
  }
  // Acquire at the grasp (closing over 1 s), then move the held payload by
  // `d` in steps of at most 0.1 ft.
  void AcquireAndMove(DynamicCollisionProgram* dcp, const Vector3d& d) const {
    for (int f = 0; f <= 30; ++f) dcp->Step(Inputs(geo.X_RS2_grasp, f / 30.0));
    ASSERT_EQ(dcp->mode(), wire::DcpMode::kExtraction);
    const int n = static_cast<int>(std::ceil(d.norm() / 0.1));
    for (int f = 1; f <= n; ++f) dcp->Step(Inputs(Shifted(geo.X_RS2_grasp, d * f / n), 1.0));
    ASSERT_FALSE(dcp->status().held);
  }
  std::uint32_t CollisionsAt(const wire::OperatorInputs& in) const {
    // A fresh DCP's first command is tested where it is: its collisions.
    DynamicCollisionProgram fresh(config);
    fresh.Step(in);
    return fresh.status().collisions;
  }
};

TEST_F(DcpEdges, AFastCommandThroughTheBarBetweenTwoFramesIsHeld) {
  // The jaw beside the bar, then in one frame to the other side: both poses
  // are free, the motion between them passes the fingers through the bar.
  const Vector3d Y2 = geo.X_RS2_grasp.linear().col(1);
  const wire::OperatorInputs left = Inputs(Shifted(geo.X_RS2_grasp, -2.0 * Y2), 0.0);
  const wire::OperatorInputs right = Inputs(Shifted(geo.X_RS2_grasp, 2.0 * Y2), 0.0);
  ASSERT_EQ(CollisionsAt(left), 0u);
  ASSERT_EQ(CollisionsAt(right), 0u);
  DynamicCollisionProgram dcp(config);
  dcp.Step(left);
  ASSERT_FALSE(dcp.status().held);
  const wire::DcpFrameData out = dcp.Step(right);
  EXPECT_TRUE(dcp.status().held);
  EXPECT_TRUE(dcp.status().motion_collision);
  EXPECT_GT(dcp.status().substeps, 1);
  EXPECT_TRUE(dcp.status().collisions &
              (wire::collision_bits::kRecptMask | wire::collision_bits::kEffHexBarPost));
  EXPECT_TRUE(out.control.collision);  // a finger striking the bar is detrimental
  for (int i = 0; i < 6; ++i) EXPECT_EQ(dcp.status().slave.angles_deg[i], left.value[i]);
}

TEST_F(DcpEdges, TheBarsPostsAreCollisionModels) {
  // A bar on tall posts (its centre 8 ft above the payload's axis): the palm
  // below the bar, beside its end, slid along the bar's axis meets post b.
  std::ifstream f(DefaultConfigPath());
  std::stringstream text;
  text << f.rdbuf();
  std::string toml = text.str();
  const std::string from = "bar_center_ft = [0.0, 0.0, 5.8]";
  ASSERT_NE(toml.find(from), std::string::npos);
  toml.replace(toml.find(from), from.size(), "bar_center_ft = [0.0, 0.0, 8.0]");
  config = ParseConfig(toml, "tall-posts.toml");
  geo = mission::PlanGeometry(config);
  const scene_model::BarPostBoxes posts = scene_model::BarPosts_P(config.payload);
  ASSERT_EQ(posts.count, 2);
  const Vector3d X2 = geo.X_RS2_grasp.linear().col(0);
  const Vector3d along = X_RP_bay().linear().col(0);  // the bar's axis, x_P
  const Isometry3d beside = Shifted(geo.X_RS2_grasp, 1.7 * along + 2.1 * X2);
  DynamicCollisionProgram dcp(config);
  dcp.Step(Inputs(beside, 0.0));
  ASSERT_EQ(dcp.status().collisions, 0u);
  bool post_hit = false;
  for (int k = 1; k <= 60 && !post_hit; ++k) {
    dcp.Step(Inputs(Shifted(beside, -1.0 * along * k / 60), 0.0));
    post_hit = dcp.status().collisions & wire::collision_bits::kEffHexBarPost;
  }
  EXPECT_TRUE(post_hit);
  EXPECT_FALSE(dcp.status().collisions & wire::collision_bits::kRecptMask)
      << "the bar itself is not touched";
  EXPECT_TRUE(dcp.status().held);
}

TEST_F(DcpEdges, AFastCommandThroughABayWallBetweenTwoFramesIsHeld) {
  // The payload lifted until its outermost vertices (the 16-gon's side flat,
  // its lower corner at angle 9 pi/16 from z_P) are 0.5 ft below the sill and
  // 0.3 ft inside the starboard wall; then one frame 1 ft outboard and 1 ft
  // up: the end pose is free (those vertices above the sill, the rest inside
  // the walls), the motion crosses the wall below the sill.
  DynamicCollisionProgram dcp(config);
  const double rv = 0.5 * config.payload.diameter_ft;
  const double x_side = rv * std::sin(9 * M_PI / 16), z_side = rv * std::cos(9 * M_PI / 16);
  const double lift = -(config.payload.p_RoPo_R_ft.z() + z_side) - 0.5;
  const double out_y = 0.5 * config.shuttle.bay_width_ft - x_side - 0.3;
  AcquireAndMove(&dcp, Vector3d(0, out_y, lift));
  ASSERT_EQ(dcp.mode(), wire::DcpMode::kExtraction);
  dcp.Step(Inputs(Shifted(geo.X_RS2_grasp, Vector3d(0, out_y + 1.0, lift + 1.0)), 1.0));
  EXPECT_TRUE(dcp.status().held);
  EXPECT_TRUE(dcp.status().motion_collision);
  EXPECT_TRUE(dcp.status().collisions & (wire::collision_bits::kBayFace << kFaceB));
  EXPECT_EQ(dcp.mode(), wire::DcpMode::kExtraction);
}

TEST_F(DcpEdges, InMode3ThePayloadCannotBeLoweredBackThroughTheBayWalls) {
  // Lifted clear (Mode 3), moved 2 ft outboard of the starboard wall,
  // lowered 6 ft: the vertices over the wall stop at the sill.
  DynamicCollisionProgram dcp(config);
  const double r =
      scene_model::PayloadTopFlat_P(config.payload);  // the 16-gon's flats from its axis
  const double lift = -(config.payload.p_RoPo_R_ft.z() - r) + 0.5;
  AcquireAndMove(&dcp, Vector3d(0, 0, lift));
  ASSERT_EQ(dcp.mode(), wire::DcpMode::kManoeuvring);
  const Vector3d over_wall(0, 0.5 * config.shuttle.bay_width_ft - r + 2.0, lift);
  for (int f = 1; f <= 40; ++f)
    dcp.Step(Inputs(
        Shifted(geo.X_RS2_grasp, over_wall * f / 40 + Vector3d(0, 0, lift) * (1 - f / 40.0)), 1.0));
  ASSERT_FALSE(dcp.status().held);
  int held = 0;
  for (int f = 1; f <= 40; ++f) {
    dcp.Step(Inputs(Shifted(geo.X_RS2_grasp, over_wall - Vector3d(0, 0, 6.0 * f / 40)), 1.0));
    held += dcp.status().held;
  }
  EXPECT_GT(held, 15);
  EXPECT_TRUE(dcp.status().collisions & (wire::collision_bits::kBayFace << kFaceB));
  EXPECT_EQ(dcp.mode(), wire::DcpMode::kManoeuvring);
  // No payload vertex beyond the wall is below the sill.
  const PayloadModel p = MakePayload(config.payload, dcp.X_RP());
  for (const Vector3d& v : p.v) {
    if (v.y() > 0.5 * config.shuttle.bay_width_ft) {
      EXPECT_GT(v.z(), -1e-9) << v.transpose();
    }
  }
}

TEST_F(DcpEdges, AResetHeldDownDoesNotDisableTheCollisionResponse) {
  // The reset button held every frame acts once; pushing the palm down into
  // the payload's body is still held.
  DynamicCollisionProgram dcp(config);
  const Isometry3d above = Shifted(geo.X_RS2_grasp, Vector3d(-6.0, 0, 3.0));
  int held = 0;
  for (int f = 0; f <= 90; ++f) {
    wire::OperatorInputs in = Inputs(Shifted(above, Vector3d(0, 0, -5.0 * f / 90)), 0.0);
    in.reset = true;
    dcp.Step(in);
    held += dcp.status().held;
  }
  EXPECT_GT(held, 30);
  EXPECT_TRUE(dcp.status().collisions & wire::collision_bits::kEePayloadMask);
}

TEST_F(DcpEdges, AResetWhoseArmPoseWouldCollideIsRefused) {
  // Lowered 0.4 ft with the payload: put back in the bay, the payload would
  // rise into the palm. The reset is refused and nothing changes.
  DynamicCollisionProgram dcp(config);
  AcquireAndMove(&dcp, Vector3d(0, 0, -0.4));
  const std::string before = dcp.SaveState().dump();
  wire::OperatorInputs in = Inputs(Shifted(geo.X_RS2_grasp, Vector3d(0, 0, -0.4)), 1.0);
  in.reset = true;
  dcp.Step(in);
  EXPECT_TRUE(dcp.status().reset_refused);
  EXPECT_EQ(dcp.mode(), wire::DcpMode::kExtraction);
  EXPECT_TRUE(dcp.status().acquired);
  // Up 1 ft first: the reset is taken.
  for (int f = 1; f <= 14; ++f)
    dcp.Step(Inputs(Shifted(geo.X_RS2_grasp, Vector3d(0, 0, -0.4 + 0.1 * f)), 1.0));
  in = Inputs(Shifted(geo.X_RS2_grasp, Vector3d(0, 0, 1.0)), 1.0);
  in.reset = true;
  dcp.Step(in);
  EXPECT_FALSE(dcp.status().reset_refused);
  EXPECT_EQ(dcp.mode(), wire::DcpMode::kAcquisition);
  EXPECT_NE(dcp.SaveState().dump(), before);
}

TEST_F(DcpEdges, TheFingerStopsAtTheBarAndAcquisitionNeedsItThere) {
  // Below D3Y but 0.07 ft short of the bar: the six conditions hold, no contact, no acquisition.
  DynamicCollisionProgram dcp(config);
  dcp.Step(Inputs(geo.X_RS2_grasp, Lever(0.55)));
  EXPECT_EQ(dcp.mode(), wire::DcpMode::kAcquisition);
  EXPECT_FALSE(dcp.status().finger_contact);
  for (int i = 0; i < 6; ++i) EXPECT_TRUE(dcp.status().acquisition[i]) << i;
  // Closing on: acquisition when the finger reaches the bar, and the finger
  // never closes into it.
  for (int f = 1; f <= 30 && dcp.mode() == wire::DcpMode::kAcquisition; ++f)
    dcp.Step(Inputs(geo.X_RS2_grasp, Lever(0.55) + f * 0.01));
  ASSERT_EQ(dcp.mode(), wire::DcpMode::kExtraction);
  const Hexahedron bar = MakeBar(config.payload, X_RP_bay());
  const EndEffectorModel ee =
      MakeEndEffector(config.end_effector, dcp.status().X_RS2, dcp.status().finger_gap_ft);
  double least = 1e9;
  for (int i = 0; i < 8; ++i)
    least = std::min(least, ee.hex[2].Beyond(kFaceE, bar.x[i], bar.y[i], bar.z[i]));
  EXPECT_GE(least, -kFingerContactToleranceFt);
  EXPECT_LE(least, kFingerContactToleranceFt);
}

TEST_F(DcpEdges, TheFingerClosingOnTheBarIsEssentialAndThePalmStrikingItIsDetrimental) {
  // The bar in the middle of the jaw: the finger stops on it above D3Y (no
  // acquisition): RECPT, not COLLISION; within 1e-4 ft of the bar.
  DynamicCollisionProgram dcp(config);
  const Vector3d X2 = geo.X_RS2_grasp.linear().col(0), Y2 = geo.X_RS2_grasp.linear().col(1);
  const Isometry3d centred = Shifted(geo.X_RS2_grasp, 0.3 * Y2);
  bool essential = false;
  for (int f = 0; f <= 90; ++f) {
    const wire::DcpFrameData out = dcp.Step(Inputs(centred, f / 90.0));
    if (dcp.status().essential_contact) {
      essential = true;
      EXPECT_TRUE(out.control.receptacle_collision);
      EXPECT_FALSE(out.control.collision);
    }
  }
  ASSERT_TRUE(essential);
  EXPECT_EQ(dcp.mode(), wire::DcpMode::kAcquisition);
  EXPECT_NEAR(dcp.status().acquisition_margin_ft[2], 0.0, 1e-4);
  // The palm pushed down onto the bar: detrimental.
  DynamicCollisionProgram palm(config);
  bool struck = false;
  for (int f = 0; f <= 30 && !struck; ++f) {
    const wire::DcpFrameData out =
        palm.Step(Inputs(Shifted(geo.X_RS2_grasp, 0.3 * X2 * f / 30), 0.0));
    if (palm.status().collisions & wire::collision_bits::kEffHexRecpt) {
      struck = true;
      EXPECT_TRUE(out.control.collision);
      EXPECT_FALSE(out.control.receptacle_collision);
      EXPECT_TRUE(palm.status().held);
    }
  }
  EXPECT_TRUE(struck);
}

TEST_F(DcpEdges, OpeningTheFingerBeforeDockingLetsThePayloadGoWhereItIs) {
  DynamicCollisionProgram dcp(config);
  AcquireAndMove(&dcp, Vector3d(0, 0, 1.0));
  const Vector3d held_at = dcp.X_RP().translation();
  dcp.Step(Inputs(Shifted(geo.X_RS2_grasp, Vector3d(0, 0, 1.0)), 0.0));
  EXPECT_TRUE(dcp.status().let_go);
  EXPECT_EQ(dcp.mode(), wire::DcpMode::kAcquisition);
  EXPECT_FALSE(dcp.status().acquired);
  // The arm moves away; the payload stays.
  for (int f = 1; f <= 20; ++f)
    dcp.Step(Inputs(Shifted(geo.X_RS2_grasp, Vector3d(0, 0, 1.0 + 0.1 * f)), 0.0));
  EXPECT_LT((dcp.X_RP().translation() - held_at).norm(), 1e-9);
}

TEST_F(DcpEdges, NonFiniteInputsAndAFirstCommandThatCollidesAreNotTaken) {
  DynamicCollisionProgram dcp(config);
  // The palm inside the payload's body at the first frame: not taken.
  dcp.Step(Inputs(Shifted(geo.X_RS2_grasp, Vector3d(-6.0, 0, -2.0)), 0.0));
  EXPECT_TRUE(dcp.status().held);
  EXPECT_NE(dcp.status().collisions, 0u);
  EXPECT_EQ(dcp.status().slave_collisions, 0u);
  const wire::OperatorInputs initial = wire::InitialInputs(config.inputs);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(dcp.status().slave.angles_deg[i], initial.value[i]);
  // A NaN angle: the frame holds the last command.
  wire::OperatorInputs in = Inputs(geo.X_RS2_grasp, 0.0);
  in.value[2] = std::nan("");
  dcp.Step(in);
  EXPECT_TRUE(dcp.status().input_refused);
  EXPECT_EQ(dcp.status().slave_collisions, 0u);
  EXPECT_TRUE(std::isfinite(dcp.status().slave.angles_deg[2]));
}

TEST_F(DcpEdges, ACheckpointMissingItsLastKeyLeavesTheStateUnchanged) {
  DynamicCollisionProgram saved(config);
  AcquireAndMove(&saved, Vector3d(0, 0, 2.0));
  nlohmann::json cp = nlohmann::json::parse(saved.SaveState().dump());
  cp.erase("planes_ee_body");
  DynamicCollisionProgram other(config);
  for (int f = 0; f <= 10; ++f)
    other.Step(Inputs(Shifted(geo.X_RS2_grasp, Vector3d(-3, 0, 3)), 0.2));
  const std::string before = other.SaveState().dump();
  const wire::DcpMode mode = other.mode();
  EXPECT_THROW(other.RestoreState(cp), InputError);
  EXPECT_EQ(other.SaveState().dump(), before);
  EXPECT_EQ(other.mode(), mode);
  // A non-finite number in it: the same.
  cp = nlohmann::json::parse(saved.SaveState().dump());
  cp["contact_gap_ft"] = nullptr;
  EXPECT_THROW(other.RestoreState(cp), InputError);
  EXPECT_EQ(other.SaveState().dump(), before);
  // States the program could not reach: refused, nothing changed.
  const nlohmann::json good = nlohmann::json::parse(saved.SaveState().dump());
  std::vector<nlohmann::json> bad(6, good);
  bad[0]["acquired"] = false;      // Mode 2 without acquisition
  bad[1]["contact_gap_ft"] = 2.0;  // above the gap at acquisition
  bad[2]["X_S2P"][0] = 2.0;        // not a rigid pose
  bad[3]["slave"]["angles_deg"][1] =
      good["slave"]["angles_deg"][1].get<double>() - 30.0;  // the palm in the bay
  bad[4]["released"] = true;                                // released, not docked
  // The payload held 1e15 ft away: its strips are flat at such coordinates
  // (Modes 2 and 3 leave the strips out only near the origin).
  bad[5]["X_S2P"][3] = 1e15;
  for (std::size_t i = 0; i < bad.size(); ++i) {
    try {
      other.RestoreState(bad[i]);
      ADD_FAILURE() << "case " << i << " restored";
    } catch (const InputError& e) {
      std::printf("case %zu refused: %s\n", i, e.what());
      // Refused as not finite, as when the strips were always made.
      if (i == 5) {
        EXPECT_NE(std::string(e.what()).find("non-finite"), std::string::npos);
      }
    }
    EXPECT_EQ(other.SaveState().dump(), before) << "case " << i;
  }
  // The good one restores.
  other.RestoreState(good);
  EXPECT_EQ(other.mode(), wire::DcpMode::kExtraction);
}

}  // namespace
}  // namespace rms::dcp_model

namespace rms::dcp_model {
namespace {

// The distance of p from a convex hexahedron's surface, ft, signed (> 0
// outside): the farthest face plane outside, the nearest face inside.
double SurfaceDistance(const Hexahedron& h, const Eigen::Vector3d& p) {
  double worst = -1e30;
  for (int f = 0; f < kNumFaces; ++f) worst = std::max(worst, h.Beyond(f, p.x(), p.y(), p.z()));
  return worst;
}

TEST(DcpModels, WhatIsTestedIsWhatIsDrawn) {
  // Every point of the drawn payload body, bar and posts (payload frame: the
  // DCP's models built at the identity) lies on the tested models' surface,
  // within 0.05 ft (measured: the worst is printed).
  const LabConfig config = LoadConfig(DefaultConfigPath());
  const scene_model::SceneModel scene = scene_model::BuildSceneModel(config);
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  const PayloadModel payload = MakePayload(config.payload, I);
  const Hexahedron bar = MakeBar(config.payload, I);
  std::array<Hexahedron, 2> posts;
  ASSERT_EQ(MakeBarPosts(config.payload, I, &posts), 2);
  struct Part {
    int cluster;
    std::vector<const Hexahedron*> tested;
  };
  std::vector<Part> parts = {{scene_model::kPayloadBody, {}},
                             {scene_model::kBar, {&bar}},
                             {scene_model::kBarPostA, {&posts[0]}},
                             {scene_model::kBarPostB, {&posts[1]}}};
  for (const Hexahedron& s : payload.body) parts[0].tested.push_back(&s);
  for (const Part& part : parts) {
    double worst = 0;
    for (const scene_model::Triangle& t : scene[part.cluster].mesh.triangles()) {
      for (const Eigen::Vector3f* v : {&t.a, &t.b, &t.c}) {
        // The union's surface: outside all (distance to the nearest) or inside one.
        double d = 1e30;
        for (const Hexahedron* h : part.tested)
          d = std::min(d, SurfaceDistance(*h, v->cast<double>()));
        worst = std::max(worst, std::abs(d));
      }
    }
    std::printf("%s: drawn vs tested, worst %.2g ft\n",
                std::string(scene_model::ClusterName(part.cluster)).c_str(), worst);
    EXPECT_LE(worst, 0.05) << scene_model::ClusterName(part.cluster);
  }
}

}  // namespace
}  // namespace rms::dcp_model
