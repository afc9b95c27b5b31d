// scene_proc: the Visual Scene Program. RMS_DCP_FRAME in, RMS_ESG_FRAME out.
// A thin main over scene_proc/src; see docs/scene.md.
#include <CLI/CLI.hpp>

#include "rms/scene_proc/scene_proc.h"
#include "rms/transport/process.h"

int main(int argc, char** argv) {
  CLI::App app{
      "rmslab scene_proc: the Visual Scene Program. Turns each DCP frame "
      "(RMS_DCP_FRAME) into the selected camera's view and packs the ESG frame "
      "(RMS_ESG_FRAME, at most 64 twenty-four-bit words)."};
  rms::transport::CommonOptions common;
  bool every_frame = false;
  app.add_flag("--every-frame", every_frame,
               "answer every DCP frame however late it comes (a replay: nothing there is real "
               "time, so a stall slows it and loses nothing; docs/sessions.md \"Replay\")");
  return rms::transport::ProcessMain(
      app, argc, argv, "scene_proc", &common,
      [&](const rms::LabConfig& config, rms::transport::LcmInterface& lcm) {
        return rms::scene_proc::RunSceneProc(config, lcm, common.stats_path, common.ready_path,
                                             every_frame);
      });
}
