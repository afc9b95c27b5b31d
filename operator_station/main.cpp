// operator_station: the operator's inputs (Table I) onto RMS_OPERATOR_INPUT.
// A thin main over operator_station/src; see docs/operator.md.
#include <CLI/CLI.hpp>

#include "rms/operator_station/operator_station.h"
#include "rms/transport/process.h"

int main(int argc, char** argv) {
  CLI::App app{
      "rmslab operator station: publishes the operator's input block (Table I) on "
      "RMS_OPERATOR_INPUT at the frame rate, from a timeline file, the operator's hand controllers "
      "(keyboard, live window, gamepad, 3D mouse) or the autopilot, with a live status screen."};
  rms::transport::CommonOptions common;
  rms::operator_station::OperatorOptions opt;
  app.add_option("--timeline", opt.timeline_path, "Fly a timeline file (docs/timeline.md)")
      ->check(CLI::ExistingFile);
  app.add_flag("--keyboard", opt.keyboard,
               "Fly by hand from this terminal's keyboard (and any gamepad or 3D mouse)");
  app.add_flag("--manual", opt.manual,
               "Fly by hand with whatever devices are found (keyboard, gamepad, 3D mouse)");
  app.add_flag("--autopilot", opt.autopilot,
               "Let the autopilot fly the whole task: acquire, extract, dock");
  app.add_flag(
      "--autopilot-straight", opt.autopilot_straight,
      "With --autopilot: no path planning; fly straight and relieve collisions as they come");
  app.add_option("--bindings", opt.bindings_path,
                 "Device bindings file (default: config/bindings.toml)")
      ->check(CLI::ExistingFile);
  bool no_gamepad = false, no_spacemouse = false, status_on = false, status_off = false;
  app.add_flag("--no-gamepad", no_gamepad, "Don't look for a gamepad or joystick");
  app.add_flag("--no-spacemouse", no_spacemouse, "Don't look for a 3D mouse");
  app.add_flag(
      "--window-keys", opt.window_keys,
      "By hand: fly from the live window's keys too (esg_renderer --window; RMS_WINDOW_KEYS)");
  app.add_flag("--status", status_on,
               "Show the live status screen (default: on when flying by hand in a terminal)");
  app.add_flag("--no-status", status_off, "No status screen");
  app.add_option("--rate", opt.rate_hz, "Frame rate, Hz (default: config session.frame_rate_hz)")
      ->check(CLI::Range(1.0, 1000.0));
  app.add_flag("--hold", opt.hold,
               "Keep publishing after the timeline's end or docking, until stopped");
  app.add_option("--speed", opt.speed, "Play the timeline this many times faster than real time")
      ->capture_default_str()
      ->check(CLI::Range(0.01, 100.0));
  app.add_option("--frames", opt.max_frames, "Stop after this many frames");
  app.add_option("--lesson", opt.lesson_path,
                 "Scripted events: malfunctions, repairs, freezes at a session time, on entering a "
                 "mode or on a condition (docs/lessons.md)")
      ->check(CLI::ExistingFile);
  app.add_option("--end-when-docked", opt.end_when_docked_s,
                 "By hand: stop this many seconds of session time after the payload docks (a "
                 "study's trial; docs/studies.md)")
      ->check(CLI::Range(0.0, 600.0));
  app.add_option("--restore", opt.restore_path,
                 "Start from a checkpoint's operator inputs (with dynamics_proc --restore; "
                 "docs/sessions.md)")
      ->check(CLI::ExistingFile);
  app.add_option("--dcp-state-file", opt.dcp_state_path,
                 "The DCP's state file (dynamics_proc --state-file): restarted, send the inputs it "
                 "holds until the DCP's first telemetry (docs/sessions.md \"Faults\")");
  app.add_option(
      "--checkpoint-dir", opt.checkpoint_dir,
      "The session's checkpoints folder: RMS_CONTROL's RESTORE names a file in it and nowhere else "
      "(docs/security.md)");
  return rms::transport::ProcessMain(
      app, argc, argv, "operator_station", &common,
      [&](const rms::LabConfig& config, rms::transport::LcmInterface& lcm) {
        opt.gamepad = !no_gamepad;
        opt.spacemouse = !no_spacemouse;
        opt.status = status_on ? 1 : status_off ? 0 : -1;
        rms::operator_station::OperatorStation station(
            opt, config, lcm, rms::operator_station::MakeSource(opt, config));
        return station.Run(common.stats_path, common.ready_path);
      },
      [&](const rms::LabConfig& config) { rms::operator_station::CheckSourceFiles(opt, config); });
}
