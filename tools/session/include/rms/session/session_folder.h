#pragma once
// The one writer of session folders (docs/sessions.md "The session
// folder"): scripts/lab demo and replay (through `rms_session folder`) and
// the re-simulation make them here, so every session has the same layout.
#include <array>
#include <string>

namespace rms::session {

// The folders every session folder has.
inline constexpr std::array<const char*, 5> kSessionSubfolders = {"logs", "stats", "frames", "run",
                                                                  "checkpoints"};

// Creates DIR and its logs/, stats/, frames/, run/ and checkpoints/, and
// checks that it can write there. Returns DIR made absolute. Throws
// rms::InputError naming the folder and the reason: DIR already holds a
// session (an lcmlog), or it cannot be made or written.
std::string CreateSessionFolder(const std::string& dir);

}  // namespace rms::session
