#pragma once
// A look at a live LCM address before a session starts there
// (docs/sessions.md "Sharing a network").
#include <nlohmann/json.hpp>
#include <string>

namespace rms::session {

// Every rmslab session heard on an LCM address within `seconds`:
// {"url", "seconds", "sessions": [{"session_id", "channels": {name: n},
// "senders": ["dynamics_proc pid N", ...]}]} -- the launcher's look before it
// starts a session there (docs/sessions.md "Sharing a network").
// Throws rms::TransportError when the address cannot be opened.
nlohmann::ordered_json ProbeAddress(const std::string& url, double seconds);

}  // namespace rms::session
