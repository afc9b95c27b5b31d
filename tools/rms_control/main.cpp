// rms_control: commands to a running session on RMS_CONTROL
// (docs/sessions.md "Freeze, run, step, checkpoint"):
//   rms_control freeze | run | step [N] | checkpoint FILE | restore FILE [--run]
// restore freezes the session first (so no frame is in flight), restores
// the DCP's state and the operator station's inputs, and leaves the session
// frozen unless --run.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

#include "rms/channels.h"
#include "rms/lcm_interface.h"
#include "rms/message_io.h"
#include "rms/session_control_t.hpp"

int main(int argc, char** argv) {
  CLI::App app{"rmslab rms_control: freeze, run, step, checkpoint or restore a running session (RMS_CONTROL)"};
  rms::LcmOptions lcm_options;
  app.add_option("--lcm-url", lcm_options.url, "LCM URL of the session")->capture_default_str();
  app.add_option("--channel-suffix", lcm_options.channel_suffix, "The session's channel suffix");
  app.require_subcommand(1);
  int steps = 1;
  std::string path;
  bool then_run = false;
  auto* freeze = app.add_subcommand("freeze", "Freeze the session: every process holds its frame");
  auto* run = app.add_subcommand("run", "Run a frozen session again");
  auto* step = app.add_subcommand("step", "While frozen: N more frames (default 1)");
  step->add_option("n", steps, "Frames")->check(CLI::Range(1, 100000));
  auto* checkpoint = app.add_subcommand("checkpoint", "dynamics_proc saves its state to FILE");
  checkpoint->add_option("file", path, "Checkpoint file")->required();
  auto* restore = app.add_subcommand("restore", "Freeze, then restore the DCP's state (and the operator's inputs) from FILE");
  restore->add_option("file", path, "Checkpoint file")->required()->check(CLI::ExistingFile);
  restore->add_flag("--run", then_run, "Run again after restoring");
  CLI11_PARSE(app, argc, argv);
  try {
    rms::UdpLcm lcm(lcm_options);
    std::int64_t sequence = 0;
    auto send = [&](std::int8_t command, const std::string& p = "") {
      rms::session_control_t m;
      m.send_time_us = lcm.NowUs();
      m.sequence = sequence++;
      m.command = command;
      m.path = p;
      if (!rms::PublishMessage(lcm, rms::channels::kControl, m)) throw std::runtime_error("cannot publish");
    };
    auto pause = [] { std::this_thread::sleep_for(std::chrono::milliseconds(300)); };
    if (!path.empty()) path = std::filesystem::absolute(path).lexically_normal().string();
    if (freeze->parsed()) send(rms::session_control_t::FREEZE);
    if (run->parsed()) send(rms::session_control_t::RUN);
    if (step->parsed()) {
      for (int i = 0; i < steps; ++i) send(rms::session_control_t::STEP);
    }
    if (checkpoint->parsed()) send(rms::session_control_t::CHECKPOINT, path);
    if (restore->parsed()) {
      send(rms::session_control_t::FREEZE);
      pause();  // the last frames through the pipeline
      send(rms::session_control_t::RESTORE, path);
      if (then_run) {
        pause();
        send(rms::session_control_t::RUN);
      }
    }
    std::printf("sent to %s%s\n", lcm_options.url.c_str(),
                lcm_options.channel_suffix.empty() ? "" : (" (suffix " + lcm_options.channel_suffix + ")").c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rms_control: %s\n", e.what());
    return 2;
  }
}
