#pragma once
// Re-simulation's comparisons (docs/sessions.md "Re-simulation"): a DCP
// frame and its telemetry word for word against the recorded ones, and two
// configuration files key by key.
#include <cstdint>
#include <cstring>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/lcm_limits.h"
#include "rms/wire/message_io.h"

namespace rms::resim {

// True when a and b carry the same words; else false, with the first field
// that differs in *what ("arm_words[3]").
bool SameFrame(const dcp_frame_t& a, const dcp_frame_t& b, std::string* what);
// True when two raw messages of a fixed-size type whose sender, frame and
// send time come first (RMS_DCP_FRAME, RMS_DCP_TELEMETRY: wire::kFrameAt),
// each found whole by wire::CheckEncoded, agree in every byte but the
// sender's and the send time's (a re-simulation is another process, at
// another time): every field of the two but those, compared undecoded.
template <class Msg>
bool SameButSenderAndTime(const std::uint8_t* a, const std::uint8_t* b) {
  static_assert(lcm_limits::Bounds<Msg>::kFixedSize);
  constexpr int kSize = lcm_limits::kMaxEncodedSize<Msg>, kRest = wire::kSendTimeAt + 8;
  // The fingerprint, [the sender], the frame, [the send time], the rest.
  return std::memcmp(a, b, 8) == 0 && std::memcmp(a + wire::kFrameAt, b + wire::kFrameAt, 8) == 0 &&
         std::memcmp(a + kRest, b + kRest, kSize - kRest) == 0;
}
// Every key of a configuration (TOML text) as "a.b.c" -> its value's text;
// nullopt when it cannot be parsed.
using ConfigKeys = std::map<std::string, std::string>;
std::optional<ConfigKeys> FlattenConfig(const std::string& toml_text);
// Every key whose value differs between two configurations:
// [{"key", "recorded", "now"}]; empty when either cannot be parsed.
nlohmann::ordered_json ConfigChanges(const std::optional<ConfigKeys>& recorded,
                                     const std::string& now_toml);

}  // namespace rms::resim
