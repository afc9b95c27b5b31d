#pragma once
// Inside rms::base: ParseConfig's reading of a parsed TOML table, shared
// with ConfigDesigns (config_settings.cc), which sets keys on a table parsed
// once instead of parsing text again.
#include <string>
#include <toml++/toml.h>

#include "rms/base/config.h"

namespace rms::internal {

// ParseConfig(text, source) is ConfigFromTable(the text parsed, source).
LabConfig ConfigFromTable(toml::table* root, const std::string& source);

}  // namespace rms::internal
