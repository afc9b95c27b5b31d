#pragma once
// Configuration keys set on a command line, over a configuration file
// (docs/sessions.md "Sweeps"): `--set dcp.tpob_ft=0.4`, as a re-simulation
// of another design or a sweep's cell takes them. A setting names a key the
// file has (a dotted path through its tables; `cameras[2].fov_deg` into an
// array of tables) and gives a TOML value of the key's kind (a number for a
// number, an array for an array, a string for a string).
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "rms/base/config.h"

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

// A configuration's text parsed once, for many designs (a sweep's batch of
// cells): With(settings, name) is ParseConfig(ApplyConfigSettings(text,
// source, settings), name) -- the same LabConfig, as TOML prints every
// number so that it reads back exact, and the same errors -- without parsing
// and printing the text again for each.
class ConfigDesigns {
 public:
  // Throws rms::InputError for text that is no TOML (naming source).
  ConfigDesigns(std::string_view toml_text, std::string source);
  ~ConfigDesigns();
  ConfigDesigns(const ConfigDesigns&) = delete;
  ConfigDesigns& operator=(const ConfigDesigns&) = delete;
  LabConfig With(const std::vector<ConfigSetting>& settings, const std::string& name) const;

 private:
  struct Parsed;
  std::unique_ptr<const Parsed> parsed_;
};

}  // namespace rms
