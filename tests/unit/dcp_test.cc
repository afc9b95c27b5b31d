// The Dynamic Collision Program's phases (report IV.A.3) and its collision
// response, frame by frame in process.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <random>
#include <sstream>
#include <tuple>

#include "rms/base/check.h"
#include "rms/base/config.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_model/dcp_models.h"
#include "rms/dcp_model/dynamic_collision_program.h"
#include "rms/dynamics_proc/dynamics_proc.h"
#include "rms/mission/arm_ik.h"
#include "rms/mission/mission_plan.h"
#include "rms/operator_station/timeline.h"
#include "rms/scene_model/scene_model.h"
#include "rms/sim/random_operator.h"
#include "rms/wire/checkpoint.h"
#include "rms/wire/dcp_mode.h"
#include "rms/wire/word_blocks.h"

#include "dcp_fixture.h"

namespace rms::dcp_model {
namespace {

using Eigen::Isometry3d;
using Eigen::Vector3d;

class Dcp : public testing::DcpFixture {
 protected:
  // The acquisition check for System Two at X_RS2 and a finger gap.
  AcquisitionCheck Check(const Isometry3d& X_RS2, double gap) const {
    return CheckAcquisition(config.dcp, MakeEndEffector(config.end_effector, X_RS2, gap),
                            MakeBar(config.payload, X_RP_bay()), gap);
  }
};

TEST_F(Dcp, AllSixAcquisitionConditionsHoldAtTheGraspAndEachFailsAlone) {
  const Isometry3d G = geo.X_RS2_grasp;
  const double gap = 0.55;  // the bar is 0.4 wide; D3Y is 0.6
  ASSERT_LT(gap, config.dcp.d3y_ft);
  const AcquisitionCheck ok = Check(G, gap);
  for (int i = 0; i < 6; ++i) EXPECT_TRUE(ok.holds[i]) << "condition " << i + 1;
  ASSERT_TRUE(ok.all());

  const Vector3d X2 = G.linear().col(0), Y2 = G.linear().col(1), Z2 = G.linear().col(2);
  struct Case {
    const char* what;
    Isometry3d X;
    double gap;
    int fails;
  };
  const std::vector<Case> cases = {
      {"palm down into the bar", Shifted(G, 0.3 * X2), gap, 0},
      {"bar into the fixed finger", Shifted(G, -0.15 * Y2), gap, 1},
      {"bar into the movable finger", Shifted(G, 0.22 * Y2), gap, 2},
      {"finger gap not below D3Y", G, config.dcp.d3y_ft + 0.02, 3},
      {"palm too far above the bar", Shifted(G, -0.3 * X2), gap, 4},
      {"end effector past the bar's end", Shifted(G, 0.5 * Z2), gap, 5},
  };
  for (const Case& c : cases) {
    const AcquisitionCheck r = Check(c.X, c.gap);
    for (int i = 0; i < 6; ++i) {
      EXPECT_EQ(r.holds[i], i != c.fails) << c.what << ": condition " << i + 1;
    }
    EXPECT_FALSE(r.all()) << c.what;
  }
}

TEST_F(Dcp, EachConditionsMarginAgreesWithItAndIsADistance) {
  // Random poses about the grasp (seeded): where a margin is clearly
  // positive its condition holds, where clearly negative it fails; and the
  // margin moves with the pose as the distance it names.
  constexpr unsigned kSeed = 1970;
  std::printf("seed %u\n", kSeed);
  std::mt19937 rng(kSeed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Isometry3d G = geo.X_RS2_grasp;
  int checked = 0;
  for (int k = 0; k < 2000; ++k) {
    Isometry3d X = Shifted(G, Vector3d(0.6 * u(rng), 0.4 * u(rng), 0.8 * u(rng)));
    X.linear() =
        X.linear() * Eigen::AngleAxisd(0.1 * u(rng), Vector3d(u(rng), u(rng), u(rng)).normalized())
                         .toRotationMatrix();
    const double gap = 0.45 + 0.3 * (u(rng) + 1) / 2;
    const AcquisitionCheck c = Check(X, gap);
    for (int i = 0; i < 6; ++i) {
      if (std::abs(c.margin_ft[i]) < 1e-9) continue;
      // Condition 3 allows the bar within the contact tolerance behind face e.
      const double threshold = i == 2 ? -kFingerContactToleranceFt : 0.0;
      EXPECT_EQ(c.holds[i], c.margin_ft[i] > threshold)
          << "pose " << k << " condition " << i + 1 << " margin " << c.margin_ft[i];
      ++checked;
    }
  }
  EXPECT_GT(checked, 11000);
  // Along the approach axis the palm's margin (condition 5) moves foot for foot.
  const Vector3d X2 = G.linear().col(0);
  const AcquisitionCheck a = Check(G, 0.55), b = Check(Shifted(G, -0.1 * X2), 0.55);
  EXPECT_NEAR(a.margin_ft[4] - b.margin_ft[4], 0.1, 1e-9);
  EXPECT_NEAR(b.margin_ft[0] - a.margin_ft[0], 0.1,
              1e-9);  // condition 1: the BAR further beyond face d
  // Condition 5 is a distance: the BAR far behind the palm is not within TPOB.
  const AcquisitionCheck far = Check(Shifted(G, 20.0 * X2), 0.55);
  EXPECT_LT(far.palm_to_bar_ft, -19.0);
  EXPECT_FALSE(far.holds[4]);
  EXPECT_LT(far.margin_ft[4], -19.0);
}

TEST_F(Dcp, DockingNeedsTheEnvelopeTheDistanceAndTheAngle) {
  const Hexahedron front = MakeCaeFrontHalf(config.cae);
  ASSERT_TRUE(front.valid);
  const Vector3d yC = config.cae.R_RC.col(1);
  auto check = [&](const Isometry3d& X_RP) {
    return CheckDocking(config.dcp, config.cae, front, MakePayload(config.payload, X_RP));
  };
  const DockingCheck good = check(geo.X_RP_dock);  // tip 0.05 ft short of the port
  EXPECT_TRUE(good.in_envelope);
  EXPECT_NEAR(good.distance_ft, 0.05, 1e-9);
  EXPECT_NEAR(good.angle_deg, 0.0, 1e-6);
  EXPECT_TRUE(good.docked);
  // 0.3 ft off to the side: in the envelope, too far.
  const Vector3d side = config.cae.R_RC.col(0);
  const DockingCheck off = check(Shifted(geo.X_RP_dock, 0.3 * side));
  EXPECT_TRUE(off.in_envelope);
  EXPECT_FALSE(off.docked);
  // Tilted 3 deg (> 2 deg 32 min) about the tip: aligned badly.
  Isometry3d tilted = geo.X_RP_dock;
  const Vector3d tip = config.cae.p_RoCo_R_ft - 0.05 * yC;
  tilted.linear() = Eigen::AngleAxisd(3.0 * M_PI / 180, side).toRotationMatrix() * tilted.linear();
  tilted.translation() = tip + Eigen::AngleAxisd(3.0 * M_PI / 180, side).toRotationMatrix() *
                                   (geo.X_RP_dock.translation() - tip);
  const DockingCheck tilt = check(tilted);
  EXPECT_NEAR(tilt.angle_deg, 3.0, 1e-6);
  EXPECT_LT(tilt.distance_ft, 0.25);
  EXPECT_FALSE(tilt.docked);
  // 2 deg passes.
  Isometry3d tilted2 = geo.X_RP_dock;
  tilted2.linear() =
      Eigen::AngleAxisd(2.0 * M_PI / 180, side).toRotationMatrix() * tilted2.linear();
  tilted2.translation() = tip + Eigen::AngleAxisd(2.0 * M_PI / 180, side).toRotationMatrix() *
                                    (geo.X_RP_dock.translation() - tip);
  EXPECT_TRUE(check(tilted2).docked);
  // Beyond face c (the probe's tip inside the CAE): out of the envelope.
  EXPECT_FALSE(check(Shifted(geo.X_RP_dock, 0.2 * yC)).in_envelope);
}

TEST_F(Dcp, TheShippedMissionTimelineIsThePlannersForTheDefaultConfig) {
  std::ifstream f(std::string(RMSLAB_SOURCE_DIR) + "/scripts/timelines/mission.tl");
  std::stringstream ss;
  ss << f.rdbuf();
  EXPECT_EQ(ss.str(),
            mission::FormatTimeline(mission::PlanMission(config), mission::kMissionHeader))
      << "regenerate: build/tools/rms_mission --out scripts/timelines/mission.tl";
}

TEST_F(Dcp, TheMissionTimelineAcquiresExtractsAndDocks) {
  const std::string text = mission::FormatTimeline(mission::PlanMission(config), "");
  const operator_station::Timeline tl =
      operator_station::Timeline::Parse(text, "mission", config.inputs);
  DynamicCollisionProgram dcp(config);
  std::vector<int> modes;
  int frames = 0;
  for (double t = 0; t <= tl.end_time(); t += 1.0 / 30.0, ++frames) {
    const wire::DcpFrameData out = dcp.Step(tl.Sample(t));
    if (modes.empty() || modes.back() != out.control.mode) modes.push_back(out.control.mode);
    EXPECT_EQ(dcp.status().slave_collisions, 0u)
        << "the slave never stands in collision, t = " << t;
    EXPECT_EQ(dcp.status().collisions, 0u) << "the planned mission never collides, t = " << t;
  }
  EXPECT_EQ(modes, (std::vector<int>{1, 2, 3}));
  EXPECT_TRUE(dcp.status().docked);
  EXPECT_LE(dcp.status().dock_distance_ft, config.dcp.dock_distance_ft);
  EXPECT_LE(dcp.status().dock_angle_deg, config.dcp.dock_angle_deg);
}

// The encoded DCP frame and telemetry of a frame: every word and field.
std::vector<std::uint8_t> FrameBytes(const DynamicCollisionProgram& dcp,
                                     const wire::DcpFrameData& out) {
  Counters counters;
  dcp_frame_t f{};
  wire::PackDcpFrame(out, &f, &counters);
  dcp_telemetry_t t = MakeTelemetry(dcp.status(), out);
  std::vector<std::uint8_t> bytes(
      static_cast<std::size_t>(f.getEncodedSize() + t.getEncodedSize()));
  f.encode(bytes.data(), 0, f.getEncodedSize());
  t.encode(bytes.data() + f.getEncodedSize(), 0, t.getEncodedSize());
  return bytes;
}

TEST_F(Dcp, AStillFrameKeptGivesTheWordsAndStateOfOneEvaluatedAgain) {
  // The mission and a random operator, each input held for 1 to 4 frames
  // (still frames), with resets: with still frames kept and without, with
  // and without frame coherence, every frame's words and telemetry and the
  // state every 25 frames are the same, bit for bit.
  constexpr unsigned kSeed = 20261202;
  std::printf("seed %u\n", kSeed);
  std::mt19937 rng(kSeed);
  std::vector<wire::OperatorInputs> inputs;
  const operator_station::Timeline tl = operator_station::Timeline::Parse(
      mission::FormatTimeline(mission::PlanMission(config), ""), "mission", config.inputs);
  for (double t = 0; t <= tl.end_time(); t += 1.0 / 30.0) {
    for (int k = std::uniform_int_distribution<int>(1, 4)(rng); k > 0; --k)
      inputs.push_back(tl.Sample(t));
  }
  sim::RandomOperator op(config.inputs, kSeed);
  for (int f = 0; f < 3000; ++f) {
    wire::OperatorInputs in = op.Next();
    in.reset = f % 700 == 350;
    for (int k = std::uniform_int_distribution<int>(1, 4)(rng); k > 0; --k) inputs.push_back(in);
  }
  for (const bool coherence : {false, true}) {
    DynamicCollisionProgram kept(config, {.frame_coherence = coherence, .reuse_still = true});
    DynamicCollisionProgram again(config, {.frame_coherence = coherence, .reuse_still = false});
    long still = 0;
    for (std::size_t i = 0; i < inputs.size(); ++i) {
      const ArmCommand before = kept.status().slave;
      const wire::DcpFrameData a = kept.Step(inputs[i]), b = again.Step(inputs[i]);
      still += before.angles_deg == kept.status().slave.angles_deg &&
               before.finger == kept.status().slave.finger && !kept.status().held;
      ASSERT_EQ(FrameBytes(kept, a), FrameBytes(again, b))
          << "frame " << i << ", frame coherence " << coherence;
      const DcpStatus &x = kept.status(), &y = again.status();
      ASSERT_EQ(std::tie(x.collisions, x.slave_collisions, x.held, x.finger_held, x.substeps,
                         x.motion_collision, x.too_fast, x.essential_contact),
                std::tie(y.collisions, y.slave_collisions, y.held, y.finger_held, y.substeps,
                         y.motion_collision, y.too_fast, y.essential_contact))
          << "frame " << i << ", frame coherence " << coherence;
      if (i % 25 == 0) {
        ASSERT_EQ(kept.SaveState().dump(), again.SaveState().dump())
            << "frame " << i << ", frame coherence " << coherence;
      }
    }
    EXPECT_GT(still, static_cast<long>(inputs.size() / 3)) << "too few still frames to test";
  }
}

TEST_F(Dcp, ACollisionHoldsTheSlaveAtContactAndReleasesIt) {
  DynamicCollisionProgram dcp(config);
  // Over the payload's body, well away from the bar, palm down.
  const Isometry3d above = Shifted(geo.X_RS2_grasp, Vector3d(-6.0, 0, 3.0));
  const PayloadModel payload = MakePayload(config.payload, X_RP_bay());
  int held = 0;
  double lowest = 1e9;
  // Down 5 ft over 3 s (through the body's top), then back up.
  for (int f = 0; f <= 180; ++f) {
    const double down = f <= 90 ? 5.0 * f / 90 : 5.0 * (180 - f) / 90;
    const wire::OperatorInputs in = Inputs(Shifted(above, Vector3d(0, 0, -down)), 0.0);
    const wire::DcpFrameData out = dcp.Step(in);
    const DcpStatus& st = dcp.status();
    if (st.held) {
      ++held;
      EXPECT_TRUE(st.collisions & wire::collision_bits::kEePayloadMask);
      EXPECT_TRUE(out.control.collision);
    }
    // The slave's end effector never penetrates the body.
    const EndEffectorModel ee = MakeEndEffector(config.end_effector, st.X_RS2, st.finger_gap_ft);
    for (const Hexahedron& h : ee.hex)
      for (const Hexahedron& strip : payload.body)
        ASSERT_NE(Collide(h, strip).verdict, Verdict::kCollide) << "frame " << f;
    lowest = std::min(lowest, st.X_RS2.translation().z());
  }
  EXPECT_GT(held, 30);
  // Contact: the fingers' tips stopped within one frame's travel of the body's top.
  const double finger_tip =
      lowest - config.end_effector.palm_length_ft - config.end_effector.finger_length_ft;
  const double body_top = config.payload.p_RoPo_R_ft.z() +
                          scene_model::PayloadTopFlat_P(config.payload);  // the 16-gon's top flat
  EXPECT_GT(finger_tip, body_top);
  EXPECT_LT(finger_tip, body_top + 5.0 / 90 + 1e-6);
  // Released: back above, the slave follows the master exactly.
  EXPECT_FALSE(dcp.status().held);
  for (int i = 0; i < 6; ++i)
    EXPECT_EQ(dcp.status().slave.angles_deg[i], dcp.status().master.angles_deg[i]);
}

TEST_F(Dcp, TheFingerStopsOnTheBarWhileTheArmFollows) {
  // With the bar in the middle of the jaw the movable finger meets it before
  // the gap is below D3Y: the finger holds on the bar (the receptacle bit),
  // no acquisition, and the arm still follows.
  DynamicCollisionProgram dcp(config);
  const Vector3d Y2 = geo.X_RS2_grasp.linear().col(1);
  const Isometry3d centred = Shifted(geo.X_RS2_grasp, 0.3 * Y2);
  bool finger_held = false;
  for (int f = 0; f <= 90; ++f) {
    dcp.Step(Inputs(centred, f / 90.0));
    if (dcp.status().finger_held) {
      finger_held = true;
      EXPECT_TRUE(dcp.status().collisions & wire::collision_bits::kRecptMask);
    }
  }
  EXPECT_TRUE(finger_held);
  EXPECT_EQ(dcp.mode(), wire::DcpMode::kAcquisition);
  EXPECT_GT(dcp.status().finger_gap_ft, config.dcp.d3y_ft);  // stopped on the bar, above D3Y
  // The arm moves up 0.5 ft with the finger still commanded closed: it follows.
  const double z0 = dcp.status().X_RS2.translation().z();
  dcp.Step(Inputs(Shifted(centred, Vector3d(0, 0, 0.5)), 1.0));
  EXPECT_NEAR(dcp.status().X_RS2.translation().z(), z0 + 0.5, 1e-3);
}

TEST_F(Dcp, InMode2APayloadVertexBeyondABayWallHoldsTheArm) {
  DynamicCollisionProgram dcp(config);
  for (int f = 0; f <= 30; ++f) dcp.Step(Inputs(geo.X_RS2_grasp, f / 30.0));
  ASSERT_EQ(dcp.mode(), wire::DcpMode::kExtraction);
  // Push sideways toward the starboard wall (+Y_R): the payload's side is 2.5 ft from it.
  int held = 0;
  for (int f = 1; f <= 60; ++f) {
    dcp.Step(Inputs(Shifted(geo.X_RS2_grasp, Vector3d(0, 4.0 * f / 60, 0.5)), 1.0));
    if (dcp.status().held) {
      ++held;
      // The starboard wall is bay face b (v = -Y_R): bit 6 + 1.
      EXPECT_TRUE(dcp.status().collisions & (wire::collision_bits::kBayFace << kFaceB));
    }
  }
  EXPECT_GT(held, 10);
  EXPECT_LT(dcp.status().X_RP.translation().y() +
                scene_model::PayloadTopFlat_P(config.payload),  // the 16-gon's side flat
            0.5 * config.shuttle.bay_width_ft + 1e-9);
  EXPECT_EQ(dcp.mode(), wire::DcpMode::kExtraction);
}

TEST_F(Dcp, ResetReturnsToMode1AndTheInitialState) {
  DynamicCollisionProgram dcp(config);
  for (int f = 0; f <= 30; ++f) dcp.Step(Inputs(geo.X_RS2_grasp, f / 30.0));
  ASSERT_EQ(dcp.mode(), wire::DcpMode::kExtraction);
  for (int f = 1; f <= 30; ++f)
    dcp.Step(Inputs(Shifted(geo.X_RS2_grasp, Vector3d(0, 0, 0.2 * f)), 1.0));
  ASSERT_GT(dcp.X_RP().translation().z(), config.payload.p_RoPo_R_ft.z() + 5.0);
  wire::OperatorInputs in = Inputs(Shifted(geo.X_RS2_grasp, Vector3d(0, 0, 6)), 0.0);
  in.reset = true;
  const wire::DcpFrameData out = dcp.Step(in);
  EXPECT_EQ(dcp.mode(), wire::DcpMode::kAcquisition);
  EXPECT_EQ(out.control.mode, wire::DcpMode::kAcquisition);
  EXPECT_TRUE(out.control.reset);
  EXPECT_FALSE(out.control.acquired);
  EXPECT_LT((dcp.X_RP().translation() - config.payload.p_RoPo_R_ft).norm(), 1e-12);
}

TEST_F(Dcp, ACheckpointRestoresTheStateExactly) {
  // At every phase of the mission: save, go on; restore into a fresh DCP and
  // go on with the same inputs: the same outputs, word for word.
  const std::string text = mission::FormatTimeline(mission::PlanMission(config), "");
  const operator_station::Timeline tl =
      operator_station::Timeline::Parse(text, "mission", config.inputs);
  std::vector<wire::OperatorInputs> inputs;
  for (double t = 0; t <= tl.end_time(); t += 1.0 / 30.0) inputs.push_back(tl.Sample(t));
  for (std::size_t at : {std::size_t{100}, std::size_t{500}, std::size_t{800}, std::size_t{1300}}) {
    DynamicCollisionProgram live(config);
    for (std::size_t k = 0; k < at; ++k) live.Step(inputs[k]);
    // Through the text of a file, as a checkpoint goes.
    const nlohmann::json saved = nlohmann::json::parse(live.SaveState().dump());
    // Into a DCP that had flown elsewhere (fingers closed in Mode 1, say):
    // nothing of that is reported after the restore.
    DynamicCollisionProgram restored(config);
    for (std::size_t k = 0; k < 30; ++k) restored.Step(inputs[k]);
    restored.RestoreState(saved);
    EXPECT_EQ(restored.mode(), live.mode()) << "at frame " << at;
    for (int i = 0; i < 6; ++i) {
      EXPECT_EQ(restored.status().acquisition[i], live.status().acquisition[i])
          << at << " condition " << i + 1;
      EXPECT_DOUBLE_EQ(restored.status().acquisition_margin_ft[i],
                       live.status().acquisition_margin_ft[i])
          << at;
    }
    EXPECT_DOUBLE_EQ(restored.status().dock_distance_ft, live.status().dock_distance_ft) << at;
    EXPECT_DOUBLE_EQ(restored.status().bay_clearance_ft, live.status().bay_clearance_ft) << at;
    if (live.mode() >= wire::DcpMode::kExtraction) {
      for (int i = 0; i < 6; ++i)
        EXPECT_FALSE(live.status().acquisition[i]) << "not evaluated after acquisition";
    }
    for (std::size_t k = at; k < inputs.size(); ++k) {
      const wire::DcpFrameData a = live.Step(inputs[k]), b = restored.Step(inputs[k]);
      dcp_frame_t wa, wb;
      wire::PackDcpFrame(a, &wa, nullptr);
      wire::PackDcpFrame(b, &wb, nullptr);
      ASSERT_EQ(std::memcmp(wa.arm_words, wb.arm_words, sizeof wa.arm_words), 0) << at << "+" << k;
      ASSERT_EQ(wa.control_word, wb.control_word) << at << "+" << k;
      ASSERT_EQ(std::memcmp(wa.state_words, wb.state_words, sizeof wa.state_words), 0)
          << at << "+" << k;
      ASSERT_EQ(std::memcmp(wa.plane_words, wb.plane_words, sizeof wa.plane_words), 0)
          << at << "+" << k;
    }
    EXPECT_TRUE(restored.status().docked);
  }
}

TEST_F(Dcp, ABadCheckpointIsRefusedNamingWhatIsWrong) {
  DynamicCollisionProgram dcp(config);
  nlohmann::json j = dcp.SaveState();
  j["format"] = "something else";
  EXPECT_THROW(dcp.RestoreState(j), InputError);
  j = dcp.SaveState();
  j["mode"] = 7;
  try {
    dcp.RestoreState(j);
    ADD_FAILURE() << "mode 7 accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("mode"), std::string::npos) << e.what();
  }
  j = dcp.SaveState();
  j.erase("X_S2P");
  EXPECT_THROW(dcp.RestoreState(j), InputError);
  EXPECT_EQ(dcp.mode(), wire::DcpMode::kAcquisition);
}

// wire::TextHoldsDcp (the re-simulation's check of a logged state): a
// checkpoint's text holds its own state and no other; a text ParseCheckpoint
// refuses is refused the same, even when its state is the one asked about.
TEST_F(Dcp, ACheckpointsTextHoldsItsStateAndIsReadAsParseCheckpointReadsIt) {
  DynamicCollisionProgram dcp(config);
  wire::Checkpoint c;
  c.config = "config.toml";
  c.dcp = dcp.SaveState();
  const std::string text = wire::CheckpointText(c);
  EXPECT_TRUE(wire::TextHoldsDcp(text, c.dcp, "it"));
  EXPECT_EQ(wire::ParseCheckpoint(text, "it").dcp, c.dcp);
  nlohmann::json other = c.dcp;
  other["mode"] = 2;
  EXPECT_FALSE(wire::TextHoldsDcp(text, other, "it"));
  // Damaged before the state: refused as ParseCheckpoint refuses it.
  for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{
           {"\"format\"", "GARBAGE \"format\""},
           {"rmslab-checkpoint-1", "rmslab-checkpoint-9"},
           {"\"saved_us\"", "\"saved\""},
           {"\"operator_inputs\": {", "\"operator_inputs\": [{"}}) {
    std::string bad = text;
    ASSERT_NE(bad.find(from), std::string::npos) << from;
    bad.replace(bad.find(from), from.size(), to);
    EXPECT_THROW(wire::ParseCheckpoint(bad, "it"), InputError) << to;
    EXPECT_THROW(wire::TextHoldsDcp(bad, c.dcp, "it"), InputError) << to;
  }
}

}  // namespace
}  // namespace rms::dcp_model

