#include "rms/wire/word_blocks.h"

#include <gtest/gtest.h>
#include <random>

#include "rms/base/check.h"
#include "rms/dcp_frame_t.hpp"

namespace rms {
namespace {

Eigen::Matrix3d RandomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0, 1);
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
}

wire::EsgFrameData RandomEsg(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> pos(-500, 500), ang(-180, 180), u(0, 1);
  wire::EsgFrameData e;
  e.frame_count = static_cast<std::uint32_t>(rng() & 0xFFFFFF);
  e.control.camera_station = 1 + static_cast<int>(rng() % 8);
  e.control.mode = 1 + static_cast<int>(rng() % 3);
  e.control.priority_fixed = static_cast<std::uint32_t>(rng() % 128);
  e.arm = arm::SinCosFromDegrees({ang(rng), ang(rng), ang(rng), ang(rng), ang(rng), ang(rng)});
  e.shoulder_height_ft = 20 * u(rng);
  e.finger_gap_ft = u(rng);
  e.p_RoEye_R_ft = {pos(rng), pos(rng), pos(rng)};
  e.R_RE = RandomRotation(rng);
  e.fov_deg = 5 + 100 * u(rng);
  e.p_RoPo_R_ft = {pos(rng), pos(rng), pos(rng)};
  e.R_RP = RandomRotation(rng);
  return e;
}

TEST(EsgFrame, PackedFramesFitTheIeuAndRoundTripWithinOneLsb) {
  const std::uint64_t seed = 42;
  std::printf("seed %llu\n", static_cast<unsigned long long>(seed));
  std::mt19937_64 rng(seed);
  const double ft = wire::kFT12.lsb(), sc = wire::kSC22.lsb();
  for (int i = 0; i < 20000; ++i) {
    const wire::EsgFrameData e = RandomEsg(rng);
    Counters c;
    const std::vector<std::int32_t> w = wire::PackEsgWords(e, &c);
    ASSERT_LE(w.size(), 64u);
    ASSERT_EQ(wire::FirstInvalidWord(w), -1);
    ASSERT_EQ(c.Sum(Counter::kSaturatedArm, Counter::kSaturatedView), 0);
    const wire::EsgFrameData d = wire::UnpackEsgWords(w);
    ASSERT_EQ(d.frame_count, e.frame_count);
    ASSERT_EQ(d.control, e.control);
    for (int k = 0; k < 6; ++k) {
      ASSERT_NEAR(d.arm[k].s, e.arm[k].s, sc);
      ASSERT_NEAR(d.arm[k].c, e.arm[k].c, sc);
    }
    ASSERT_LE((d.p_RoEye_R_ft - e.p_RoEye_R_ft).cwiseAbs().maxCoeff(), ft);
    ASSERT_LE((d.R_RE - e.R_RE).cwiseAbs().maxCoeff(), sc);
    ASSERT_LE((d.R_RP - e.R_RP).cwiseAbs().maxCoeff(), sc);
    ASSERT_NEAR(d.fov_deg, e.fov_deg, wire::kBamLsbDeg);
    ASSERT_NEAR(d.shoulder_height_ft, e.shoulder_height_ft, ft);
  }
}

TEST(EsgFrame, PositionsBeyondTheFormatSaturateAndAreCounted) {
  std::mt19937_64 rng(1);
  wire::EsgFrameData e = RandomEsg(rng);
  e.p_RoEye_R_ft.x() = 1e5;
  Counters c;
  const auto w = wire::PackEsgWords(e, &c);
  EXPECT_EQ(c.Get(Counter::kSaturatedEye), 1);
  EXPECT_NEAR(wire::UnpackEsgWords(w).p_RoEye_R_ft.x(), 2048.0, 1e-3);
}

std::string ErrorOf(std::vector<std::int32_t> w) {
  try {
    wire::UnpackEsgWords(w);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(EsgFrame, MalformedFramesAreRefusedNamingTheWord) {
  std::mt19937_64 rng(2);
  const std::vector<std::int32_t> good = wire::PackEsgWords(RandomEsg(rng), nullptr);
  ASSERT_EQ(ErrorOf(good), "");
  {
    auto w = good;
    w[17] |= 1 << 24;
    EXPECT_NE(ErrorOf(w).find("word 17"), std::string::npos) << ErrorOf(w);
  }
  {
    auto w = good;
    w.push_back(0);
    EXPECT_NE(ErrorOf(w).find("this layout has " + std::to_string(wire::esg_words::kCount)),
              std::string::npos)
        << ErrorOf(w);
  }
  {
    auto w = good;
    w[wire::esg_words::kArm] = 0;
    w[wire::esg_words::kArm + 1] = 0;  // sin = cos = 0
    EXPECT_NE(ErrorOf(w).find("unit circle"), std::string::npos) << ErrorOf(w);
  }
  {
    auto w = good;
    for (int k = 0; k < 9; ++k) w[wire::esg_words::kView + k] = 0;
    EXPECT_NE(ErrorOf(w).find("rotation"), std::string::npos) << ErrorOf(w);
  }
  {
    auto w = good;
    w[wire::esg_words::kControl] = 0;  // mode 0
    EXPECT_NE(ErrorOf(w).find("mode 0"), std::string::npos) << ErrorOf(w);
  }
  {
    auto w = good;
    w[wire::esg_words::kFov] = 0;
    EXPECT_NE(ErrorOf(w).find("field of view"), std::string::npos) << ErrorOf(w);
  }
}

TEST(DcpFrame, RoundTripAndRefusals) {
  std::mt19937_64 rng(3);
  wire::DcpFrameData d;
  d.frame = 12;
  d.input_frame = 10;
  d.arm = arm::SinCosFromDegrees({1, 2, 3, 4, 5, 6});
  d.control.mode = 2;
  d.control.acquired = true;
  d.planes[1].n_R = Eigen::Vector3d(0, 0.6, 0.8);
  d.planes[1].d_ft = -12.5;
  d.plane_valid = 2;
  d.shoulder_height_ft = 4.25;
  d.finger_gap_ft = 0.5;
  d.camera_pan_deg = -30;
  d.camera_tilt_deg = 12;
  d.camera_zoom = 0.25;
  d.p_RoPo_R_ft = {30, 1, -2};
  d.R_RP = RandomRotation(rng);
  dcp_frame_t m;
  wire::PackDcpFrame(d, &m, nullptr);
  const wire::DcpFrameData u = wire::UnpackDcpFrame(m);
  EXPECT_EQ(u.frame, 12);
  EXPECT_EQ(u.control, d.control);
  EXPECT_EQ(u.plane_valid, 2u);
  EXPECT_NEAR(u.planes[1].d_ft, -12.5, 1e-9);
  EXPECT_NEAR(u.planes[1].n_R.y(), 0.6, 1e-6);
  EXPECT_NEAR(u.camera_pan_deg, -30, 1e-4);
  EXPECT_NEAR(u.camera_zoom, 0.25, 1e-6);
  EXPECT_LT((u.R_RP - d.R_RP).norm(), 1e-6);

  dcp_frame_t bad = m;
  bad.control_word |= 1 << 20;  // a priority bit: scene_proc's, not the DCP's
  EXPECT_THROW(wire::UnpackDcpFrame(bad), InputError);
  bad = m;
  bad.state_words[wire::dcp_state::kPayloadPos] = -5;  // bits above 23
  EXPECT_THROW(wire::UnpackDcpFrame(bad), InputError);
  bad = m;
  bad.plane_status = 9;
  EXPECT_THROW(wire::UnpackDcpFrame(bad), InputError);
}

}  // namespace
}  // namespace rms
