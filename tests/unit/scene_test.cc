// The Visual Scene Program and the ESG over the standard mission, in
// process: each camera station shows what it should (object-id renders);
// pan, tilt and zoom move the image the right way; the camera drives slew at
// their rates; visual priority (no depth buffer) draws exactly what the
// depth buffer does, from every station, over the whole mission.
#include <cmath>
#include <cstring>
#include <fstream>
#include <gtest/gtest.h>
#include <map>
#include <set>
#include <sstream>

#include "rms/base/config.h"
#include "rms/esg_renderer/gl_context.h"
#include "rms/esg_renderer/renderer.h"
#include "rms/sim/offline_session.h"
#include "rms/sim/priority_table.h"
#include "rms/sim/visibility.h"

namespace rms {
namespace {

constexpr int kW = 320, kH = 240;

class Scene : public ::testing::Test {
 protected:
  Scene()
      : gl(esg_renderer::CreateGlContext(esg_renderer::GlBackend::kOsMesa, kW, kH)),
        renderer(config, gl.get(), {.id_colors = true}) {}

  // Pixels of each cluster in a frame's object-id render.
  std::map<int, int> Seen(const wire::EsgFrameData& f) {
    renderer.Render(f);
    const std::uint8_t* px = renderer.pixels();
    std::map<int, int> n;
    for (int i = 0; i < kW * kH; ++i) {
      const int c = esg_renderer::ClusterOfColor(px + 4 * i);
      if (c >= 0) ++n[c];
    }
    return n;
  }
  // The mission's frames at these times (s), from every station.
  std::map<double, std::array<wire::EsgFrameData, kNumCameraStations>> AtTimes(
      const std::set<double>& times) {
    sim::OfflineSession s(
        config,
        operator_station::Timeline::Load(
            std::string(RMSLAB_SOURCE_DIR) + "/scripts/timelines/mission.tl", config.inputs));
    std::map<double, std::array<wire::EsgFrameData, kNumCameraStations>> out;
    while (s.Next()) {
      for (double t : times) {
        if (std::abs(s.t_s() - t) < 1e-6) {
          for (int st = 1; st <= kNumCameraStations; ++st) out[t][st - 1] = s.esg(st);
        }
      }
    }
    return out;
  }

