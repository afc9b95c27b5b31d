#pragma once
// Checkpoint files (docs/sessions.md "Freeze, run, step, checkpoint"): the
// DCP's state at a frame and the operator inputs it had just processed, so a
// session can restart from that moment. Written by dynamics_proc; read by
// dynamics_proc (the state) and operator_station (the inputs, to carry on
// from where the arm is). JSON, doubles exact.
#include <algorithm>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <utility>

#include "rms/wire/input_block.h"

namespace rms::wire {

struct Checkpoint {
  std::int64_t dcp_frame = -1;    // the last DCP frame before the save
  std::int64_t input_frame = -1;  // the operator frame it answered
  std::int64_t saved_us = 0;      // wall clock at the save
  std::string config;             // the configuration file the session ran
  OperatorInputs inputs;          // the operator inputs of that frame
  nlohmann::json dcp;             // DynamicCollisionProgram::SaveState()
};

// The largest checkpoint read (a real one is about 10 KB): a bigger file, or
// one that is not a regular file (/dev/zero, a FIFO), is refused unread.
inline constexpr std::int64_t kMaxCheckpointBytes = std::int64_t{1} << 20;

// Throw rms::InputError naming the file and what is wrong.
void WriteCheckpoint(const std::string& path, const Checkpoint& c);
Checkpoint ReadCheckpoint(const std::string& path);
// The file's text (JSON, doubles exact), as written and as RMS_DCP_STATE
// carries it.
std::string CheckpointText(const Checkpoint& c);
// The same from the file's text (path names it in errors).
Checkpoint ParseCheckpoint(std::string_view text, const std::string& path);
// True when a checkpoint's text, as CheckpointText writes it, holds this
// DCP state: its last member, "dcp", is this state's text to the byte (the
// same text parses to the same state), the rest read as ParseCheckpoint
// reads it (which throws rms::InputError, path naming it, where
// ParseCheckpoint would for the whole). False says only that it does not
// read so: ParseCheckpoint and compare to know whether the states differ.
// (A re-simulation checks the DCP's logged states this way without parsing
// each state again: docs/sessions.md "Re-simulation".)
bool TextHoldsDcp(std::string_view text, const nlohmann::json& dcp, const std::string& path);

// The session's checkpoints folder (docs/security.md "The control channel"):
// RMS_CONTROL names a checkpoint, never a path, and the name is looked up
// here only. A name is 1..64 of [A-Za-z0-9_.-], not starting with '.', and
// ends in ".json". Writing never replaces a file (O_EXCL) and never follows
// a symbolic link (O_NOFOLLOW); reading takes only a regular file of at
// most kMaxCheckpointBytes. A folder of "" (none given) refuses everything.
// How often the checkpoint commands of RMS_CONTROL (CHECKPOINT, RESTORE) are
// taken: a burst of kBurst, then kPerSecond; the rest are refused and
// counted ("control.rate_limited"). Freeze, run and step are not limited.
class CheckpointRateLimit {
 public:
  static constexpr double kPerSecond = 2.0, kBurst = 4.0;
  bool Allow(std::int64_t now_us) {
    tokens_ = std::min(kBurst, tokens_ + (now_us - last_us_) * 1e-6 * kPerSecond);
    last_us_ = now_us;
    if (tokens_ < 1.0) return false;
    tokens_ -= 1.0;
    return true;
  }

 private:
  double tokens_ = kBurst;
  std::int64_t last_us_ = 0;
};

class CheckpointFolder {
 public:
  explicit CheckpointFolder(std::string dir = "") : dir_(std::move(dir)) {}
  const std::string& dir() const { return dir_; }
  // Throws InputError saying what a name may be.
  static void ValidateName(const std::string& name);
  void Write(const std::string& name, const Checkpoint& c) const;
  Checkpoint Read(const std::string& name) const;
  std::string PathOf(const std::string& name) const { return dir_ + "/" + name; }

 private:
  int OpenDir() const;  // the folder itself, not through a link
  std::string dir_;
};

}  // namespace rms::wire
