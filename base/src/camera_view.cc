#include "rms/base/camera_view.h"

#include <algorithm>
#include <cctype>
#include <string>

namespace rms {

namespace {

std::string Lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

}  // namespace

std::optional<int> CameraStationFor(const std::vector<CameraStationConfig>& cameras,
                                    CameraView view) {
  const CameraViewInfo& info = kCameraViews[static_cast<int>(view)];
  const std::string word = Lower(info.name_word);
  for (std::size_t i = 0; i < cameras.size() && i < static_cast<std::size_t>(kNumCameraStations);
       ++i) {
    if (cameras[i].mount != info.mount) continue;
    if (Lower(cameras[i].name).find(word) != std::string::npos) return static_cast<int>(i) + 1;
  }
  return std::nullopt;
}

CameraStations FindCameraStations(const std::vector<CameraStationConfig>& cameras) {
  CameraStations stations{};
  for (const CameraViewInfo& info : kCameraViews)
    stations[static_cast<int>(info.view)] = CameraStationFor(cameras, info.view).value_or(0);
  return stations;
}

}  // namespace rms
