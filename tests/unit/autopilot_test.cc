// The autopilot in the loop with the real DCP (in process, the inputs through
// the input block's words, the telemetry one frame late as over LCM): it
// docks from the default state and from perturbed initial states, and
// relieves the collisions it runs into.
#include <cstdio>
#include <gtest/gtest.h>
#include <random>

#include "rms/arm/kinematics.h"
#include "rms/base/config.h"
#include "rms/mission/mission_geometry.h"
#include "rms/sim/closed_loop.h"

namespace rms {
namespace {

constexpr int kMaxFrames = 30 * 400;  // 400 s of session time

void ExpectDocked(const sim::ClosedLoopResult& r, const LabConfig& c) {
  EXPECT_TRUE(r.docked) << r.failure << " (mode " << int(r.last.mode) << ")";
  EXPECT_LE(r.dock_distance_ft, c.dcp.dock_distance_ft);
  EXPECT_LE(r.dock_angle_deg, c.dcp.dock_angle_deg);
  EXPECT_GT(r.modes_entered[2], 0);
  EXPECT_GT(r.modes_entered[3], r.modes_entered[2]);
}

TEST(Autopilot, DocksFromTheDefaultState) {
  const LabConfig c = LoadConfig(DefaultConfigPath());
  const auto r = sim::FlyAutopilot(c, {}, kMaxFrames);
  ExpectDocked(r, c);
  std::printf(
      "docked after %.1f s: distance %.4f ft, angle %.4f deg; modes 2 at %.1f s, 3 at %.1f s\n",
      r.time_s, r.dock_distance_ft, r.dock_angle_deg, r.modes_entered[2] / 30.0,
      r.modes_entered[3] / 30.0);
  EXPECT_EQ(r.autopilot.Get(Counter::kAutopilotCollisionsRelieved), 0);
}

// Moves the payload's position in the bay (and so where the DCP has it).
void OffsetPayload(LabConfig* c, const Eigen::Vector3d& d_ft, double yaw_deg) {
  c->payload.p_RoPo_R_ft += d_ft;
  const double a = yaw_deg * M_PI / 180.0;
  c->payload.R_RP = arm::RotZ({std::sin(a), std::cos(a)}) * c->payload.R_RP;
}

// Does the payload (body and probe) lie inside the cargo bay's walls?
bool PayloadFitsTheBay(const LabConfig& c) {
  const auto& p = c.payload;
  const double r = p.diameter_ft / 2, hl = p.length_ft / 2, pr = p.probe_diameter_ft / 2;
  for (int k = 0; k < 32; ++k) {
    const double a = 2 * M_PI * k / 32;
    for (const Eigen::Vector3d& q :
         {Eigen::Vector3d(r * std::cos(a), -hl, r * std::sin(a)),
          Eigen::Vector3d(r * std::cos(a), hl, r * std::sin(a)),
          Eigen::Vector3d(pr * std::cos(a), hl + p.probe_length_ft, pr * std::sin(a))}) {
      const Eigen::Vector3d v = p.R_RP * q + p.p_RoPo_R_ft;
      if (v.x() < 0.05 || v.x() > c.shuttle.bay_length_ft - 0.05 ||
          std::abs(v.y()) > c.shuttle.bay_width_ft / 2 - 0.05 ||
          v.z() < -c.shuttle.bay_depth_ft + 0.05) {
        return false;
      }
    }
  }
  return true;
}

TEST(Autopilot, DocksWithThePayloadElsewhereInTheBay) {
  LabConfig c = LoadConfig(DefaultConfigPath());
  OffsetPayload(&c, {6.0, -0.8, 0.0}, 4.0);
  ASSERT_TRUE(PayloadFitsTheBay(c));
  ExpectDocked(sim::FlyAutopilot(c, {}, kMaxFrames), c);
}

TEST(Autopilot, DocksFromOtherShoulderHeights) {
  for (double h : {1.5, 6.0}) {
    LabConfig c = LoadConfig(DefaultConfigPath());
    c.inputs[kShoulderHeight].initial = h;
    SCOPED_TRACE("shoulder height " + std::to_string(h));
    ExpectDocked(sim::FlyAutopilot(c, {}, kMaxFrames), c);
  }
}

TEST(Autopilot, OpensAClosedFingerFirst) {
  LabConfig c = LoadConfig(DefaultConfigPath());
  c.inputs[kFinger].initial = 1.0;
  ExpectDocked(sim::FlyAutopilot(c, {}, kMaxFrames), c);
}

TEST(Autopilot, DocksFromAnArmThatIsNotStowed) {
  LabConfig c = LoadConfig(DefaultConfigPath());
  const double q[6] = {40.0, 35.0, -50.0, -20.0, 10.0, 30.0};
  for (int i = 0; i < 6; ++i) c.inputs[i].initial = q[i];
  ExpectDocked(sim::FlyAutopilot(c, {}, kMaxFrames), c);
}

TEST(Autopilot, DocksFromRandomPerturbations) {
  constexpr unsigned kSeed = 19721122;
  std::printf("seed %u\n", kSeed);
  std::mt19937 rng(kSeed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0, tried = 0; k < 12; ++tried) {
    ASSERT_LT(tried, 100);
    LabConfig c = LoadConfig(DefaultConfigPath());
    const Eigen::Vector3d d(6.0 * u(rng), 2.0 * u(rng), 0.0);
    const double yaw = 10.0 * u(rng), h = 3.5 + 2.5 * u(rng), finger = 0.5 + 0.5 * u(rng);
    OffsetPayload(&c, d, yaw);
    if (!PayloadFitsTheBay(c)) continue;  // a payload through the bay's wall is no starting state
    ++k;
    c.inputs[kShoulderHeight].initial = h;
    c.inputs[kFinger].initial = finger;
    char what[160];
    std::snprintf(
        what, sizeof what,
        "case %d: payload moved (%.2f, %.2f) ft, yaw %.1f deg; shoulder %.2f ft; finger %.2f", k,
        d.x(), d.y(), yaw, h, finger);
    SCOPED_TRACE(what);
    const auto r = sim::FlyAutopilot(c, {}, kMaxFrames);
    ExpectDocked(r, c);
    std::printf("%s: %s after %.1f s (%.3f ft, %.3f deg)\n", what,
                r.docked ? "docked" : r.failure.c_str(), r.time_s, r.dock_distance_ft,
                r.dock_angle_deg);
  }
}

// A start from which the straight joint move to the approach pose brings
// the end effector into the payload (found by search over random starts).
constexpr double kNearPayload[6] = {5.5, 21.2, -37.6, -38.9, -14.8, -39.6};

// A start whose straight approach strikes the payload's body (16-sided, as
// drawn: docs/collision.md "The payload").
constexpr double kStraightIntoPayload[6] = {4.2, 17.9, -37.2, -39.9, -7.4, -44.0};

TEST(Autopilot, RelievesTheCollisionsItRunsIntoAndStillDocks) {
  LabConfig c = LoadConfig(DefaultConfigPath());
  for (int i = 0; i < 6; ++i) c.inputs[i].initial = kStraightIntoPayload[i];
  operator_station::AutopilotOptions o;
  o.plan_clear_paths = false;  // fly straight, like a novice: the DCP stops the arm
  const auto r = sim::FlyAutopilot(c, o, kMaxFrames);
  EXPECT_GT(r.held_frames, 0) << "the DCP never held the arm: no collision to relieve";
  EXPECT_GE(r.autopilot.Get(Counter::kAutopilotCollisionsRelieved), 1);
  ExpectDocked(r, c);
}

TEST(Autopilot, PlansAroundWhatItWouldHit) {
  LabConfig c = LoadConfig(DefaultConfigPath());
  for (int i = 0; i < 6; ++i) c.inputs[i].initial = kNearPayload[i];
  const auto r = sim::FlyAutopilot(c, {}, kMaxFrames);
  EXPECT_EQ(r.held_frames, 0);
  EXPECT_EQ(r.autopilot.Get(Counter::kAutopilotCollisionsRelieved), 0);
  EXPECT_GE(r.autopilot.Get(Counter::kAutopilotViaPoints), 1);
  ExpectDocked(r, c);
}

TEST(Autopilot, DocksWithoutACollisionFromRandomArmStarts) {
  constexpr unsigned kSeed = 7;
  std::printf("seed %u\n", kSeed);
  std::mt19937 rng(kSeed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const LabConfig c0 = LoadConfig(DefaultConfigPath());
  const scene_model::SceneModel model = scene_model::BuildSceneModel(c0);
  int flown = 0;
  for (int k = 0; k < 200 && flown < 20; ++k) {
    LabConfig c = c0;
    const std::array<double, 6> q = {30 * u(rng),       20 + 25 * u(rng), -60 + 40 * u(rng),
                                     -60 + 40 * u(rng), 20 * u(rng),      90 * u(rng)};
    for (int i = 0; i < 6; ++i) c.inputs[i].initial = q[i];
    // Only starts that are physically possible: nothing of the arm in the payload or the orbiter.
    if (!mission::Interpenetration(c, model, q, c.inputs[kShoulderHeight].initial,
                                   c.end_effector.finger_gap_open_ft,
                                   arm::MakeIsometry(c.payload.R_RP, c.payload.p_RoPo_R_ft),
                                   mission::PayloadState::kInBay)
             .empty()) {
      continue;
    }
    ++flown;
    char what[128];
    std::snprintf(what, sizeof what, "start %.1f %.1f %.1f %.1f %.1f %.1f", q[0], q[1], q[2], q[3],
                  q[4], q[5]);
    SCOPED_TRACE(what);
    const auto r = sim::FlyAutopilot(c, {}, kMaxFrames);
    ExpectDocked(r, c);
    EXPECT_EQ(r.held_frames, 0);
  }
  EXPECT_EQ(flown, 20);
}

}  // namespace
}  // namespace rms
