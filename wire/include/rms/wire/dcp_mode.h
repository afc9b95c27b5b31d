#pragma once
// The DCP's modes (report Section II; docs/collision.md): their one
// enumeration and one name table. The wire carries the mode as its number
// (the control word's MODE bits, RMS_DCP_TELEMETRY.mode, RMS_OPERATOR_STATE
// guidance's mode); the summary's phase keys are the attempts' (docs/
// sessions.md "Attempts": "maneuvering", a key kept as recorded sessions
// have it).
#include <array>
#include <compare>
#include <concepts>
#include <type_traits>

namespace rms::wire {

enum class DcpMode : int {
  kAcquisition = 1,  // Mode 1: acquire the payload in the cargo bay
  kExtraction = 2,   // Mode 2: lift it clear of the bay
  kManoeuvring = 3,  // Mode 3: manoeuvre it and dock it to the CAE
};
inline constexpr int kNumDcpModes = 3;

// The number the wire carries for a mode (0 on the wire: not yet known).
constexpr int ModeNumber(DcpMode mode) { return static_cast<int>(mode); }

struct DcpModeInfo {
  DcpMode mode;
  const char* name;   // "acquisition", "extraction", "manoeuvring and docking"
  const char* upper;  // the operator's screen: "ACQUISITION", ...
};
inline constexpr std::array<DcpModeInfo, kNumDcpModes> kDcpModes = {{
    {DcpMode::kAcquisition, "acquisition", "ACQUISITION"},
    {DcpMode::kExtraction, "extraction", "EXTRACTION"},
    {DcpMode::kManoeuvring, "manoeuvring and docking", "MANOEUVRING AND DOCKING"},
}};

// kDcpModes is in the enumeration's order, mode k at index k - 1 (DcpModeOf
// reads it so).
static_assert([] {
  for (int i = 0; i < kNumDcpModes; ++i) {
    if (ModeNumber(kDcpModes[i].mode) != i + 1) return false;
  }
  return ModeNumber(DcpMode::kManoeuvring) == kNumDcpModes;
}());

// Mode 1..3's entry; nullptr for any other number (a mode not yet known).
constexpr const DcpModeInfo* DcpModeOf(int mode) {
  return mode >= 1 && mode <= kNumDcpModes ? &kDcpModes[mode - 1] : nullptr;
}

// A mode as the wire carries it (its number) compared with the enumeration,
// so readers of telemetry write the mode's name, never its number:
// `tm.mode == DcpMode::kManoeuvring`, `tm.mode >= DcpMode::kExtraction`
// (the payload held: Mode 2 or 3). Only a wire number, an integer that is
// not a bool, on the left: a double or a bool does not compare, and a
// DcpMode never compares with a bare number (`mode == 3` does not build;
// the deleted overloads below win over C++20's reversed candidates).
template <typename I>
concept WireModeNumber = std::integral<I> && !std::same_as<I, bool>;
template <WireModeNumber I>
constexpr bool operator==(I number, DcpMode mode) {
  return number == ModeNumber(mode);
}
template <WireModeNumber I>
constexpr std::strong_ordering operator<=>(I number, DcpMode mode) {
  return static_cast<int>(number) <=> ModeNumber(mode);
}
template <typename T>
requires std::is_arithmetic_v<T>
bool operator==(DcpMode, T) = delete;
template <typename T>
requires std::is_arithmetic_v<T> std::strong_ordering operator<=>(DcpMode, T) = delete;

}  // namespace rms::wire
