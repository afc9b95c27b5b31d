// dynamics_proc's and scene_proc's libraries chained on one log-backed
// transport: deterministic, no network. One ESG frame per input block, in
// order, carrying the kinematics; malformed blocks are counted and dropped.
// With esg_renderer's library on the end, the video has one frame per frame
// number.
#include <unistd.h>

#include <filesystem>
#include <gtest/gtest.h>

#include "rms/base/config.h"
#include "rms/dynamics_proc/dynamics_proc.h"
#include "rms/esg_frame_t.hpp"
#include "rms/esg_renderer/esg_renderer.h"
#include "rms/esg_renderer/gl_context.h"
#include "rms/operator_input_t.hpp"
#include "rms/scene_proc/camera_stations.h"
#include "rms/scene_proc/scene_proc.h"
#include "rms/wire/channels.h"
#include "rms/wire/dcp_mode.h"
#include "rms/wire/message_io.h"

namespace rms {
namespace {

class Pipeline : public ::testing::Test {
 protected:
  Pipeline() : lcm("", ""), dcp(config, &lcm), scene(config, &lcm) {
    lcm.Subscribe(wire::channels::kEsgFrame, [this](const void* d, int n, std::int64_t) {
      esg_frame_t m;
      ASSERT_EQ(wire::SafeDecode(d, n, &m), wire::DecodeError::kNone);
      esg.push_back(m);
    });
  }
  void Send(const operator_input_t& m) {
    transport::PublishMessage(lcm, wire::channels::kOperatorInput, m);
    while (lcm.HandleSubscriptions(0) > 0) {
    }
  }
  operator_input_t Block(std::int64_t frame, const wire::OperatorInputs& in) {
    operator_input_t m{};
    m.frame = frame;
    m.send_time_us = 1000 * frame;
    const auto w = wire::EncodeInputs(in, config.inputs, nullptr);
    std::copy(w.begin(), w.end(), m.words);
    return m;
  }
  LabConfig config = LoadConfig(DefaultConfigPath());
  transport::LogLcm lcm;
  dynamics_proc::DynamicsProc dcp;
  scene_proc::SceneProc scene;
  std::vector<esg_frame_t> esg;
};

TEST_F(Pipeline, OneEsgFramePerInputBlockCarryingTheKinematics) {
  wire::OperatorInputs in = wire::InitialInputs(config.inputs);
  for (int f = 0; f < 30; ++f) {
    in.value[kShoulderYaw] = f;
    in.value[kShoulderPitch] = 2.0 * f;
    in.value[kShoulderHeight] = 3.0 + 0.1 * f;
    in.camera_station = 1 + f % 8;
    Send(Block(f, in));
  }
  ASSERT_EQ(esg.size(), 30u);
  for (int f = 0; f < 30; ++f) {
    EXPECT_EQ(esg[f].frame, f);
    EXPECT_EQ(esg[f].input_frame, f);
    ASSERT_LE(esg[f].num_words, 64);
    const wire::EsgFrameData d = wire::UnpackEsgWords(esg[f].words);
    EXPECT_EQ(d.control.camera_station, 1 + f % 8);
    EXPECT_EQ(d.control.mode, wire::DcpMode::kAcquisition);
    EXPECT_NEAR(std::atan2(d.arm[0].s, d.arm[0].c) * 180 / M_PI, f, 0.006);
    EXPECT_NEAR(std::atan2(d.arm[1].s, d.arm[1].c) * 180 / M_PI, 2.0 * f, 0.006);
    EXPECT_NEAR(d.shoulder_height_ft, 3.0 + 0.1 * f, 1e-3);
    // The payload rests at its bay position in Mode 1.
    EXPECT_LT((d.p_RoPo_R_ft - config.payload.p_RoPo_R_ft).norm(), 1e-3);
  }
  EXPECT_EQ(dcp.counters().Get(Counter::kPublished), 30);
  EXPECT_EQ(scene.counters().Get(Counter::kPublished), 30);
}

TEST_F(Pipeline, ViewFollowsTheSelectedCameraStation) {
  wire::OperatorInputs in = wire::InitialInputs(config.inputs);
  in.camera_station = 8;
  Send(Block(0, in));
  ASSERT_EQ(esg.size(), 1u);
  const wire::EsgFrameData d = wire::UnpackEsgWords(esg[0].words);
  const auto& cam = config.cameras[7];
  EXPECT_LT((d.p_RoEye_R_ft - cam.p_MoCam_M_ft).norm(), 1e-3);
  const Eigen::Vector3d look = (cam.p_MoAim_M_ft - cam.p_MoCam_M_ft).normalized();
  EXPECT_LT((d.R_RE.col(0) - look).norm(), 1e-5);
  EXPECT_NEAR(d.fov_deg, cam.fov_max_deg, 1e-3);  // zoom 0: widest
}

TEST_F(Pipeline, MalformedDuplicateAndStaleBlocksAreCountedAndDropped) {
  wire::OperatorInputs in = wire::InitialInputs(config.inputs);
  Send(Block(0, in));
  operator_input_t bad = Block(1, in);
  bad.words[2] = 0x7000000;  // bits above 23
  Send(bad);
  Send(Block(1, in));
  Send(Block(1, in));  // duplicate
  Send(Block(0, in));  // stale
  const char junk[5] = {1, 2, 3, 4, 5};
  lcm.Publish(wire::channels::kOperatorInput, junk, 5);
  while (lcm.HandleSubscriptions(0) > 0) {
  }
  Send(Block(4, in));  // frames 2 and 3 lost
  EXPECT_EQ(esg.size(), 3u);
  EXPECT_EQ(dcp.counters().Get(Counter::kDroppedBadWord), 1);
  EXPECT_EQ(dcp.counters().Get(Counter::kDroppedDuplicate), 1);
  EXPECT_EQ(dcp.counters().Get(Counter::kDroppedStale), 1);
  EXPECT_EQ(dcp.counters().Get(Counter::kDroppedTruncated), 1);
  EXPECT_EQ(dcp.counters().Get(Counter::kInputMissing), 2);
}

TEST_F(Pipeline, ResetReturnsToMode1AndSetsTheResetBit) {
  wire::OperatorInputs in = wire::InitialInputs(config.inputs);
  in.reset = true;
  Send(Block(0, in));
  ASSERT_EQ(esg.size(), 1u);
  const wire::EsgFrameData d = wire::UnpackEsgWords(esg[0].words);
  EXPECT_TRUE(d.control.reset);
  EXPECT_EQ(d.control.mode, wire::DcpMode::kAcquisition);
}

TEST_F(Pipeline, TheVideoHasOneFramePerFrameNumberThoughTheFirstFramesWereSuperseded) {
  // On a loaded machine frames 0 and 1 may both arrive before the ESG draws:
  // frame 1 supersedes frame 0, and the video must still start at frame 0.
  constexpr int kW = 64, kH = 48;
  auto gl = esg_renderer::CreateGlContext(esg_renderer::GlBackend::kOsMesa, kW, kH);
  esg_renderer::FrameRenderer renderer(config, gl.get(), {});
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("rms_pipeline_video_" + std::to_string(getpid()) + ".mp4"))
                               .string();
  esg_renderer::VideoWriter video(path, kW, kH, config.session.frame_rate_hz);
  esg_renderer::EsgOptions options;
  options.width = kW;
  options.height = kH;
  esg_renderer::EsgRenderer esg_node(config, &lcm, &renderer, options, &video, nullptr);
  wire::OperatorInputs in = wire::InitialInputs(config.inputs);
  for (int f = 0; f < 3; ++f) Send(Block(f, in));  // nothing drawn yet
  EXPECT_TRUE(esg_node.RenderPending());
  EXPECT_EQ(esg_node.counters().Get(Counter::kSuperseded), 2);
  Send(Block(3, in));
  EXPECT_TRUE(esg_node.RenderPending());
  Send(Block(4, in));
  Send(Block(5, in));  // frame 4 superseded at the end
  esg_node.FinishVideo();
  video.Close();
  EXPECT_EQ(video.frames_written(), 6);  // frames 0 to 5
  EXPECT_EQ(video.frames_dropped(), 0);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace rms
