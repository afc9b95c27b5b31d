// dynamics_proc: the Dynamic Collision Program. RMS_OPERATOR_INPUT in,
// RMS_DCP_FRAME out. A thin main over dynamics_proc/src; see docs/.
#include <CLI/CLI.hpp>

#include "rms/dynamics_proc/dynamics_proc.h"
#include "rms/transport/process.h"
#include "rms/wire/checkpoint.h"

int main(int argc, char** argv) {
  CLI::App app{
      "rmslab dynamics_proc: the Dynamic Collision Program. Reads the operator's input "
      "block (RMS_OPERATOR_INPUT), computes the arm words, kinematics and control word, "
      "and publishes RMS_DCP_FRAME once per input block."};
  rms::transport::CommonOptions common;
  std::string restore;
  app.add_option("--restore", restore, "Start from this checkpoint (docs/sessions.md)")
      ->check(CLI::ExistingFile);
  std::string state_file;
  app.add_option(
      "--state-file", state_file,
      "Keep the DCP's state in this file and, when it exists at start, resume from it instead of "
      "Mode 1 (the launcher's restart after a fault; docs/sessions.md \"Faults\")");
  std::string checkpoint_dir;
  app.add_option(
      "--checkpoint-dir", checkpoint_dir,
      "The session's checkpoints folder: RMS_CONTROL's CHECKPOINT and RESTORE name files in it and "
      "nowhere else (none: they are refused; docs/security.md)");
  return rms::transport::ProcessMain(
      app, argc, argv, "dynamics_proc", &common,
      [&](const rms::LabConfig& config, rms::transport::LcmInterface& lcm) {
        return rms::dynamics_proc::RunDynamicsProc(
            config, lcm, common.stats_path, common.ready_path, restore, state_file, checkpoint_dir);
      },
      [&](const rms::LabConfig&) {
        if (!restore.empty()) (void)rms::wire::ReadCheckpoint(restore);
      });
}
