// The ESG draws each object where the frame's words put it: rendered in
// identity colours, the pixel where an independent pinhole projection of the
// kinematics puts an arm part has that part's colour. Both GL backends draw
// the same pixels; priority mode (no depth buffer) draws what depth mode does.
#include "rms/esg_renderer/renderer.h"

#include <cmath>
#include <cstdio>
#include <gtest/gtest.h>
#include <random>

#include "rms/base/config.h"
#include "rms/esg_renderer/draw_order.h"
#include "rms/esg_renderer/gl_context.h"
#include "rms/esg_renderer/overlay.h"
#include "rms/scene_model/scene_model.h"
#include "rms/scene_proc/camera_stations.h"
#include "rms/scene_proc/visual_scene_program.h"

#include "pinhole.h"

namespace rms::esg_renderer {
namespace {

using testing::Project;

class Renderer : public ::testing::Test {
 protected:
  static constexpr int kW = 320, kH = 240;
  Renderer()
      : gl(CreateGlContext(GlBackend::kOsMesa, kW, kH)),
        renderer(config, gl.get(), RenderOptions{.id_colors = true}) {}

  // A frame as scene_proc makes it (view, priority bits) for a pose.
  wire::EsgFrameData Frame(std::array<double, 6> deg, int station, double height = 3.0,
                           double pan = 0, double tilt = 0, double zoom = 0) {
    scene_proc::VisualSceneProgram vs(config);
    wire::DcpFrameData d;
    d.arm = arm::SinCosFromDegrees(deg);
    d.control.camera_station = station;
    d.shoulder_height_ft = height;
    d.finger_gap_ft = 1.3;  // open: the finger clear of the bar
    d.camera_pan_deg = pan;
    d.camera_tilt_deg = tilt;
    d.camera_zoom = zoom;
    d.p_RoPo_R_ft = config.payload.p_RoPo_R_ft;
    d.R_RP = config.payload.R_RP;
    wire::EsgFrameData e;
    for (int i = 0; i < 300; ++i) e = vs.Step(d, 0, nullptr);  // let the camera drive arrive
    return wire::UnpackEsgWords(wire::PackEsgWords(e, nullptr));
  }

  scene_model::Rgb PixelAt(const std::uint8_t* px, int x, int y) {
    const std::uint8_t* p = px + (static_cast<std::size_t>(y) * kW + x) * 4;
    return {p[0], p[1], p[2]};
  }

