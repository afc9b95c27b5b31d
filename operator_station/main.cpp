// operator_station: the operator's inputs (Table I) onto RMS_OPERATOR_INPUT.
// A thin main over operator_station/src; see docs/operator.md.
#include <CLI/CLI.hpp>

#include "operator_station.h"
#include "rms/process.h"

int main(int argc, char** argv) {
  CLI::App app{"rmslab operator station: publishes the operator's input block (Table I) on "
               "RMS_OPERATOR_INPUT at the frame rate, from a timeline file or the keyboard."};
  rms::CommonOptions common;
  rms::op::OperatorOptions opt;
  app.add_option("--timeline", opt.timeline_path, "Timeline file (docs/timeline.md)")
      ->check(CLI::ExistingFile);
  app.add_flag("--keyboard", opt.keyboard, "Fly from this terminal's keyboard");
  app.add_option("--rate", opt.rate_hz, "Frame rate, Hz (default: config session.frame_rate_hz)")
      ->check(CLI::Range(1.0, 1000.0));
  app.add_flag("--hold", opt.hold, "Keep publishing the timeline's last inputs after it ends");
  app.add_option("--speed", opt.speed, "Play the timeline this many times faster than real time")
      ->capture_default_str()
      ->check(CLI::Range(0.01, 100.0));
  app.add_option("--frames", opt.max_frames, "Stop after this many frames");
  return rms::ProcessMain(app, argc, argv, "operator_station", &common,
                          [&](const rms::LabConfig& config, rms::LcmInterface& lcm) {
                            return rms::op::RunOperatorStation(opt, config, lcm, common.stats_path,
                                                               common.ready_path);
                          });
}
