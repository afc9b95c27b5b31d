#include "rms/transport/lcm_interface.h"

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <lcm/lcm-cpp.hpp>
#include <spdlog/spdlog.h>

#include "rms/base/check.h"
#include "rms/transport/journal.h"
#include "rms/wire/channels.h"
#include "rms/wire/message_io.h"

namespace rms::transport {

std::int64_t WallTimeUs() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

void ValidateChannelSuffix(std::string_view suffix) {
  for (char ch : suffix) {
    const bool ok = (ch >= 'A' && ch <= 'Z') || (ch >= 'a' && ch <= 'z') ||
                    (ch >= '0' && ch <= '9') || ch == '_';
    if (!ok) {
      throw InputError("channel suffix '" + std::string(suffix) +
                       "' may hold only letters, digits and '_'");
    }
  }
}

LcmInterface::LcmInterface(std::string suffix, std::int64_t started_us)
    : suffix_(std::move(suffix)), started_us_(started_us) {
  ValidateChannelSuffix(suffix_);
}

LcmInterface::~LcmInterface() = default;

void LcmInterface::SetJournal(std::unique_ptr<Journal> journal) { journal_ = std::move(journal); }

void LcmInterface::Journalize(const std::string& full_channel, const void* data, int size) {
  if (journal_) journal_->Append(full_channel, data, size, WallTimeUs());
}

std::int64_t ParseSessionId(const std::string& text, const std::string& what) {
  const bool hex = text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X');
  const std::string digits = hex ? text.substr(2) : text;
  bool ok = !digits.empty() && digits.size() <= (hex ? 16u : 19u);
  for (char c : digits)
    ok = ok && (hex ? std::isxdigit(static_cast<unsigned char>(c))
                    : std::isdigit(static_cast<unsigned char>(c)));
  if (!ok)
    throw InputError(what + "='" + text +
                     "': not a session id (decimal, or 0x and up to 16 hex digits)");
  return static_cast<std::int64_t>(std::strtoull(digits.c_str(), nullptr, hex ? 16 : 10));
}

std::int64_t SessionIdFromEnv() {
  const char* v = std::getenv("RMSLAB_SESSION_ID");
  if (!v || !*v) return 0;
  return ParseSessionId(v, "RMSLAB_SESSION_ID");
}

const void* LcmInterface::Seal(const std::string& full_channel, const void* data, int* size) {
  if (!key_) return data;
  const auto tag = wire::MessageMac(*key_, full_channel, data, *size);
  const auto* b = static_cast<const std::uint8_t*>(data);
  sealed_.assign(b, b + *size);
  sealed_.insert(sealed_.end(), tag.begin(), tag.end());
  *size = static_cast<int>(sealed_.size());
  return sealed_.data();
}

// A message of the session's (docs/security.md "Authenticated messages"):
// its tag good, and *size then the message's own.
bool LcmInterface::Authentic(const std::string& channel, const void* data, int* size) {
  if (!wire::VerifyMessageMac(*key_, channel, data, *size)) {
    ++bad_mac_dropped_;
    if (!bad_mac_warned_) {
      bad_mac_warned_ = true;
      std::int8_t process = 0;
      std::int32_t pid = 0;
      wire::ReadSenderProcess(data, *size, &process, &pid);
      spdlog::warn(
          "{}: a message with this session's id (claiming {} pid {}) whose tag is not the "
          "session key's -- dropped, as every one like it will be (dropped.bad_mac): someone "
          "without the key is sending as the session (docs/security.md)",
          channel, wire::ProcessCodeName(process), pid);
    }
    return false;
  }
  *size -= wire::kMacBytes;
  return true;
}

// A control message taken once, and only while fresh: a real one recorded
// off the network and sent again is refused (dropped.replayed).
bool LcmInterface::FreshControl(const void* data, int size) {
  std::int64_t sent = 0;
  const std::int64_t now = NowUs();
  while (!control_seen_.empty() && control_seen_.front().first < now - kControlFreshUs)
    control_seen_.pop_front();
  // Sent before this process began: a restarted process has not seen the
  // tags its predecessor took, and takes no command older than itself.
  if (!wire::ReadInt64At(data, size, wire::kFrameAt, &sent) ||
      std::abs(now - sent) > kControlFreshUs || sent < started_us_) {
    if (replayed_dropped_++ == 0)
      spdlog::warn(
          "{}: a command sent at {} us, {:.1f} s from now -- dropped, as every one like it will "
          "be (dropped.replayed): a recorded command sent again, or a host whose clock is off",
          wire::channels::kControl, sent, (sent - now) * 1e-6);
    return false;
  }
  std::array<std::uint8_t, wire::kMacBytes> tag{};
  std::memcpy(tag.data(), static_cast<const std::uint8_t*>(data) + size, tag.size());
  for (const auto& seen : control_seen_) {
    if (seen.second == tag) {
      if (replayed_dropped_++ == 0)
        spdlog::warn(
            "{}: a command taken before, sent again -- dropped, as every one like it will be "
            "(dropped.replayed)",
            wire::channels::kControl);
      return false;
    }
  }
  control_seen_.emplace_back(now, tag);
  return true;
}

bool LcmInterface::Admit(const std::string& channel, const void* data, int* size) {
  if (sender_.session_id == 0) return true;  // no session: takes every session's messages
  std::int64_t fp = 0, id = 0;
  // Only rmslab messages carry a sender; anything else goes on to be
  // refused by the decoder (dropped.wrong_type), as before.
  if (!wire::ReadFingerprint(data, *size, &fp) || !wire::IsRmslabFingerprint(fp) ||
      !wire::ReadSessionId(data, *size, &id))
    return true;
  if (id == sender_.session_id) {
    if (key_) {
      if (!Authentic(channel, data, size)) return false;
      std::string_view base = channel;
      if (!suffix_.empty() && base.size() >= suffix_.size()) base.remove_suffix(suffix_.size());
      if (base == wire::channels::kControl && !FreshControl(data, *size)) return false;
    }
    return AdmitPublisher(channel, data, *size);
  }
  ++other_session_dropped_;
  if (other_sessions_[id]++ == 0) {
    std::int8_t process = 0;
    std::int32_t pid = 0;
    wire::ReadSenderProcess(data, *size, &process, &pid);
    spdlog::warn(
        "{}: a message of another session (session {}, {} pid {}) -- dropped, as every one of it "
        "will be "
        "(dropped.other_session). Two sessions share this address: give each its own "
        "--channel-suffix or "
        "--lcm-url (docs/security.md)",
        channel, wire::FormatSessionId(id), wire::ProcessCodeName(process), pid);
  }
  return false;
}

// One publisher a channel (docs/security.md "Sessions know each other"): on
// the channels that only one process of a session publishes, a message from
// another pid is taken only once the current publisher has fallen silent (it
// ended, and this is its restart); while it still sends, the other is an
// impostor with the session's id, dropped and counted.
bool LcmInterface::AdmitPublisher(const std::string& channel, const void* data, int size) {
  std::string_view base = channel;  // per message: no allocation
  if (!suffix_.empty() && base.size() >= suffix_.size()) base.remove_suffix(suffix_.size());
  if (base != wire::channels::kOperatorInput && base != wire::channels::kDcpFrame &&
      base != wire::channels::kEsgFrame && base != wire::channels::kDcpTelemetry &&
      base != wire::channels::kOperatorState && base != wire::channels::kWindowKeys &&
      base != wire::channels::kDcpState) {
    return true;  // RMS_STATUS and RMS_CONTROL have several publishers
  }
  std::int8_t process = 0;
  std::int32_t pid = 0;
  if (!wire::ReadSenderProcess(data, size, &process, &pid)) return true;
  const std::int64_t now = NowUs();
  Publisher& p = publishers_[channel];
  if (p.last_us == 0 || (p.pid == pid && p.process == process)) {
    p.process = process;
    p.pid = pid;
    p.last_us = now;
    return true;
  }
  if (now - p.last_us < kPublisherSilenceUs) {
    ++other_sender_dropped_;
    if (!p.warned) {
      p.warned = true;
      spdlog::warn(
          "{}: a message of this session from {} pid {} while its publisher ({} pid {}) is sending "
          "-- dropped, "
          "as every one will be while it sends (dropped.other_sender): someone with this session's "
          "id is "
          "impersonating a process (docs/security.md)",
          channel, wire::ProcessCodeName(process), pid, wire::ProcessCodeName(p.process), p.pid);
    }
    return false;
  }
  spdlog::info("{}: a new publisher, {} pid {}, after {} ms of silence from pid {} (a restart)",
               channel, wire::ProcessCodeName(process), pid, (now - p.last_us) / 1000, p.pid);
  p = Publisher{process, pid, now, false};
  return true;
}

// ---------------------------------------------------------------- UdpLcm

struct UdpLcm::Sub {
  Handler handler;
  UdpLcm* owner = nullptr;
  static void OnMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel, Sub* self) {
    int size = static_cast<int>(rbuf->data_size);
    if (!self->owner->Admit(channel, rbuf->data, &size)) return;
    self->handler(rbuf->data, size, rbuf->recv_utime);
  }
};

