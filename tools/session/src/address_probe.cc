#include "rms/session/address_probe.h"

#include <algorithm>
#include <cstdint>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <set>

#include "rms/transport/lcm_interface.h"
#include "rms/transport/process.h"
#include "rms/wire/message_io.h"

namespace rms::session {

nlohmann::ordered_json ProbeAddress(const std::string& url, double seconds) {
  lcm::LCM lcm(url);
  if (!lcm.good())
    throw transport::TransportError("cannot listen on '" + url +
                                    "' (no route for multicast? scripts/lab adds one)");
  struct Heard {
    std::map<std::string, std::int64_t> channels;
    std::set<std::string> senders;
  };
  std::map<std::int64_t, Heard> sessions;
  struct Handler {
    std::map<std::int64_t, Heard>* out;
    void On(const lcm::ReceiveBuffer* rb, const std::string& channel) {
      std::int64_t fp = 0, id = 0;
      std::int8_t process = 0;
      std::int32_t pid = 0;
      const int n = static_cast<int>(rb->data_size);
      if (!wire::ReadFingerprint(rb->data, n, &fp) || !wire::IsRmslabFingerprint(fp) ||
          !wire::ReadSessionId(rb->data, n, &id))
        return;
      wire::ReadSenderProcess(rb->data, n, &process, &pid);
      Heard& h = (*out)[id];
      ++h.channels[channel];
      h.senders.insert(std::string(wire::ProcessCodeName(process)) + " pid " + std::to_string(pid));
    }
  } handler{&sessions};
  lcm.subscribe("RMS_.*", &Handler::On, &handler);
  const std::int64_t end = transport::WallTimeUs() + static_cast<std::int64_t>(seconds * 1e6);
  for (std::int64_t now = transport::WallTimeUs(); now < end; now = transport::WallTimeUs()) {
    lcm.handleTimeout(static_cast<int>(std::max<std::int64_t>(1, (end - now) / 1000)));
  }
  nlohmann::ordered_json j;
  j["url"] = url;
  j["seconds"] = seconds;
  j["sessions"] = nlohmann::ordered_json::array();
  for (const auto& [id, h] : sessions) {
    j["sessions"].push_back({{"session_id", wire::FormatSessionId(id)},
                             {"channels", h.channels},
                             {"senders", h.senders}});
  }
  return j;
}

}  // namespace rms::session
