// The ESG draws each object where the frame's words put it: rendered in
// identity colours, the pixel where an independent pinhole projection of the
// kinematics puts an arm part has that part's colour. Both GL backends draw
// the same pixels; priority mode (no depth buffer) draws what depth mode does.
#include <gtest/gtest.h>

#include <cmath>

#include "camera_stations.h"
#include "gl_context.h"
#include "pinhole.h"
#include "renderer.h"
#include "rms/config.h"
#include "rms/priority.h"
#include "rms/scene_model.h"
#include "visual_scene.h"

namespace rms::esg {
namespace {

using testing::Project;

class Renderer : public ::testing::Test {
 protected:
  static constexpr int kW = 320, kH = 240;
  Renderer() : gl(CreateGlContext(GlBackend::kOsMesa, kW, kH)), renderer(config, gl.get(), RenderOptions{.id_colors = true}) {}

  // A frame as scene_proc makes it (view, priority bits) for a pose.
  EsgFrameData Frame(std::array<double, 6> deg, int station, double height = 3.0, double pan = 0, double tilt = 0,
                     double zoom = 0) {
    scene::VisualScene vs(config);
    DcpFrameData d;
    d.arm = SinCosFromDegrees(deg);
    d.control.camera_station = station;
    d.shoulder_height_ft = height;
    d.finger_gap_ft = 1.3;  // open: the finger clear of the bar
    d.camera_pan_deg = pan;
    d.camera_tilt_deg = tilt;
    d.camera_zoom = zoom;
    d.p_RoPo_R_ft = config.payload.p_RoPo_R_ft;
    d.R_RP = config.payload.R_RP;
    EsgFrameData e;
    for (int i = 0; i < 300; ++i) e = vs.Step(d, 0, nullptr);  // let the camera drive arrive
    return UnpackEsgWords(PackEsgWords(e, nullptr));
  }

  Rgb PixelAt(const std::uint8_t* px, int x, int y) {
    const std::uint8_t* p = px + (static_cast<std::size_t>(y) * kW + x) * 4;
    return {p[0], p[1], p[2]};
  }

  LabConfig config = LoadConfig(DefaultConfigPath());
  std::unique_ptr<GlContext> gl;
  EsgRenderer renderer;
};

TEST_F(Renderer, ArmPartsAppearWhereTheKinematicsPutThem) {
  for (const auto& deg : {std::array<double, 6>{20, 60, -70, -30, 0, 0},
                          std::array<double, 6>{-30, 35, -20, 10, 20, 45}}) {
    const EsgFrameData f = Frame(deg, 8);
    renderer.Render(f);
    const std::uint8_t* px = renderer.pixels();
    const ArmPose arm = ComputeArmPose(config.arm, f.arm, f.shoulder_height_ft);
    for (const auto& [p, id] : {std::pair{0.5 * (arm.p_RoS_R + arm.p_RoE_R), kUpperBoom},
                                std::pair{0.5 * (arm.p_RoE_R + arm.p_RoW_R), kLowerBoom}}) {
      int x = 0, y = 0;
      ASSERT_TRUE(Project(f, p, kW, kH, &x, &y));
      EXPECT_EQ(PixelAt(px, x, y), IdColor(id)) << ClusterName(id) << " at " << x << "," << y;
    }
  }
}

TEST_F(Renderer, MovingTheArmMovesItsPixels) {
  const EsgFrameData a = Frame({20, 60, -70, -30, 0, 0}, 8);
  const EsgFrameData b = Frame({-40, 20, -10, -30, 0, 0}, 8);
  const ArmPose pa = ComputeArmPose(config.arm, a.arm, 3.0);
  int x = 0, y = 0;
  ASSERT_TRUE(Project(a, 0.5 * (pa.p_RoE_R + pa.p_RoW_R), kW, kH, &x, &y));
  renderer.Render(a);
  EXPECT_EQ(PixelAt(renderer.pixels(), x, y), IdColor(kLowerBoom));
  renderer.Render(b);
  EXPECT_NE(PixelAt(renderer.pixels(), x, y), IdColor(kLowerBoom));
}

TEST_F(Renderer, SpaceIsBlackAndTheBayFloorIsTheFloor) {
  const EsgFrameData f = Frame({0, 0, 0, 0, 0, 0}, 1);  // aft flight deck window
  renderer.Render(f);
  const std::uint8_t* px = renderer.pixels();
  int x = 0, y = 0;
  ASSERT_TRUE(Project(f, Eigen::Vector3d(12.0, 4.0, -12.0), kW, kH, &x, &y));
  EXPECT_EQ(PixelAt(px, x, y), IdColor(kFloor));
  ASSERT_TRUE(Project(f, f.p_RoEye_R_ft + 100 * (f.R_RE.col(0) - 0.6 * f.R_RE.col(2) + 0.55 * f.R_RE.col(1)), kW, kH, &x, &y));
  EXPECT_EQ(PixelAt(px, x, y), (Rgb{0, 0, 0}));
}

TEST_F(Renderer, IdColoursMapBackToTheirClusters) {
  for (int c = 0; c < kNumClusters; ++c) {
    const Rgb rgb = IdColor(c);
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
  EsgRenderer r2(config, egl.get(), RenderOptions{.id_colors = true});
  const EsgFrameData f = Frame({20, 60, -70, -30, 0, 0}, 8);
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
  EsgRenderer depth(config, gl2.get(), RenderOptions{.visibility = Visibility::kDepth, .id_colors = true});
  int frames = 0;
  for (int station = 1; station <= 8; ++station) {
    for (const auto& deg : {std::array<double, 6>{16, 53, -85, -58, 0, -74}, std::array<double, 6>{0, 30, -10, 0, 0, 0}}) {
      const EsgFrameData f = Frame(deg, station);
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

}  // namespace
}  // namespace rms::esg
