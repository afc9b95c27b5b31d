#pragma once
// The six acquisition conditions of report IV.A.3, in its order: the one
// table of their names (RMS_DCP_TELEMETRY acquisition_conditions[i] and
// acquisition_margin_ft[i]; docs/collision.md "Acquisition").
#include <array>

namespace rms::wire {

// The conditions by their index in the telemetry's arrays.
enum AcquisitionCondition : int {
  kBarBeyondPalmFaceD = 0,  // all BAR vertices on the TRUE side of face d of EFF HEX 1
  kBarBeyondFingerFaceB,    // ... of face b of EFF HEX 2 (the fixed finger)
  kBarBeyondFingerFaceE,    // ... of face e of EFF HEX 3 (the movable finger)
  kFingerGapBelowD3Y,       // faces b and e nearer than D3Y
  kPalmWithinTpob,          // EFF HEX 1's face d within TPOB of the BAR's face c
  kBetweenBarEnds,          // the end effector between the BAR's ends
  kNumAcquisitionConditions
};

struct AcquisitionConditionName {
  const char* tag;    // a narrow screen's: "palm d"
  const char* brief;  // a screen's column: "BAR beyond palm face d"
  const char* text;   // a sentence's: "the BAR beyond face d of EFF HEX 1 (the palm)"
};

inline constexpr std::array<AcquisitionConditionName, kNumAcquisitionConditions>
    kAcquisitionConditionNames = {{
        {"palm d", "BAR beyond palm face d", "the BAR beyond face d of EFF HEX 1 (the palm)"},
        {"finger b", "BAR beyond finger face b",
         "the BAR beyond face b of EFF HEX 2 (the fixed finger)"},
        {"finger e", "BAR beyond finger face e",
         "the BAR beyond face e of EFF HEX 3 (the movable finger)"},
        {"gap D3Y", "finger gap below D3Y", "the finger gap below D3Y"},
        {"TPOB", "palm within TPOB of BAR", "the palm within TPOB of the BAR's top"},
        {"BAR ends", "palm between BAR ends", "the end effector between the BAR's ends"},
    }};

}  // namespace rms::wire
