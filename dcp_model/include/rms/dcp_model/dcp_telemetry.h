#pragma once
// The DCP's telemetry message for a frame (docs/protocol.md
// "RMS_DCP_TELEMETRY"): what the process publishes and the offline
// sessions (sim) read, made from the program's status. The message type is
// lcm-gen's, header-only: building it needs no LCM library.
#include "rms/dcp_model/dynamic_collision_program.h"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/wire/word_blocks.h"

namespace rms::dcp_model {

dcp_telemetry_t MakeTelemetry(const DcpStatus& status, const wire::DcpFrameData& frame);

}  // namespace rms::dcp_model
