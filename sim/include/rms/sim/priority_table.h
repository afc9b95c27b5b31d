#pragma once
// The priority table of docs/priority-table.md, generated from the scene
// model and the Visual Scene Program's planner (so the document cannot drift
// from the code: a unit test compares the shipped file with this output).
//   build/tools/rms_priority_table > docs/priority-table.md
#include <string>

#include "rms/base/config.h"

namespace rms::sim {

// The table for a configuration; `timeline` gives the first frame, whose
// poses place the fixed and rigid planes (the same for any pose).
std::string PriorityTableMarkdown(const LabConfig& config, const std::string& timeline);

}  // namespace rms::sim
