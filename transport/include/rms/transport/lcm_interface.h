#pragma once
// The LCM transport behind a small interface (after Drake's
// lcm/drake_lcm_interface.h and drake_lcm_log.h): processes publish and
// subscribe through LcmInterface; UdpLcm is real LCM (UDP multicast), LogLcm
// replays / records an LCM log file deterministically, without a network.
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rms/wire/message_auth.h"
#include "rms/wire/message_io.h"

namespace lcm {
class LCM;
class LogFile;
}  // namespace lcm

namespace rms::transport {

class Journal;

// Default URL: UDP multicast on this host only (TTL 0). docs/protocol.md "Transport".
inline constexpr const char* kDefaultLcmUrl = "udpm://239.255.76.67:7667?ttl=0";

struct LcmOptions {
  std::string url = kDefaultLcmUrl;
  // Appended to every channel name, e.g. "_BAY2". Letters, digits, '_' only.
  std::string channel_suffix;
  // Per-subscription receive queue (LCM's default of 30 drops silently).
  int queue_capacity = 1000;
};

// Throws rms::InputError when the suffix has characters other than [A-Za-z0-9_].
void ValidateChannelSuffix(std::string_view suffix);

// Who this process is on the wire: stamped into every message it publishes
// (the sender_t first field, lcmtypes/sender_t.lcm; docs/protocol.md
// "Senders"). session_id 0: no session (a process started by hand).
struct Sender {
  std::int64_t session_id = 0;
  std::int8_t process = 0;  // sender_t::PROCESS_*
  std::int32_t pid = 0;
};

// A session id from text: decimal, or hexadecimal with 0x (as the manifest
// writes it). Throws InputError naming `what` otherwise.
std::int64_t ParseSessionId(const std::string& text, const std::string& what);

// The session id the launcher gave this process in RMSLAB_SESSION_ID, or 0.
// A malformed value is an InputError naming the variable.
std::int64_t SessionIdFromEnv();

// Raised when the transport cannot be opened; the message says how to fix it.
class TransportError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class LcmInterface {
 public:
  // data/size: the raw message; recv_time_us: when it arrived (wall clock for
  // UDP, the log's timestamp for a log).
  using Handler = std::function<void(const void* data, int size, std::int64_t recv_time_us)>;

  virtual ~LcmInterface();
  LcmInterface(const LcmInterface&) = delete;
  LcmInterface& operator=(const LcmInterface&) = delete;

  // Publishes on channel + suffix. Returns false when the transport refused.
  virtual bool Publish(std::string_view channel, const void* data, int size) = 0;
  // Subscribes to exactly channel + suffix.
  virtual void Subscribe(std::string_view channel, Handler handler) = 0;
  // Waits up to timeout_ms (0: don't wait) and dispatches what arrived; returns
  // the number of messages dispatched (0 on timeout or end of log), <0 on error.
  virtual int HandleSubscriptions(int timeout_ms) = 0;
  // Time as this transport sees it, microseconds since 1970.
  virtual std::int64_t NowUs() const = 0;

  const std::string& channel_suffix() const { return suffix_; }
  std::string FullChannel(std::string_view channel) const { return std::string(channel) + suffix_; }

  // This process on the wire (PublishMessage stamps it into every message).
  // With a session id other than 0, every rmslab message of another session
  // (or of none) is dropped before it reaches a handler, and counted; the
  // first from each other session is logged with what sent it.
  void SetSender(const Sender& sender) { sender_ = sender; }
  const Sender& sender() const { return sender_; }
  // Messages of other sessions dropped so far ("dropped.other_session").
  std::int64_t other_session_dropped() const { return other_session_dropped_; }
  // Messages on a one-publisher channel from a pid other than its
  // publisher's while that one was still sending ("dropped.other_sender";
  // docs/security.md "Sessions know each other").
  std::int64_t other_sender_dropped() const { return other_sender_dropped_; }

  // The session's secret key (docs/security.md "Authenticated messages"):
  // from then on every message published ends in its tag
  // (wire::MessageMac), and every rmslab message received must end in a
  // good one: one that does not is dropped before any handler sees it, and
  // counted (dropped.bad_mac). Handlers get the message without its tag.
  // On RMS_CONTROL a tagged message already taken, or sent more than
  // kControlFreshUs from now, or sent before this process began (a restart
  // has not seen the tags its predecessor took), is a replay of a real one:
  // dropped.replayed.
  void SetKey(const wire::SessionKey& key) { key_ = key; }
  bool authenticates() const { return key_.has_value(); }
  std::int64_t bad_mac_dropped() const { return bad_mac_dropped_; }
  std::int64_t replayed_dropped() const { return replayed_dropped_; }
  static constexpr std::int64_t kControlFreshUs = 30'000'000;

  // What this process publishes goes to its journal too, before the wire
  // (rms/transport/journal.h; docs/sessions.md "The record"). UdpLcm only: a
  // log-backed transport writes its own log.
  void SetJournal(std::unique_ptr<Journal> journal);
  const Journal* journal() const { return journal_.get(); }

  // A one-publisher channel takes another publisher (a restarted process's
  // new pid) only after the current one has been silent this long.
  static constexpr std::int64_t kPublisherSilenceUs = 100000;

