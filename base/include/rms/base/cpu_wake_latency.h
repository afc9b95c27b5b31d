#pragma once
// The CPUs' wake-up latency, held low while a session's process runs
// (docs/performance.md "Wake latency"). Between two frames the session's
// processes sleep, and an idle CPU halts: on this machine kind (a virtual
// machine whose idle vCPU leaves the guest) waking it for the next frame's
// message costs more than the hop itself, once at each of the four
// processes and again at the renderer's rasteriser threads. A Linux PM QoS
// request (/dev/cpu_dma_latency, the kernel's Documentation/power/pm_qos_
// interface.rst) of at most N microseconds keeps the idle CPUs in the idle
// states that wake within N: at 0, the idle loop polls instead of halting.
// The request is the whole machine's, not the process's: every CPU polls
// while any process holds it. Tasks on the machine lose no time to it (a
// polling CPU runs whatever becomes ready at once); it costs power, and the
// polling CPUs are busy to whatever shares them (a hyperthread's sibling, a
// virtual machine's host). The request lasts as long as the file stays
// open: the kernel drops it when the process ends, however it ends.
#include <cstdint>
#include <optional>
#include <string>

namespace rms {

inline constexpr const char* kCpuWakeLatencyDevice = "/dev/cpu_dma_latency";
inline constexpr std::int32_t kMaxCpuWakeLatencyUs = 1000000;
// The launcher's request to its processes (docs/sessions.md "The launcher").
inline constexpr const char* kCpuWakeLatencyEnv = "RMSLAB_CPU_WAKE_LATENCY_US";

class CpuWakeLatencyRequest {
 public:
  CpuWakeLatencyRequest() = default;  // none asked: "off"
  // Asks for at most `max_us` (0 .. kMaxCpuWakeLatencyUs) on `device`. A
  // request that cannot be made (no such device, not permitted) is not an
  // error: held() is false and state() says why.
  explicit CpuWakeLatencyRequest(std::int32_t max_us,
                                 const std::string& device = kCpuWakeLatencyDevice);
  ~CpuWakeLatencyRequest();
  CpuWakeLatencyRequest(CpuWakeLatencyRequest&& other) noexcept;
  CpuWakeLatencyRequest& operator=(CpuWakeLatencyRequest&& other) noexcept;
  CpuWakeLatencyRequest(const CpuWakeLatencyRequest&) = delete;
  CpuWakeLatencyRequest& operator=(const CpuWakeLatencyRequest&) = delete;

  bool asked() const { return asked_; }
  bool held() const { return fd_ >= 0; }
  // "held at 0 us (/dev/cpu_dma_latency)", "off", or
  // "not held at 0 us: /dev/cpu_dma_latency: Permission denied".
  const std::string& state() const { return state_; }

 private:
  int fd_ = -1;
  bool asked_ = false;
  std::string state_ = "off";
};

// RMSLAB_CPU_WAKE_LATENCY_US: unset, empty or "off": nothing asked;
// otherwise a whole number of microseconds, 0 .. kMaxCpuWakeLatencyUs.
// Anything else is an InputError naming the variable and the value.
std::optional<std::int32_t> CpuWakeLatencyFromEnv();

}  // namespace rms