  LabConfig config = LoadConfig(DefaultConfigPath());
  std::unique_ptr<esg_renderer::GlContext> gl;
  esg_renderer::FrameRenderer renderer;
};

TEST_F(Scene, EachStationShowsWhatItShould) {
  const auto frames = AtTimes({11.0, 24.0, 41.0});  // at the grasp, out of the bay, docked
  struct Expect {
    double t;
    int station;
    std::vector<int> shows;
    std::vector<int> hides;
  };
  const std::vector<Expect> expects = {
      {11,
       1,
       {scene_model::kFloor, scene_model::kPayloadBody, scene_model::kEffHex1, scene_model::kWrist},
       {scene_model::kCaeModule}},  // aft flight deck, overhead
      {11,
       2,
       {scene_model::kFloor, scene_model::kPayloadBody, scene_model::kTail},
       {}},  // aft flight deck, port aft
      {11,
       3,
       {scene_model::kLowerBoom, scene_model::kPayloadBody},
       {scene_model::kUpperBoom}},  // elbow, looking along the lower boom
      {11,
       4,
       {scene_model::kEffHex1, scene_model::kEffHex2, scene_model::kEffHex3, scene_model::kBar,
        scene_model::kPayloadBody},
       {scene_model::kCaeModule}},  // wrist: fingers about the bar
      {11,
       5,
       {scene_model::kPayloadBody, scene_model::kBulkheadAft, scene_model::kEffHex1},
       {scene_model::kBulkheadFwd}},  // bay, forward bulkhead, looking aft
      {11,
       6,
       {scene_model::kPayloadBody, scene_model::kProbe, scene_model::kBulkheadFwd,
        scene_model::kCabin},
       {scene_model::kBulkheadAft}},  // bay, aft bulkhead, looking forward
      {24,
       8,
       {scene_model::kCaeModule, scene_model::kTail, scene_model::kPayloadBody,
        scene_model::kWingStbd, scene_model::kDoorStbd},
       {}},                                                           // external
      {41, 7, {scene_model::kProbe, scene_model::kPayloadBody}, {}},  // CAE port: the probe docked
      {41, 1, {scene_model::kFloor}, {scene_model::kPayloadBody}},  // the payload has left the bay
      {41, 3, {scene_model::kLowerBoom, scene_model::kPayloadBody, scene_model::kCaeModule}, {}},
  };
  for (const Expect& e : expects) {
    const auto seen = Seen(frames.at(e.t)[e.station - 1]);
    for (int c : e.shows) {
      EXPECT_GT(seen.count(c) ? seen.at(c) : 0, 20)
          << "t " << e.t << " station " << e.station << " should show "
          << scene_model::ClusterName(c);
    }
    for (int c : e.hides) {
      EXPECT_EQ(seen.count(c), 0u) << "t " << e.t << " station " << e.station << " should not show "
                                   << scene_model::ClusterName(c);
    }
  }
}

// The centroid (x, y) and size of a cluster's pixels from station 8 with the
// given pan, tilt and zoom commanded (the drive given time to arrive).
struct Blob {
  double x = 0, y = 0;
  int pixels = 0;
};

TEST_F(Scene, PanTiltAndZoomMoveTheImageTheRightWay) {
  const auto frames = AtTimes({11.0});
  sim::OfflineSession s(
      config, operator_station::Timeline::Load(
                  std::string(RMSLAB_SOURCE_DIR) + "/scripts/timelines/mission.tl", config.inputs));
  while (s.Next() && s.t_s() < 11.0 - 1e-9) {
  }
  auto look = [&](double pan, double tilt, double zoom) {
    scene_proc::VisualSceneProgram vs(config);
    wire::DcpFrameData d = s.dcp();
    d.control.camera_station = 8;
    d.camera_pan_deg = pan;
    d.camera_tilt_deg = tilt;
    d.camera_zoom = zoom;
    wire::EsgFrameData e;
    for (int i = 0; i < 150; ++i) e = vs.Step(d, 0, nullptr);  // 5 s: every drive has arrived
    renderer.Render(wire::UnpackEsgWords(wire::PackEsgWords(e, nullptr)));
    const std::uint8_t* px = renderer.pixels();
    Blob b;
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        if (esg_renderer::ClusterOfColor(px + 4 * (y * kW + x)) == scene_model::kCabin) {
          b.x += x;
          b.y += y;
          ++b.pixels;
        }
      }
    b.x /= std::max(b.pixels, 1);
    b.y /= std::max(b.pixels, 1);
    return b;
  };
  const Blob home = look(0, 0, 0);
  ASSERT_GT(home.pixels, 500);
  const Blob right = look(10, 0, 0);
  EXPECT_LT(right.x, home.x - 10) << "pan right: the scene moves left";
  const Blob up = look(0, 8, 0);
  EXPECT_GT(up.y, home.y + 10) << "tilt up: the scene moves down";
  const Blob in = look(0, 0, 0.5);
  EXPECT_GT(in.pixels, 1.5 * home.pixels) << "zoom in: objects grow";
  EXPECT_GT(std::hypot(in.x - kW / 2.0, in.y - kH / 2.0),
            std::hypot(home.x - kW / 2.0, home.y - kH / 2.0))
      << "zoom in: objects move out from the centre";
}

TEST_F(Scene, CameraDrivesSlewAtTheirRates) {
  scene_proc::VisualSceneProgram vs(config);
  wire::DcpFrameData d;
  d.arm = arm::SinCosFromDegrees({0, 0, 0, 0, 0, 0});
  d.control.camera_station = 1;
  d.shoulder_height_ft = 3;
  d.camera_pan_deg = 60;
  d.camera_zoom = 1;
  d.R_RP = config.payload.R_RP;
  const CameraStationConfig& cam = config.cameras[0];
  const double dt = 1.0 / config.session.frame_rate_hz;
  vs.Step(d, 0, nullptr);
  EXPECT_NEAR(vs.drive(1).pan_deg, cam.pan_rate_deg_s * dt, 1e-9);
  EXPECT_NEAR(vs.drive(1).zoom, cam.zoom_rate_per_s * dt, 1e-9);
  for (int i = 0; i < 200; ++i) vs.Step(d, 0, nullptr);
  EXPECT_NEAR(vs.drive(1).pan_deg, 60, 1e-9);
  EXPECT_NEAR(vs.drive(1).zoom, 1, 1e-9);
  // Beyond the station's limit: clamped and counted.
  Counters c;
  d.camera_pan_deg = 170;
  vs.Step(d, 0, &c);
  EXPECT_EQ(c.Get(Counter::kClampedCameraPan), 1);
  EXPECT_EQ(vs.drive(2).pan_deg, 0);  // other stations keep their drives
}

// docs/scene.md "Camera drives": the drive runs in session time. A scene
// that missed DCP frames 10..19 (lost on the way) makes up their slew with
// frame 20's command and from there agrees bit for bit with one that had
// them all; a frame numbered backward or a fresh numbering is one step.
TEST_F(Scene, ADriveMakesUpTheFramesLostOnTheWay) {
  scene_proc::VisualSceneProgram all(config), missed(config), renumbered(config);
  wire::DcpFrameData d;
  d.arm = arm::SinCosFromDegrees({0, 0, 0, 0, 0, 0});
  d.control.camera_station = 1;
  d.shoulder_height_ft = 3;
  d.camera_pan_deg = 60;
  d.camera_tilt_deg = -20;
  d.camera_zoom = 1;
  d.R_RP = config.payload.R_RP;
  for (std::int64_t f = 0; f <= 60; ++f) {
    d.frame = f;
    const wire::EsgFrameData a = all.Step(d, static_cast<std::uint32_t>(f), nullptr);
    if (f >= 10 && f < 20) continue;
    const wire::EsgFrameData b = missed.Step(d, static_cast<std::uint32_t>(f), nullptr);
    if (f < 20) continue;
    SCOPED_TRACE("DCP frame " + std::to_string(f));
    EXPECT_EQ(missed.drive(1).pan_deg, all.drive(1).pan_deg);
    EXPECT_EQ(missed.drive(1).tilt_deg, all.drive(1).tilt_deg);
    EXPECT_EQ(missed.drive(1).zoom, all.drive(1).zoom);
    EXPECT_EQ(wire::PackEsgWords(b, nullptr), wire::PackEsgWords(a, nullptr));
  }
  // Still slewing at frame 20 (the test means something): 60 deg at the rate.
  const double dt = 1.0 / config.session.frame_rate_hz;
  ASSERT_GT(60.0, config.cameras[0].pan_rate_deg_s * dt * 21);
  const double one_step = config.cameras[0].pan_rate_deg_s * dt;
  d.frame = 100;
  renumbered.Step(d, 100, nullptr);
  d.frame = 50;  // a restore to an earlier frame
  renumbered.Step(d, 50, nullptr);
  EXPECT_NEAR(renumbered.drive(1).pan_deg, 2 * one_step, 1e-12);
  d.frame = 50 + static_cast<std::int64_t>(61.0 / dt);  // a fresh numbering
  renumbered.Step(d, 0, nullptr);
  EXPECT_NEAR(renumbered.drive(1).pan_deg, 3 * one_step, 1e-12);
}

TEST_F(Scene, PriorityDrawsWhatTheDepthBufferDrawsOverTheMissionFromEveryStation) {
  // Every 15th frame of the mission from all eight stations at 320 x 240;
  // build/tools/rms_visibility measures every frame at 1024 x 768.
  sim::VisibilityOptions o;
  o.timeline = std::string(RMSLAB_SOURCE_DIR) + "/scripts/timelines/mission.tl";
  o.every = 15;
  o.width = kW;
  o.height = kH;
  const sim::VisibilityReport r = sim::CompareVisibility(config, o);
  EXPECT_GT(r.stations[0].frames, 80);
  for (int st = 0; st < kNumCameraStations; ++st) {
    EXPECT_EQ(r.stations[st].differing, 0) << "station " << st + 1;
    EXPECT_EQ(r.stations[st].cycles, 0) << "station " << st + 1;
  }
}

TEST_F(Scene, APlaneSeparatesEveryPairOfClustersThroughoutTheMission) {
  // A pair with no separating plane interpenetrates (the arm through the
  // orbiter, say): visual priority can then not be right, and the mission
  // flies through something solid.
  sim::OfflineSession s(
      config, operator_station::Timeline::Load(
                  std::string(RMSLAB_SOURCE_DIR) + "/scripts/timelines/mission.tl", config.inputs));
  long frames = 0;
  while (s.Next()) ++frames;
  EXPECT_EQ(frames, 1351);
  EXPECT_EQ(s.scene_counters().Get(Counter::kPriorityUnresolved), 0);
}

TEST_F(Scene, NoCameraEverSitsInsideASolid) {
  // A camera inside a convex cluster sees through it (all its faces turn
  // away) and would see its inside if back faces were drawn: a modelling
  // error that back-face culling hides. Every 5th frame of the mission, every
  // station, every solid cluster.
  const scene_model::SceneModel model = scene_model::BuildSceneModel(config);
  sim::OfflineSession s(
      config, operator_station::Timeline::Load(
                  std::string(RMSLAB_SOURCE_DIR) + "/scripts/timelines/mission.tl", config.inputs));
  long checked = 0;
  while (s.Next()) {
    if (s.frame() % 5) continue;
    for (int st = 1; st <= kNumCameraStations; ++st) {
      const wire::EsgFrameData& f = s.esg(st);
      const scene_model::ClusterPoses poses =
          scene_model::ComputeClusterPoses(config, f.scene_pose());
      for (int c = 0; c < scene_model::kNumClusters; ++c) {
        if (!poses.present[c] || model[c].flat) continue;
        ++checked;
        // The eye in the cluster's frame; inside when behind every face.
        const Eigen::Vector3f p = (poses.X_RC[c].inverse() * f.p_RoEye_R_ft).cast<float>();
        float max_out_ft = -1e9f;
        for (const scene_model::Triangle& t : model[c].mesh.triangles()) {
          if (!t.decal) max_out_ft = std::max(max_out_ft, t.n.dot(p - t.a));
        }
        EXPECT_GT(max_out_ft, 0.0f)
            << "station " << st << " (" << config.cameras[st - 1].name << ") is inside "
            << scene_model::ClusterName(c) << " at frame " << s.frame();
      }
    }
  }
  EXPECT_GT(checked, 10000);
}

TEST_F(Scene, ThePriorityTableInTheDocsIsWhatTheCodeComputes) {
  std::ifstream in(std::string(RMSLAB_SOURCE_DIR) + "/docs/priority-table.md");
  std::stringstream shipped;
  shipped << in.rdbuf();
  EXPECT_EQ(shipped.str(), sim::PriorityTableMarkdown(config, std::string(RMSLAB_SOURCE_DIR) +
                                                                  "/scripts/timelines/mission.tl"))
      << "regenerate: build/tools/rms_priority_table > docs/priority-table.md";
}

}  // namespace
}  // namespace rms
