// rms_mission: writes the standard mission (acquire, extract, dock) as a
// timeline for the given configuration (docs/timeline.md).
#include <CLI/CLI.hpp>
#include <fstream>
#include <iostream>

#include "rms/base/check.h"
#include "rms/base/command_line.h"
#include "rms/base/text.h"
#include "rms/mission/mission_plan.h"

int main(int argc, char** argv) {
  CLI::App app{
      "rmslab rms_mission: plan the standard mission (acquire, extract, dock) for a "
      "configuration by inverse kinematics and write it as a timeline"};
  std::string config_path = rms::DefaultConfigPath(), out;
  app.add_option("--config", config_path, "Configuration file")->capture_default_str();
  app.add_option("--out", out, "Timeline file to write (default: standard output)");
  if (const auto rc = rms::ParseCommandLine(app, argc, argv)) return *rc;
  try {
    const rms::LabConfig config = rms::LoadConfig(config_path);
    const std::string text = rms::mission::FormatTimeline(rms::mission::PlanMission(config),
                                                          rms::mission::kMissionHeader);
    if (out.empty()) {
      std::cout << text;
    } else {
      rms::WriteWholeFile(out, text);
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "rms_mission: " << e.what() << "\n";
    return 2;
  }
}