UdpLcm::UdpLcm(const LcmOptions& options)
    : LcmInterface(options.channel_suffix, WallTimeUs()),
      url_(options.url),
      queue_capacity_(options.queue_capacity) {
  if (queue_capacity_ < 1) throw InputError("LCM queue capacity must be >= 1");
  lcm_ = std::make_unique<lcm::LCM>(url_);
  if (!lcm_->good()) {
    throw TransportError(
        "LCM could not open '" + url_ +
        "'. For UDP multicast this machine needs a route to 224.0.0.0/4; on a host without a "
        "default route add one on loopback:  sudo ip route add 224.0.0.0/4 dev lo  "
        "(scripts/lab and scripts/test add it for you). Check the URL's group, port and ttl.");
  }
}

UdpLcm::~UdpLcm() = default;

bool UdpLcm::Publish(std::string_view channel, const void* data, int size) {
  // The journal first: the record holds what was sent even when the
  // process dies right after (docs/sessions.md "The record").
  const std::string full = FullChannel(channel);
  data = Seal(full, data, &size);
  Journalize(full, data, size);
  return lcm_->publish(full, data, static_cast<unsigned>(size)) == 0;
}

void UdpLcm::Subscribe(std::string_view channel, Handler handler) {
  auto sub = std::make_unique<Sub>();
  sub->handler = std::move(handler);
  sub->owner = this;
  // LCM treats the channel as a regex; our names hold only [A-Za-z0-9_].
  lcm::Subscription* s = lcm_->subscribeFunction(FullChannel(channel), &Sub::OnMessage, sub.get());
  RMS_CHECK(s != nullptr);
  s->setQueueCapacity(queue_capacity_);
  subs_.push_back(std::move(sub));
}

