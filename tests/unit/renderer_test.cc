// The ESG draws each object where the frame's words put it: rendered in
// identity colours with OSMesa, the pixel where an independent pinhole
// projection of the kinematics puts an arm part has that part's colour.
#include <gtest/gtest.h>

#include <cmath>

#include "camera_stations.h"
#include "gl_context.h"
#include "models.h"
#include "renderer.h"
#include "pinhole.h"
#include "rms/config.h"

namespace rms::esg {
namespace {

using testing::Project;

class Renderer : public ::testing::Test {
 protected:
  static constexpr int kW = 320, kH = 240;
  Renderer() : gl(CreateOsMesaContext(kW, kH)), renderer(config, gl.get(), RenderOptions{true}) {}

  EsgFrameData Frame(std::array<double, 6> deg, int station, double height = 3.0) {
    EsgFrameData f;
    f.control.camera_station = station;
    f.arm = SinCosFromDegrees(deg);
    f.shoulder_height_ft = height;
    f.finger_gap_ft = 0.8;
    const ArmPose arm = ComputeArmPose(config.arm, f.arm, height);
    const scene::CameraView v = scene::ComputeCameraView(config, station, 0, 0, 0, arm, nullptr);
    f.p_RoEye_R_ft = v.p_RoEye_R_ft;
    f.R_RE = v.R_RE;
    f.fov_deg = v.fov_deg;
    f.p_RoPo_R_ft = config.payload.p_RoPo_R_ft;
    f.R_RP = config.payload.R_RP;
    return f;
  }

  Rgb PixelAt(int x, int y) {
    const std::uint8_t* p = renderer.pixels() + (static_cast<std::size_t>(y) * kW + x) * 4;
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
    const ArmPose arm = ComputeArmPose(config.arm, f.arm, f.shoulder_height_ft);
    const struct {
      Eigen::Vector3d p;
      PartId id;
    } checks[] = {
        {0.5 * (arm.p_RoS_R + arm.p_RoE_R), PartId::kUpperBoom},
        {0.5 * (arm.p_RoE_R + arm.p_RoW_R), PartId::kLowerBoom},
    };
    for (const auto& c : checks) {
      int x = 0, y = 0;
      ASSERT_TRUE(Project(f, c.p, kW, kH, &x, &y));
      EXPECT_EQ(PixelAt(x, y), IdColor(c.id)) << PartName(c.id) << " at " << x << "," << y;
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
  EXPECT_EQ(PixelAt(x, y), IdColor(PartId::kLowerBoom));
  renderer.Render(b);  // the boom has left that pixel
  EXPECT_NE(PixelAt(x, y), IdColor(PartId::kLowerBoom));
}

TEST_F(Renderer, SpaceIsBlackAndTheBayIsShuttle) {
  const EsgFrameData f = Frame({0, 0, 0, 0, 0, 0}, 1);  // aft flight deck window
  renderer.Render(f);
  int x = 0, y = 0;
  // The bay floor under the forward half, left of the payload.
  ASSERT_TRUE(Project(f, Eigen::Vector3d(12.0, 4.0, -12.0), kW, kH, &x, &y));
  EXPECT_EQ(PixelAt(x, y), IdColor(PartId::kShuttle));
  // Up and to the right of the line of sight, past the tail: empty sky.
  ASSERT_TRUE(Project(f, f.p_RoEye_R_ft + 100 * (f.R_RE.col(0) - 0.6 * f.R_RE.col(2) + 0.55 * f.R_RE.col(1)), kW, kH, &x, &y));
  EXPECT_EQ(PixelAt(x, y), (Rgb{0, 0, 0}));
}

TEST_F(Renderer, TheFingerMovesWithTheFingerGap) {
  EsgFrameData f = Frame({16.19, 52.93, -84.89, -58.04, 0, -73.81}, 8);
  const ArmPose arm = ComputeArmPose(config.arm, f.arm, 3.0);
  // EFF HEX 3's centre for an open gap, in R.
  const auto& ee = config.end_effector;
  const double xc = ee.palm_length_ft + 0.5 * ee.finger_length_ft;
  auto centre = [&](double gap) {
    return arm.X_RS2 * Eigen::Vector3d(xc, MovingFingerCentreY2(ee, gap), 0);
  };
  f.finger_gap_ft = ee.finger_gap_open_ft;
  EXPECT_NEAR((centre(ee.finger_gap_open_ft) - centre(ee.finger_gap_closed_ft)).norm(),
              ee.finger_gap_open_ft - ee.finger_gap_closed_ft, 1e-9);
  EXPECT_NEAR(MovingFingerCentreY2(ee, ee.finger_gap_open_ft),
              ee.palm_half_width_ft - ee.finger_thickness_ft - ee.finger_gap_open_ft - 0.5 * ee.finger_thickness_ft, 1e-12);
}

}  // namespace
}  // namespace rms::esg
