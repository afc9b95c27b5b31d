// dynamics_proc: the Dynamic Collision Program. RMS_OPERATOR_INPUT in,
// RMS_DCP_FRAME out. A thin main over dynamics_proc/src; see docs/.
#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "dcp_node.h"
#include "rms/config.h"
#include "rms/process.h"

int main(int argc, char** argv) {
  CLI::App app{"rmslab dynamics_proc: the Dynamic Collision Program. Reads the operator's input "
               "block (RMS_OPERATOR_INPUT), computes the arm words, kinematics and control word, "
               "and publishes RMS_DCP_FRAME once per input block."};
  rms::CommonOptions common;
  rms::AddCommonOptions(app, &common);
  CLI11_PARSE(app, argc, argv);

  rms::SetUpLogging("dynamics_proc", common.log_level);
  rms::InstallStopHandlers();
  try {
    const rms::LabConfig config = rms::LoadConfig(common.config_path);
    rms::UdpLcm lcm(common.lcm);
    return rms::dcp::RunDynamicsProc(config, lcm, common.stats_path, common.ready_path);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 2;
  }
}
