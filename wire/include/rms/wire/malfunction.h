#pragma once
// Malfunctions an instructor injects (docs/sessions.md "Malfunctions"): what
// RMS_CONTROL's MALFUNCTION and REPAIR commands carry in their `name`, as
// text, so the control message's type (and every log recorded before
// malfunctions existed) stays as it was. One grammar, parsed and printed
// here only (the page's menu is built from kMalfunctionKinds through
// /api/map; the launcher's `scripts/lab control --help` and docs/sessions.md
// still write it out by hand):
//
//   MALFUNCTION  joint N stuck            joint N (1..6) stays where it is
//                joint N drift RATE       joint N turns at RATE deg/s whatever is commanded
//                joint N slow RATE        joint N follows at most RATE deg/s
//                finger jammed open       the finger can no longer close past where it is
//                finger jammed closed     the finger can no longer open past where it is
//                camera N lost            camera station N (1..8) sends no picture
//                inputs delayed MS        the operator's inputs reach the DCP MS ms late
//   REPAIR       joint N | finger | camera N | inputs | all
//
// Joints are numbered as the report's angles: 1 shoulder yaw, 2 shoulder
// pitch, 3 elbow pitch, 4 wrist pitch, 5 wrist yaw, 6 wrist roll.
#include <array>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "rms/base/analog_inputs.h"
#include "rms/base/config.h"

namespace rms::wire {

enum class MalfunctionKind : int {
  kJointStuck = 0,
  kJointDrift,
  kJointSlow,
  kFingerJammedOpen,
  kFingerJammedClosed,
  kCameraLost,
  kInputsDelayed,
  kCount
};

// What a kind's text looks like and what its number means (the one table:
// the parser, the page's menu and docs/sessions.md follow it).
struct MalfunctionKindInfo {
  MalfunctionKind kind;
  const char* name;             // identifier, e.g. "joint_stuck" (the page's menu, summary.json)
  const char* pattern;          // the text, with N the target and V the value
  const char* value;            // the value's meaning and unit ("" when none)
  double min_value, max_value;  // the value's accepted range (inclusive)
};
inline constexpr std::array<MalfunctionKindInfo, static_cast<int>(MalfunctionKind::kCount)>
    kMalfunctionKinds = {{
        {MalfunctionKind::kJointStuck, "joint_stuck", "joint N stuck", "", 0, 0},
        {MalfunctionKind::kJointDrift, "joint_drift", "joint N drift V",
         "drift rate, deg/s (signed, not 0)", -20.0, 20.0},
        {MalfunctionKind::kJointSlow, "joint_slow", "joint N slow V",
         "the joint's rate at most, deg/s", 0.01, 100.0},
        {MalfunctionKind::kFingerJammedOpen, "finger_jammed_open", "finger jammed open", "", 0, 0},
        {MalfunctionKind::kFingerJammedClosed, "finger_jammed_closed", "finger jammed closed", "",
         0, 0},
        {MalfunctionKind::kCameraLost, "camera_lost", "camera N lost", "", 0, 0},
        {MalfunctionKind::kInputsDelayed, "inputs_delayed", "inputs delayed V", "the delay, ms",
         1.0, 3000.0},
    }};
const MalfunctionKindInfo& KindInfo(MalfunctionKind kind);

// The joints and camera stations a malfunction names (their one home:
// rms/base/analog_inputs.h, rms/base/config.h).
using ::rms::kNumCameraStations;
using ::rms::kNumJoints;

struct Malfunction {
  MalfunctionKind kind = MalfunctionKind::kJointStuck;
  int target = 0;      // joint 1..6 or camera station 1..8; 0 for the finger and the inputs
  double value = 0.0;  // as KindInfo(kind).value says; 0 when none
  bool operator==(const Malfunction&) const = default;
};

// What a REPAIR clears.
enum class RepairWhat : int { kJoint = 0, kFinger, kCamera, kInputs, kAll };
struct Repair {
  RepairWhat what = RepairWhat::kAll;
  int target = 0;  // the joint or camera station; 0 otherwise
  bool operator==(const Repair&) const = default;
};

// Text -> malfunction or repair. Extra spaces and case are forgiven; a
// value must be a plain decimal number. Throws rms::InputError naming what is
// wrong and showing the grammar (an unknown word, a joint outside 1..6, a
// value outside its range, ...).
Malfunction ParseMalfunction(std::string_view text);
Repair ParseRepair(std::string_view text);
// The canonical text (ParseMalfunction(MalfunctionText(m)) == m).
std::string MalfunctionText(const Malfunction& m);
std::string RepairText(const Repair& r);
// Whether a repair clears this malfunction.
bool Clears(const Repair& r, const Malfunction& m);
// The repair that clears exactly this malfunction's part (its joint, the
// finger, its camera station, the inputs): the part's name as RepairText.
Repair RepairFor(const Malfunction& m);
// The joint's name, 1 "shoulder yaw" .. 6 "wrist roll".
const char* JointName(int joint);
// The longest malfunction or repair text a command may carry, bytes.
inline constexpr std::size_t kMaxMalfunctionTextBytes = 64;

// The key of a DCP checkpoint (DynamicCollisionProgram::SaveState) under
// which the malfunctions in force are kept (dynamics_proc's Malfunctions),
// and the texts of those in force; none when the state has no such key. For
// readers of RMS_DCP_STATE (the instructor's station, the summary).
inline constexpr const char* kMalfunctionsKey = "malfunctions";
std::vector<std::string> MalfunctionTexts(const nlohmann::json& dcp_state);

}  // namespace rms::wire
