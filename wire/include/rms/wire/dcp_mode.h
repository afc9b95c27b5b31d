#pragma once
// The DCP's modes (report Section II; docs/collision.md): their one
// enumeration and one name table. The wire carries the mode as its number
// (the control word's MODE bits, RMS_DCP_TELEMETRY.mode, RMS_OPERATOR_STATE
// guidance's mode); the summary's phase keys are the attempts' (docs/
// sessions.md "Attempts": "maneuvering", a key kept as recorded sessions
// have it).
#include <array>
#include <compare>

namespace rms::wire {

enum class DcpMode : int {
  kAcquisition = 1,  // Mode 1: acquire the payload in the cargo bay
  kExtraction = 2,   // Mode 2: lift it clear of the bay
  kManoeuvring = 3,  // Mode 3: manoeuvre it and dock it to the CAE
};
inline constexpr int kNumDcpModes = 3;

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

// Mode 1..3's entry; nullptr for any other number (a mode not yet known).
constexpr const DcpModeInfo* DcpModeOf(int mode) {
  return mode >= 1 && mode <= kNumDcpModes ? &kDcpModes[mode - 1] : nullptr;
}

// The number the wire carries for a mode (0 on the wire: not yet known).
constexpr int ModeNumber(DcpMode mode) { return static_cast<int>(mode); }

// A mode as the wire carries it (its number) compared with the enumeration,
// so readers of telemetry write the mode's name, never its number:
// `tm.mode == DcpMode::kManoeuvring`, `tm.mode >= DcpMode::kExtraction`
// (the payload held: Mode 2 or 3).
constexpr bool operator==(int number, DcpMode mode) { return number == ModeNumber(mode); }
constexpr std::strong_ordering operator<=>(int number, DcpMode mode) {
  return number <=> ModeNumber(mode);
}

}  // namespace rms::wire
