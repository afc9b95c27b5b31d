// rms_snapshot: pictures of a mission from every camera station, rendered
// exactly as esg_renderer renders them (rms/sim/snapshots.h). By default each
// station is shown in the middle of the mission's first visit to it (or,
// with --time, all at one moment); one PNG a station and a contact sheet of
// all eight. The README's pictures come from
//   build/tools/rms_snapshot --out-dir docs/images
// With --shot T:STATION:NAME (repeated) it takes just those pictures, with
// the crosshairs on and the live window's guidance panel drawn as the
// operator station would fill it (docs/operator.md's pictures).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <optional>

#include "rms/base/command_line.h"
#include "rms/sim/snapshots.h"

int main(int argc, char** argv) {
  CLI::App app{
      "rmslab rms_snapshot: one picture from each camera station over a mission, and a contact "
      "sheet"};
  std::string config_path = rms::DefaultConfigPath();
  std::string timeline = std::string(RMSLAB_SOURCE_DIR) + "/scripts/timelines/mission.tl";
  rms::sim::PictureOptions o;
  int columns = 4;
  std::optional<double> at_time;
  app.add_option("--config", config_path, "Configuration file")->capture_default_str();
  app.add_option("--timeline", timeline, "Timeline to fly")->capture_default_str();
  app.add_option("--out-dir", o.out_dir, "Directory for station_N.png and stations.png")
      ->capture_default_str();
  app.add_option("--time", at_time,
                 "All stations at this time (s) instead of each at its first visit");
  app.add_option("--width", o.width, "Width of each picture")
      ->capture_default_str()
      ->check(CLI::Range(64, 4096));
  app.add_option("--height", o.height, "Height of each picture")
      ->capture_default_str()
      ->check(CLI::Range(48, 4096));
  app.add_option("--columns", columns, "Pictures a row in the contact sheet")
      ->capture_default_str()
      ->check(CLI::Range(1, 8));
  app.add_option("--gl", o.gl, "GL backend: osmesa or egl")->capture_default_str();
  std::vector<std::string> shots;
  app.add_option("--shot", shots,
                 "T:STATION:NAME: one picture at time T (s) from STATION into NAME.png, crosshairs "
                 "on, with the "
                 "window's guidance panel (repeat for more)");
  std::string guidance_frame = "end_effector";
  app.add_option("--guidance-frame", guidance_frame,
                 "The guidance panel's command frame: end_effector, orbiter, payload")
      ->capture_default_str()
      ->check(CLI::IsMember({"end_effector", "orbiter", "payload"}));
  if (const auto rc = rms::ParseCommandLine(app, argc, argv)) return *rc;
  try {
    const rms::LabConfig config = rms::LoadConfig(config_path);
    const auto tl = rms::operator_station::Timeline::Load(timeline, config.inputs);
    if (!shots.empty()) {
      rms::sim::TakeShots(config, tl, shots,
                          *rms::operator_station::ParseCommandFrame(guidance_frame), o);
      return 0;
    }
    rms::sim::ContactSheet(config, tl, rms::sim::StationTimes(config, tl, at_time), columns, o);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rms_snapshot: %s\n", e.what());
    return 2;
  }
}
