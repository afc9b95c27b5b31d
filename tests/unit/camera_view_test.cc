// Views found by their camera station's mount, not its number
// (rms/base/camera_view.h): reordered stations keep every view, and the
// mission plan and the autopilot follow.
#include "rms/base/camera_view.h"

#include <algorithm>
#include <gtest/gtest.h>
#include <string>
#include <vector>

#include "rms/mission/mission_plan.h"

namespace rms {
namespace {

std::string StationName(const LabConfig& c, int station) {
  return station == 0 ? "(unchanged)" : c.cameras.at(station - 1).name;
}

TEST(CameraView, EachViewIsFoundByItsMountWhereverItsStationIs) {
  const LabConfig c = LoadConfig(DefaultConfigPath());
  const CameraStations stations = FindCameraStations(c.cameras);
  // The default configuration has every view, each on its own station.
  std::vector<int> seen(stations.begin(), stations.end());
  std::sort(seen.begin(), seen.end());
  EXPECT_EQ(std::unique(seen.begin(), seen.end()), seen.end());
  for (const CameraViewInfo& v : kCameraViews) {
    const int s = stations[static_cast<int>(v.view)];
    ASSERT_GE(s, 1) << v.name;
    EXPECT_EQ(c.cameras[s - 1].mount, v.mount) << v.name;
  }
  EXPECT_EQ(StationName(c, stations[static_cast<int>(CameraView::kWrist)]), "wrist");
  EXPECT_EQ(StationName(c, stations[static_cast<int>(CameraView::kExternal)]), "external");
  // Reversed, every view finds the same station by name.
  LabConfig r = c;
  std::reverse(r.cameras.begin(), r.cameras.end());
  const CameraStations moved = FindCameraStations(r.cameras);
  for (const CameraViewInfo& v : kCameraViews) {
    const int i = static_cast<int>(v.view);
    EXPECT_NE(moved[i], stations[i]) << v.name << ": reversed, its number changes";
    EXPECT_EQ(StationName(r, moved[i]), StationName(c, stations[i])) << v.name;
  }
  // A view whose station is gone is none (the caller keeps its station).
  LabConfig no_wrist = c;
  no_wrist.cameras[stations[static_cast<int>(CameraView::kWrist)] - 1].mount = CameraMount::kElbow;
  EXPECT_FALSE(CameraStationFor(no_wrist.cameras, CameraView::kWrist).has_value());
}

TEST(CameraView, TheMissionPlanLooksThroughTheSameStationsWhenTheyAreReordered) {
  const LabConfig c = LoadConfig(DefaultConfigPath());
  LabConfig r = c;
  std::rotate(r.cameras.begin(), r.cameras.begin() + 3, r.cameras.end());
  const std::vector<mission::Keyframe> a = mission::PlanMission(c), b = mission::PlanMission(r);
  ASSERT_EQ(a.size(), b.size());
  int switches = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(StationName(c, a[i].camera), StationName(r, b[i].camera)) << a[i].note;
    switches += a[i].camera != 0;
  }
  EXPECT_GE(switches, 8) << "the plan switches to every view";
}

}  // namespace
}  // namespace rms
