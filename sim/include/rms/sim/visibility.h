#pragma once
// Visual priority (separating planes, no depth buffer: the ESG's way)
// against the depth-buffer reference over a whole scripted mission, from
// every camera station (docs/scene.md "Measured: priority against the depth buffer"):
// each pixel on which the two disagree is judged by an exact ray cast
// through its centre. rms_visibility prints it.
#include <array>
#include <map>
#include <string>
#include <tuple>

#include "rms/base/config.h"

namespace rms::sim {

struct VisibilityOptions {
  std::string timeline;  // the mission flown
  int every = 1;         // every Nth frame checked
  int width = 1024, height = 768;
  std::string gl = "osmesa";  // GL backend
  bool explain = false;       // count the cluster pairs on the differing pixels
};

struct StationVisibility {
  long frames = 0, pixels = 0, differing = 0, frames_differing = 0, cycles = 0;
  long priority_errors = 0;   // the exact ray cast sides with the depth buffer
  long reference_errors = 0;  // the exact ray cast sides with priority
  long silhouette_ties = 0;   // within 1/64 pixel of a silhouette: the rasteriser's precision
};

struct VisibilityReport {
  std::array<StationVisibility, kNumCameraStations> stations{};
  // With explain: pixels by (station, cluster drawn by priority, cluster the
  // depth buffer shows; -1 the sky).
  std::map<std::tuple<int, int, int>, long> pairs;
};

VisibilityReport CompareVisibility(const LabConfig& config, const VisibilityOptions& options);

}  // namespace rms::sim
