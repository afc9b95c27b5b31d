// scene_proc: the Visual Scene Program. RMS_DCP_FRAME in, RMS_ESG_FRAME out.
// A thin main over scene_proc/src; see docs/scene.md.
#include <CLI/CLI.hpp>

#include "rms/process.h"
#include "visual_scene.h"

int main(int argc, char** argv) {
  CLI::App app{"rmslab scene_proc: the Visual Scene Program. Turns each DCP frame "
               "(RMS_DCP_FRAME) into the selected camera's view and packs the ESG frame "
               "(RMS_ESG_FRAME, at most 64 twenty-four-bit words)."};
  rms::CommonOptions common;
  return rms::ProcessMain(app, argc, argv, "scene_proc", &common,
                          [&](const rms::LabConfig& config, rms::LcmInterface& lcm) {
                            return rms::scene::RunSceneProc(config, lcm, common.stats_path,
                                                            common.ready_path);
                          });
}
