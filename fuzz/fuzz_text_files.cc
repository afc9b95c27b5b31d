// The text files a user or a lab hands the processes: the configuration
// (ParseConfig), the timeline (Timeline::Parse), the lab file
// (ParseLabFile) and a checkpoint (ParseCheckpoint, then the DCP's
// RestoreState). The first byte picks which. Each must accept the text or
// refuse it with rms::InputError; anything else escaping is a finding.
#include <string_view>

#include "rms/base/check.h"
#include "rms/dcp_model/dynamic_collision_program.h"
#include "rms/operator_station/timeline.h"
#include "rms/session/lab_file.h"
#include "rms/wire/checkpoint.h"

#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const rms::LabConfig& config = rms::fuzz::Config();
  if (size < 1) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  try {
    switch (data[0] % 4) {
      case 0:
        (void)rms::ParseConfig(text, "fuzz.toml");
        break;
      case 1:
        (void)rms::operator_station::Timeline::Parse(text, "fuzz.tl", config.inputs);
        break;
      case 2:
        (void)rms::session::ParseLabFile(text, "fuzz-lab.toml");
        break;
      default: {
        const rms::wire::Checkpoint c = rms::wire::ParseCheckpoint(text, "fuzz.json");
        rms::dcp_model::DynamicCollisionProgram dcp(config);
        dcp.RestoreState(c.dcp);
        dcp.Step(c.inputs);
        break;
      }
    }
  } catch (const rms::InputError&) {
    // Refused with a message: the expected outcome for bad text.
  }
  return 0;
}
