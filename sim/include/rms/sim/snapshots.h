#pragma once
// Pictures of a mission as esg_renderer renders them (the same words,
// renderer and overlay): one a camera station and a contact sheet of all
// eight (the README's), or single shots with the crosshairs and the live
// window's guidance panel as the operator station fills it
// (docs/operator.md's). rms_snapshot takes them.
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "rms/base/config.h"
#include "rms/operator_station/guidance.h"
#include "rms/operator_station/timeline.h"

namespace rms::sim {

struct PictureOptions {
  std::string out_dir = ".";
  int width = 480, height = 360;
  std::string gl = "osmesa";  // GL backend
};

// When to show each station: at `at_time_s` for all, or in the middle of the
// mission's first visit to it (the end for a station never selected, said).
std::array<double, kNumCameraStations> StationTimes(const LabConfig& config,
                                                    const operator_station::Timeline& tl,
                                                    std::optional<double> at_time_s);

// out_dir/station_N.png each at its time, and out_dir/stations.png, `columns` a row.
void ContactSheet(const LabConfig& config, const operator_station::Timeline& tl,
                  const std::array<double, kNumCameraStations>& when, int columns,
                  const PictureOptions& o);

// One picture a spec "T:STATION:NAME" (NAME.png at T s from STATION),
// crosshairs on, with the guidance panel in `frame`; InputError for a bad spec.
void TakeShots(const LabConfig& config, const operator_station::Timeline& tl,
               const std::vector<std::string>& shots, operator_station::CommandFrame frame,
               const PictureOptions& o);

}  // namespace rms::sim