int UdpLcm::HandleSubscriptions(int timeout_ms) {
  int handled = 0;
  errno = 0;
  int r = lcm_->handleTimeout(timeout_ms);
  while (r > 0) {
    ++handled;
    r = lcm_->handleTimeout(0);  // drain what is already queued
  }
  // A signal (SIGINT to stop) interrupting the wait is not a transport error.
  if (r < 0 && errno == EINTR) return handled;
  return r < 0 ? r : handled;
}

std::int64_t UdpLcm::NowUs() const { return WallTimeUs(); }

// ---------------------------------------------------------------- LogLcm

LogLcm::LogLcm(const std::string& input_path, const std::string& output_path,
               std::string channel_suffix)
    : LcmInterface(std::move(channel_suffix)) {
  if (!input_path.empty()) {
    in_ = std::make_unique<lcm::LogFile>(input_path, "r");
    if (!in_->good()) throw InputError("cannot read LCM log '" + input_path + "'");
    input_done_ = false;
  }
  if (!output_path.empty()) {
    out_ = std::make_unique<lcm::LogFile>(output_path, "w");
    if (!out_->good()) throw InputError("cannot write LCM log '" + output_path + "'");
  }
}

LogLcm::~LogLcm() = default;

bool LogLcm::Publish(std::string_view channel, const void* data, int size) {
  if (pending_count_ == pending_.size()) pending_.emplace_back();
  Pending& p = pending_[pending_count_++];
  p.channel.assign(channel);
  p.channel.append(channel_suffix());
  data = Seal(p.channel, data, &size);
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  p.data.assign(bytes, bytes + size);
  if (out_) {
    lcm::LogEvent ev{};
    ev.timestamp = now_us_;
    ev.channel = p.channel;
    ev.datalen = size;
    ev.data = const_cast<void*>(data);
    if (out_->writeEvent(&ev) != 0) {
      --pending_count_;  // not sent
      if (write_failures_++ == 0) write_errno_ = errno ? errno : EIO;
      return false;
    }
  }
  return true;
}

bool LogLcm::FinishOutput(std::string* why) {
  if (!out_) return true;
  FILE* f = out_->getFilePtr();
  if (write_failures_ == 0 && f && std::fflush(f) == 0 && !std::ferror(f)) return true;
  const int e = write_failures_ > 0 ? write_errno_ : (errno ? errno : EIO);
  *why = std::to_string(write_failures_) + " event(s) could not be written, and the log " +
         (write_failures_ > 0 ? "is short of them" : "could not be flushed") + " (" +
         std::strerror(e) + ")";
  return false;
}

void LogLcm::Subscribe(std::string_view channel, Handler handler) {
  handlers_.emplace_back(FullChannel(channel), std::move(handler));
}

void LogLcm::Dispatch(const std::string& channel, const void* data, int size) {
  if (!Admit(channel, data, &size)) return;
  for (auto& [name, handler] : handlers_) {
    if (name == channel) handler(data, size, now_us_);
  }
}

int LogLcm::HandleSubscriptions(int /*timeout_ms*/) {
  // Messages published locally go first (they were "sent" before the next
  // logged event is read), then one logged event.
  int handled = 0;
  // A handler may publish (into the other list) but not dispatch again: the
  // list being dispatched would be swapped under it.
  RMS_CHECK(!dispatching_now_);
  dispatching_now_ = true;
  struct Done {
    bool* flag;
    ~Done() { *flag = false; }  // also when a handler throws
  } done{&dispatching_now_};
  while (pending_count_ > 0) {
    // Handlers may publish: into the other list.
    std::swap(pending_, dispatching_);
    const std::size_t n = pending_count_;
    pending_count_ = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const Pending& p = dispatching_[i];
      Dispatch(p.channel, p.data.data(), static_cast<int>(p.data.size()));
      ++handled;
    }
  }
  if (handled > 0 || input_done_) return handled;
  const lcm::LogEvent* ev = in_->readNextEvent();
  if (ev == nullptr) {
    input_done_ = true;
    return 0;
  }
  now_us_ = ev->timestamp;
  Dispatch(ev->channel, ev->data, ev->datalen);
  return 1;
}

}  // namespace rms::transport
