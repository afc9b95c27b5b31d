#pragma once
// Authenticated messages (docs/security.md "Authenticated messages",
// docs/protocol.md "Message authentication"): every message a session's
// process sends ends in a tag, a MAC over its channel and bytes under the
// session's secret key, appended after the LCM encoding (the message's type
// and fingerprint unchanged). Keyed BLAKE2b (libsodium's crypto_generichash)
// with a 32-byte key and a 16-byte tag.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace rms::wire {

inline constexpr int kSessionKeyBytes = 32;
inline constexpr int kMacBytes = 16;
// The manifest's `message_auth` for messages tagged this way.
inline constexpr const char* kMessageAuthName = "blake2b-128";

struct SessionKey {
  std::array<std::uint8_t, kSessionKeyBytes> bytes{};
};

// The tag of a message: over the full channel (with its suffix), a 0 byte,
// then the message's `size` bytes.
std::array<std::uint8_t, kMacBytes> MessageMac(const SessionKey& key, std::string_view channel,
                                               const void* data, int size);
// Whether the last kMacBytes of a tagged message (`size` with its tag) are
// its tag under `key`; compared in constant time. False when it is too short.
bool VerifyMessageMac(const SessionKey& key, std::string_view channel, const void* data, int size);

// A session's key file (`SESSION/run/session.key`, docs/sessions.md "The
// session folder"): 64 hex digits and a newline, a regular file owned by
// this user and readable by nobody else (mode 0600 or 0400), opened without
// following a link. Throws rms::InputError naming the file and what is wrong.
SessionKey ReadSessionKeyFile(const std::string& path);
// The key file the launcher names in RMSLAB_SESSION_KEY_FILE, read; none
// when the variable is unset or empty. Throws InputError as above.
std::optional<SessionKey> SessionKeyFromEnv();

}  // namespace rms::wire