  LabConfig config = LoadConfig(DefaultConfigPath());
  std::unique_ptr<GlContext> gl;
  FrameRenderer renderer;
};

TEST_F(Renderer, ArmPartsAppearWhereTheKinematicsPutThem) {
  for (const auto& deg : {std::array<double, 6>{20, 60, -70, -30, 0, 0},
                          std::array<double, 6>{-30, 35, -20, 10, 20, 45}}) {
    const wire::EsgFrameData f = Frame(deg, 8);
    renderer.Render(f);
    const std::uint8_t* px = renderer.pixels();
    const arm::ArmPose arm = arm::ComputeArmPose(config.arm, f.arm, f.shoulder_height_ft);
    for (const auto& [p, id] :
         {std::pair{0.5 * (arm.p_RoS_R + arm.p_RoE_R), scene_model::kUpperBoom},
          std::pair{0.5 * (arm.p_RoE_R + arm.p_RoW_R), scene_model::kLowerBoom}}) {
      int x = 0, y = 0;
      ASSERT_TRUE(Project(f, p, kW, kH, &x, &y));
      EXPECT_EQ(PixelAt(px, x, y), IdColor(id))
          << scene_model::ClusterName(id) << " at " << x << "," << y;
    }
  }
}

TEST_F(Renderer, MovingTheArmMovesItsPixels) {
  const wire::EsgFrameData a = Frame({20, 60, -70, -30, 0, 0}, 8);
  const wire::EsgFrameData b = Frame({-40, 20, -10, -30, 0, 0}, 8);
  const arm::ArmPose pa = arm::ComputeArmPose(config.arm, a.arm, 3.0);
  int x = 0, y = 0;
  ASSERT_TRUE(Project(a, 0.5 * (pa.p_RoE_R + pa.p_RoW_R), kW, kH, &x, &y));
  renderer.Render(a);
  EXPECT_EQ(PixelAt(renderer.pixels(), x, y), IdColor(scene_model::kLowerBoom));
  renderer.Render(b);
  EXPECT_NE(PixelAt(renderer.pixels(), x, y), IdColor(scene_model::kLowerBoom));
}

TEST_F(Renderer, SpaceIsBlackAndTheBayFloorIsTheFloor) {
  const wire::EsgFrameData f = Frame({0, 0, 0, 0, 0, 0}, 1);  // aft flight deck window
  renderer.Render(f);
  const std::uint8_t* px = renderer.pixels();
  int x = 0, y = 0;
  ASSERT_TRUE(Project(f, Eigen::Vector3d(12.0, 4.0, -12.0), kW, kH, &x, &y));
  EXPECT_EQ(PixelAt(px, x, y), IdColor(scene_model::kFloor));
  ASSERT_TRUE(Project(
      f, f.p_RoEye_R_ft + 100 * (f.R_RE.col(0) - 0.6 * f.R_RE.col(2) + 0.55 * f.R_RE.col(1)), kW,
      kH, &x, &y));
  EXPECT_EQ(PixelAt(px, x, y), (scene_model::Rgb{0, 0, 0}));
}

TEST_F(Renderer, IdColoursMapBackToTheirClusters) {
  for (int c = 0; c < scene_model::kNumClusters; ++c) {
    const scene_model::Rgb rgb = IdColor(c);
    EXPECT_EQ(ClusterOfColor(rgb.data()), c);
  }
  const std::uint8_t black[3] = {0, 0, 0};
  EXPECT_EQ(ClusterOfColor(black), -1);
}

TEST_F(Renderer, TheEglBackendDrawsTheSamePixels) {
  std::unique_ptr<GlContext> egl;
  try {
    egl = CreateGlContext(GlBackend::kEgl, kW, kH);
  } catch (const std::exception& e) {
    // scripts/install-deps installs libegl-dev (and through it Mesa's EGL).
    FAIL() << "EGL surfaceless not available: " << e.what();
  }
  EXPECT_NE(egl->description().find("EGL"), std::string::npos);
  FrameRenderer r2(config, egl.get(), RenderOptions{.id_colors = true});
  const wire::EsgFrameData f = Frame({20, 60, -70, -30, 0, 0}, 8);
  r2.Render(f);
  const std::vector<std::uint8_t> from_egl(r2.pixels(), r2.pixels() + kW * kH * 4);
  renderer.Render(f);
  const std::uint8_t* from_osmesa = renderer.pixels();
  int differ = 0, lit = 0;
  for (int i = 0; i < kW * kH; ++i) {
    differ += std::memcmp(&from_egl[4 * i], from_osmesa + 4 * i, 3) != 0;
    lit += from_egl[4 * i] != 0;
  }
  EXPECT_GT(lit, kW * kH / 10);
  EXPECT_EQ(differ, 0);
}

TEST_F(Renderer, PriorityModeDrawsWhatTheDepthBufferDraws) {
  std::unique_ptr<GlContext> gl2 = CreateGlContext(GlBackend::kOsMesa, kW, kH);
  FrameRenderer depth(config, gl2.get(),
                      RenderOptions{.visibility = Visibility::kDepth, .id_colors = true});
  int frames = 0;
  for (int station = 1; station <= 8; ++station) {
    for (const auto& deg : {std::array<double, 6>{16, 53, -85, -58, 0, -74},
                            std::array<double, 6>{0, 30, -10, 0, 0, 0}}) {
      const wire::EsgFrameData f = Frame(deg, station);
      renderer.Render(f);
      const std::vector<std::uint8_t> prio(renderer.pixels(), renderer.pixels() + kW * kH * 4);
      depth.Render(f);
      const std::uint8_t* ref = depth.pixels();
      int differ = 0;
      for (int i = 0; i < kW * kH; ++i) differ += std::memcmp(&prio[4 * i], ref + 4 * i, 3) != 0;
      EXPECT_EQ(differ, 0) << "station " << station;
      EXPECT_EQ(renderer.stats().cycles_broken, 0) << "station " << station;
      ++frames;
    }
  }
  EXPECT_EQ(frames, 16);
}

// esg_renderer's unchanged frames: the last output image with what lay under
// its frame counter put back and the overlay drawn again is, pixel for pixel,
// the image a full redraw gives (the scene and the new frame's overlay), for
// every station's overlay (crosshairs on the wrist and CAE cameras, lamps,
// NO VIDEO), counters that gain digits, and images so small that the lamps
// and the crosshairs run over the counter.
TEST_F(Renderer, AnUnchangedFramesOverlayDrawnAgainOverTheLastImageIsAFullRedraw) {
  constexpr unsigned kSeed = 19721122;
  std::printf("seed %u\n", kSeed);
  std::mt19937 rng(kSeed);
  const OverlayModel model = MakeOverlayModel(config);
  const std::pair<std::uint32_t, std::uint32_t> counters[] = {
      {41, 42}, {999999, 1000000}, {7, 4294967295u}, {4294967295u, 0}};
  int checked = 0;
  for (const auto& [w, h] : {std::pair{1024, 768}, std::pair{320, 240}, std::pair{100, 75}}) {
    std::vector<std::uint8_t> scene(static_cast<std::size_t>(w) * h * 4);
    for (auto& b : scene) b = static_cast<std::uint8_t>(rng());
    for (int station = 1; station <= static_cast<int>(config.cameras.size()); ++station) {
      wire::EsgFrameData f = Frame({10, 30, -60, 20, 0, 0}, station);
      f.control.overlay = true;
      f.control.crosshairs = true;
      f.control.no_video = station == 2;
      f.control.collision = f.control.docked = (station % 2) == 0;
      f.control.acquired = f.control.receptacle_collision = (station % 2) == 1;
      for (const auto& [before, after] : counters) {
        f.frame_count = before;
        std::vector<std::uint8_t> last = scene;
        CounterBackdrop backdrop;
        DrawOverlay(last.data(), w, h, f, model, &backdrop);
        f.frame_count = after;
        std::vector<std::uint8_t> full = scene;
        DrawOverlay(full.data(), w, h, f, model);
        // (On the smallest image the lamps, drawn after it, may hide it.)
        if (w >= 320) {
          ASSERT_NE(last, full) << "the counter changed no pixel at " << w << "x" << h;
        }
        RestoreCounterBackdrop(last.data(), w, h, backdrop);
        DrawOverlay(last.data(), w, h, f, model, &backdrop);
        ASSERT_EQ(last, full) << w << "x" << h << ", station " << station << ", counter " << before
                              << " -> " << after;
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 3 * 4 * static_cast<int>(config.cameras.size()));
}

}  // namespace
}  // namespace rms::esg_renderer
