#pragma once
// A running session's traffic, per channel: messages, rates, gaps,
// malformed ones, the latest decoded in a line; and each process's last
// status (docs/sessions.md "Monitor"; lcm-spy does not run on Java 17).
#include <cstdint>
#include <map>
#include <string>

#include "rms/transport/lcm_interface.h"
#include "rms/wire/frame_numbers.h"

namespace rms::monitor {

struct ChannelStats {
  std::int64_t messages = 0, malformed = 0, bytes = 0;
  std::int64_t tagged_unchecked = 0;  // a session's, shown without checking its tag (no --session)
  wire::SequenceTracker frames;
  bool numbered = false;
  std::int64_t window_start_us = 0, window_count = 0;
  double hz = 0.0;
  std::string last;  // the latest message, decoded, one line
  void Tick(std::int64_t now_us, int size);
};

class Monitor {
 public:
  // Subscribes to every channel of the session on `lcm`.
  Monitor(transport::LcmInterface* lcm, transport::LcmOptions options);
  // Listens: `for_s` seconds and returns one snapshot; 0: redraws the
  // terminal twice a second until SIGINT / SIGTERM, then the snapshot.
  std::string Run(double for_s);
  // The table as it stands.
  std::string Render() const;

 private:
  template <class Decode>
  void On(const char* channel, Decode decode);
  bool Status(const void* d, int n, ChannelStats* c);
  transport::LcmInterface* lcm_;
  transport::LcmOptions options_;
  std::map<std::string, ChannelStats> channels_;
  static constexpr std::size_t kMaxProcesses = 64;
  std::map<std::string, std::string> processes_;  // name -> its last status line
};

}  // namespace rms::monitor
