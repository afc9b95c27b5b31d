#pragma once
// The standard mission as waypoints for the end effector, solved to joint
// angles: over the payload's bar receptacle, down, close the finger
// (acquisition), straight up out of the cargo bay (extraction), turn the
// payload's probe up under the CAE's port and rise to it (docking). Written as
// a timeline (docs/timeline.md) by rms_mission; the geometry comes from the
// configuration, so the plan follows any change an experimenter makes.
#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "rms/base/config.h"
#include "rms/mission/mission_geometry.h"

namespace rms::mission {

struct Keyframe {
  double t_s = 0;
  std::array<double, 6> angles_deg{};
  double shoulder_height_ft = 0;
  double finger = 0;
  int camera = 0;  // 0: unchanged
  std::string note;
  std::string extra;  // more timeline items, e.g. "camera_zoom=0.5"
};

// Throws rms::InputError naming the waypoint when one is out of reach, or
// puts the arm or the payload into the orbiter or the CAE.
std::vector<Keyframe> PlanMission(const LabConfig& config);

std::string FormatTimeline(const std::vector<Keyframe>& keys, const std::string& header);

// The header of scripts/timelines/mission.tl.
inline constexpr const char* kMissionHeader =
    "# The standard mission, written by rms_mission for the default configuration:\n"
    "# acquire the payload (Mode 1), extract it (Mode 2), dock it to the CAE (Mode 3).\n"
    "# Regenerate with: build/tools/rms_mission --out scripts/timelines/mission.tl\n";

}  // namespace rms::mission
