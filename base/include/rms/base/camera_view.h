#pragma once
// The views the autopilot and the mission plan switch to, each found among
// the configuration's camera stations (config [[cameras]]) by its mount --
// and, for the several on the shuttle, a word of its name -- never by its
// number (docs/architecture.md "One home for each quantity"). Reordered or
// added stations keep each view where it was.
#include <array>
#include <optional>
#include <string_view>
#include <vector>

#include "rms/base/config.h"

namespace rms {

enum class CameraView : int {
  kOverTheBay = 0,   // aft flight deck, overhead window: over the receptacle
  kPortAftWindow,    // aft flight deck, port aft window: up and over the bay
  kElbow,            // on the elbow
  kWrist,            // on the wrist: just above the receptacle
  kForwardBulkhead,  // cargo bay, forward bulkhead: the finger on the bar
  kAftBulkhead,      // cargo bay, aft bulkhead: lifting out of the bay
  kCaeDockingPort,   // on the CAE: the probe under the port
  kExternal,         // outside the orbiter: the whole arm
  kCount
};

struct CameraViewInfo {
  CameraView view;
  const char* name;       // as logged and shown ("wrist")
  CameraMount mount;      // the station's mount
  const char* name_word;  // a word of the station's name ("" when the mount alone says)
};
inline constexpr std::array<CameraViewInfo, static_cast<int>(CameraView::kCount)> kCameraViews = {{
    {CameraView::kOverTheBay, "over the bay", CameraMount::kShuttle, "overhead"},
    {CameraView::kPortAftWindow, "port aft window", CameraMount::kShuttle, "port aft"},
    {CameraView::kElbow, "elbow", CameraMount::kElbow, ""},
    {CameraView::kWrist, "wrist", CameraMount::kWrist, ""},
    {CameraView::kForwardBulkhead, "forward bulkhead", CameraMount::kShuttle, "forward bulkhead"},
    {CameraView::kAftBulkhead, "aft bulkhead", CameraMount::kShuttle, "aft bulkhead"},
    {CameraView::kCaeDockingPort, "CAE docking port", CameraMount::kCae, ""},
    {CameraView::kExternal, "external", CameraMount::kShuttle, "external"},
}};

static_assert(
    [] {
      for (std::size_t i = 0; i < kCameraViews.size(); ++i) {
        if (static_cast<std::size_t>(kCameraViews[i].view) != i) return false;
      }
      return true;
    }(),
    "kCameraViews is in CameraView's order");

// The camera station (1..kNumCameraStations) that gives the view: the first
// on its mount whose name has its word (any case); none when the
// configuration has no such station (the caller then keeps the station it
// has).
std::optional<int> CameraStationFor(const std::vector<CameraStationConfig>& cameras,
                                    CameraView view);

// Each view's station (0: none), found once.
using CameraStations = std::array<int, static_cast<int>(CameraView::kCount)>;
CameraStations FindCameraStations(const std::vector<CameraStationConfig>& cameras);

}  // namespace rms