 protected:
  // started_us: when this process's transport began (wall clock; 0: a log's,
  // which takes any command's time).
  explicit LcmInterface(std::string suffix, std::int64_t started_us = 0);
  // The session filter every transport applies before dispatching: true
  // to hand the message on, *size then the message's own (its tag, when
  // the session authenticates, left off).
  bool Admit(const std::string& channel, const void* data, int* size);
  // A message about to be published with its tag appended (the session's
  // key set; else the message itself): its bytes, valid until the next
  // call, and *size updated.
  const void* Seal(const std::string& full_channel, const void* data, int* size);
  // A message about to be published, into the journal when there is one
  // (a failure is the journal's to count).
  void Journalize(const std::string& full_channel, const void* data, int size);

 private:
  bool AdmitPublisher(const std::string& channel, const void* data, int size);
  bool Authentic(const std::string& channel, const void* data, int* size);
  bool FreshControl(const void* data, int size);
  std::unique_ptr<Journal> journal_;
  std::optional<wire::SessionKey> key_;
  std::vector<std::uint8_t> sealed_;
  std::int64_t bad_mac_dropped_ = 0, replayed_dropped_ = 0;
  bool bad_mac_warned_ = false;
  // The tags of the control messages taken within kControlFreshUs, oldest first.
  std::deque<std::pair<std::int64_t, std::array<std::uint8_t, wire::kMacBytes>>> control_seen_;
  struct Publisher {
    std::int8_t process = 0;
    std::int32_t pid = 0;
    std::int64_t last_us = 0;  // when it was last heard (0: never)
    bool warned = false;
  };

  std::string suffix_;
  std::int64_t started_us_ = 0;
  Sender sender_;
  std::int64_t other_session_dropped_ = 0;
  std::int64_t other_sender_dropped_ = 0;
  std::map<std::int64_t, std::int64_t> other_sessions_;  // id -> messages dropped
  std::map<std::string, Publisher> publishers_;          // full channel -> its current publisher
};

// Real LCM. Throws TransportError when LCM is not good() (no multicast route,
// bad URL), with the fix in the message.
class UdpLcm final : public LcmInterface {
 public:
  explicit UdpLcm(const LcmOptions& options);
  ~UdpLcm() override;
  bool Publish(std::string_view channel, const void* data, int size) override;
  void Subscribe(std::string_view channel, Handler handler) override;
  int HandleSubscriptions(int timeout_ms) override;
  std::int64_t NowUs() const override;
  const std::string& url() const { return url_; }

 private:
  struct Sub;
  std::string url_;
  int queue_capacity_;
  std::unique_ptr<lcm::LCM> lcm_;
  std::vector<std::unique_ptr<Sub>> subs_;
};

// Log-backed LCM. Reads events from an input log (optional) in order and
// dispatches them to subscribers, one event per HandleSubscriptions call;
// NowUs() is the last event's timestamp. Published messages are delivered to
// local subscribers (like multicast loopback) and appended to the output log
// (optional) with the current log time. No network, no wall clock: runs are
// deterministic.
class LogLcm final : public LcmInterface {
 public:
  LogLcm(const std::string& input_path, const std::string& output_path,
         std::string channel_suffix = "");
  ~LogLcm() override;
  bool Publish(std::string_view channel, const void* data, int size) override;
  void Subscribe(std::string_view channel, Handler handler) override;
  int HandleSubscriptions(int timeout_ms) override;
  std::int64_t NowUs() const override { return now_us_; }
  // Sets the time used for publishing when there is no input log.
  void SetNowUs(std::int64_t t) { now_us_ = t; }
  bool at_end() const { return input_done_ && pending_count_ == 0; }
  // The output log on the disk, every event of it: false (with the reason in
  // *why) when an event could not be written, or the rest cannot be flushed
  // (a full disk). Nothing is lost in silence: its writer says so.
  bool FinishOutput(std::string* why);

 private:
  struct Pending {
    std::string channel;
    std::vector<std::uint8_t> data;
  };
  void Dispatch(const std::string& channel, const void* data, int size);
  std::unique_ptr<lcm::LogFile> in_;
  std::unique_ptr<lcm::LogFile> out_;
  bool input_done_ = true;
  std::int64_t now_us_ = 0;
  std::vector<std::pair<std::string, Handler>> handlers_;
  // Published and not yet dispatched: the first pending_count_ of pending_.
  // The two lists take turns (the one being dispatched, the one filling) and
  // keep their storage, so a frame's messages allocate nothing.
  std::vector<Pending> pending_, dispatching_;
  std::size_t pending_count_ = 0;
  bool dispatching_now_ = false;
  std::int64_t write_failures_ = 0;
  int write_errno_ = 0;
};

// Wall clock, microseconds since 1970 (CLOCK_REALTIME): the send_time_us of
// every message.
std::int64_t WallTimeUs();

// Publishes msg with this process's sender stamped in (LcmInterface::sender).
// False, and nothing sent, when the transport refused it or the message is
// beyond its type's bounds (rms/lcm_limits.h: every receiver would drop it).
template <class Msg>
bool PublishMessage(LcmInterface& lcm, std::string_view channel, const Msg& msg) {
  if (!lcm_limits::Bounds<Msg>::Within(msg)) return false;
  Msg stamped = msg;
  stamped.sender.session_id = lcm.sender().session_id;
  stamped.sender.process = lcm.sender().process;
  stamped.sender.pid = lcm.sender().pid;
  const std::vector<std::uint8_t> buf = wire::EncodeMessage(stamped);
  if (buf.empty()) return false;
  return lcm.Publish(channel, buf.data(), static_cast<int>(buf.size()));
}

}  // namespace rms::transport
