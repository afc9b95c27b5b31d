#pragma once
// Configuration keys set on a command line, over a configuration file
// (docs/sessions.md "Sweeps"): `--set dcp.tpob_ft=0.4`, as a re-simulation
// of another design or a sweep's cell takes them. A setting names a key the
// file has (a dotted path through its tables; `cameras[2].fov_deg` into an
// array of tables) and gives a TOML value of the key's kind (a number for a
// number, an array for an array, a string for a string).
#include <string>
#include <string_view>
#include <vector>

namespace rms {

struct ConfigSetting {
  std::string key;    // "dcp.tpob_ft"
  std::string value;  // its TOML value as text: "0.4", "[1.5, -8.5, 0.0]", "\"wrist\""
};

// "KEY=VALUE" -> {KEY, VALUE}. Throws rms::InputError naming the text when
// it has no '=' or an empty key or value.
ConfigSetting ParseConfigSetting(const std::string& text);

// The configuration's TOML text with each setting applied in order, as TOML
// text (every value exact; the file's comments are not kept). Throws
// rms::InputError "--set KEY: reason" for a key the file does not have, a
// value that is no TOML value, or one of another kind than the key's. The
// result is not validated: ParseConfig does that.
std::string ApplyConfigSettings(std::string_view toml_text, const std::string& source,
                                const std::vector<ConfigSetting>& settings);

}  // namespace rms
