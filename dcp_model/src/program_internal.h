#pragma once
// Private to the DCP's model: what dynamic_collision_program.cc and
// dcp_state.cc (the state as JSON) share.
#include "rms/base/config.h"
#include "rms/dcp_model/dynamic_collision_program.h"
#include "rms/dcp_model/malfunctions.h"

namespace rms::dcp_model::internal {

// The malfunctions' frame rate and each joint's travel: the arm's joint
// limits within the input's range (config [arm], [inputs.*]).
Malfunctions MakeMalfunctions(const LabConfig& config);

// Every number of the command finite.
bool Finite(const ArmCommand& c);

}  // namespace rms::dcp_model::internal