namespace rms {
namespace {

// docs/security.md "The control channel": a checkpoint is a name, written
// new only and never through a link, read only from a regular file of at
// most 1 MiB, and the folder itself is never reached through a link.
TEST(CheckpointFolderTest, NamesOnlyNewFilesNoLinksAndASizeCap) {
  namespace fs = std::filesystem;
  const fs::path root = fs::temp_directory_path() / ("rmslab_cpfolder_" + std::to_string(getpid()));
  fs::remove_all(root);
  fs::create_directories(root / "checkpoints");
  fs::create_directories(root / "elsewhere");
  const wire::CheckpointFolder folder((root / "checkpoints").string());
  wire::Checkpoint c;
  c.dcp = dcp_model::DynamicCollisionProgram(
              LoadConfig(std::string(RMSLAB_SOURCE_DIR) + "/config/rmslab.toml"))
              .SaveState();
  folder.Write("good.json", c);
  EXPECT_EQ(folder.Read("good.json").dcp, c.dcp);
  for (const char* bad :
       {"../x.json", "/tmp/x.json", "a/b.json", ".hidden.json", "x.txt", "x\n.json", ""}) {
    EXPECT_THROW(folder.Write(bad, c), InputError) << bad;
    EXPECT_THROW(folder.Read(bad), InputError) << bad;
  }
  EXPECT_THROW(folder.Write("good.json", c), InputError) << "over an existing checkpoint";
  fs::create_symlink(root / "elsewhere" / "t.json", root / "checkpoints" / "link.json");
  EXPECT_THROW(folder.Write("link.json", c), InputError);
  EXPECT_FALSE(fs::exists(root / "elsewhere" / "t.json"));
  std::ofstream(root / "checkpoints" / "big.json")
      << std::string(wire::kMaxCheckpointBytes + 1, ' ');
  EXPECT_THROW(folder.Read("big.json"), InputError);
  // The folder swapped for a link to elsewhere: refused, nothing written there.
  fs::rename(root / "checkpoints", root / "moved");
  fs::create_directory_symlink(root / "elsewhere", root / "checkpoints");
  EXPECT_THROW(folder.Write("other.json", c), InputError);
  EXPECT_FALSE(fs::exists(root / "elsewhere" / "other.json"));
  fs::remove_all(root);
}

}  // namespace
}  // namespace rms
