#pragma once
// Re-simulation's comparisons (docs/sessions.md "Re-simulation"): a DCP
// frame and its telemetry word for word against the recorded ones, and two
// configuration files key by key.
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_telemetry_t.hpp"

namespace rms::resim {

// True when a and b carry the same words; else false, with the first field
// that differs in *what ("arm_words[3]").
bool SameFrame(const dcp_frame_t& a, const dcp_frame_t& b, std::string* what);
// True when every field but the wall-clock send time and the sender agrees.
bool SameTelemetry(dcp_telemetry_t a, dcp_telemetry_t b, std::string* what);
// Every key of a configuration (TOML text) as "a.b.c" -> its value's text;
// nullopt when it cannot be parsed.
using ConfigKeys = std::map<std::string, std::string>;
std::optional<ConfigKeys> FlattenConfig(const std::string& toml_text);
// Every key whose value differs between two configurations:
// [{"key", "recorded", "now"}]; empty when either cannot be parsed.
nlohmann::ordered_json ConfigChanges(const std::optional<ConfigKeys>& recorded,
                                     const std::string& now_toml);

}  // namespace rms::resim
