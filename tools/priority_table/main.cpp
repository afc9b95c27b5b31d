// rms_priority_table: prints the priority table (docs/priority-table.md).
#include <CLI/CLI.hpp>
#include <cstdio>

#include "rms/base/command_line.h"
#include "rms/sim/priority_table.h"

int main(int argc, char** argv) {
  CLI::App app{
      "rmslab rms_priority_table: the visual-priority table (every cluster pair's plane source, "
      "bit "
      "and fixed plane) as Markdown on stdout"};
  std::string config_path = rms::DefaultConfigPath();
  std::string timeline = std::string(RMSLAB_SOURCE_DIR) + "/scripts/timelines/mission.tl";
  app.add_option("--config", config_path, "Configuration file")->capture_default_str();
  app.add_option("--timeline", timeline, "Timeline whose first frame places the planes")
      ->capture_default_str();
  if (const auto rc = rms::ParseCommandLine(app, argc, argv)) return *rc;
  try {
    std::fputs(rms::sim::PriorityTableMarkdown(rms::LoadConfig(config_path), timeline).c_str(),
               stdout);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rms_priority_table: %s\n", e.what());
    return 2;
  }
}
