#pragma once
// The one writer of session folders (docs/sessions.md "The session
// folder"): scripts/lab demo and replay (through `rms_session folder`) and
// the re-simulation make them here, so every session has the same layout.
#include <array>
#include <cstdint>
#include <string>

#include "rms/base/config.h"
#include "rms/base/folder_file.h"

namespace rms::session {

// The folders every session folder has.
inline constexpr std::array<const char*, 5> kSessionSubfolders = {"logs", "stats", "frames", "run",
                                                                  "checkpoints"};

// Creates DIR and its logs/, stats/, frames/, run/ and checkpoints/, and
// checks that it can write there. Returns DIR made absolute. Throws
// rms::InputError naming the folder and the reason: DIR already holds a
// session (an lcmlog), or it cannot be made or written.
std::string CreateSessionFolder(const std::string& dir);

// A session folder's files are untrusted input (docs/security.md "Session
// folders are untrusted"): each read by these only as a regular file, no
// link followed, no larger than its kind's limit; an InputError names the
// file and what is wrong with it.
//
// DIR/config.toml, parsed (rms::LoadConfig's errors, naming the file).
LabConfig LoadSessionConfig(const std::string& dir);
// The SHA-256 of DIR/NAME (a regular file, no link followed), 64 hex
// digits: what a resimulation.json judged (its log_sha256).
std::string SessionFileSha256(const std::string& dir, const std::string& name);
// DIR/NAME (e.g. "manifest.json", "run/pids") as text, at most max_bytes.
std::string ReadSessionFile(const std::string& dir, const std::string& name,
                            std::uint64_t max_bytes);

}  // namespace rms::session
