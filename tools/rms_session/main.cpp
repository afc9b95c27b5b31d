// rms_session: tools over a lab session folder (docs/sessions.md).
//   rms_session summary SESSION   writes SESSION/summary.json
#include <CLI/CLI.hpp>
#include <fstream>
#include <iostream>

#include "session_summary.h"

int main(int argc, char** argv) {
  CLI::App app{"rmslab session tools"};
  app.require_subcommand(1);
  std::string dir;
  std::string out;
  CLI::App* summary = app.add_subcommand("summary", "Write SESSION/summary.json from the session's log and stats");
  summary->add_option("session", dir, "Session folder")->required()->check(CLI::ExistingDirectory);
  summary->add_option("--out", out, "Output file (default SESSION/summary.json)");
  bool brief = false;
  summary->add_flag("--brief", brief, "Print a few human-readable lines instead of the JSON");
  CLI11_PARSE(app, argc, argv);
  try {
    const auto j = rms::session::Summarize(dir);
    if (out.empty()) out = dir + "/summary.json";
    std::ofstream f(out);
    if (!f) throw std::runtime_error("cannot write " + out);
    f << j.dump(2) << "\n";
    if (!brief) {
      std::cout << j.dump(2) << "\n";
      return 0;
    }
    const auto& fr = j["frames"];
    std::int64_t dropped = 0;
    for (const auto& [k, v] : fr["dropped"].items()) dropped += v.get<std::int64_t>();
    std::cout << "frames: operator " << fr["operator_published"] << ", DCP " << fr["dcp_published"]
              << ", ESG " << fr["esg_published"] << ", rendered " << fr["rendered"] << ", PNG "
              << fr["png_written"] << "; dropped " << dropped << "\n";
    if (j["latency"].contains("input_to_render")) {
      const auto& l = j["latency"]["input_to_render"];
      std::cout << "operator input to rendered frame: median " << l["p50_ms"].get<double>()
                << " ms, p99 " << l["p99_ms"].get<double>() << " ms\n";
    }
    std::cout << "modes 1";
    for (const auto& mc : j["mode_changes"]) {
      std::cout << " -> " << mc["to"] << " (" << mc["time_s"].get<double>() << " s)";
    }
    std::cout << "; acquired " << (j["acquired"].get<bool>() ? "yes" : "no") << ", docked "
              << (j["docked"].get<bool>() ? "yes" : "no");
    if (!j["docking"].is_null()) {
      std::cout << " (" << j["docking"]["distance_ft"].get<double>() << " ft, "
                << j["docking"]["angle_deg"].get<double>() << " deg)";
    }
    std::cout << "\ncollisions " << j["collisions"].size() << ", frames held " << j["held_frames"]
              << "; LCM log events " << j["log"]["events"] << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "rms_session: " << e.what() << "\n";
    return 2;
  }
}
