#pragma once
// Malfunctions an instructor injects (docs/sessions.md "Malfunctions"): what
// RMS_CONTROL's MALFUNCTION and REPAIR commands carry in their `name`, as
// text, so the control message's type (and every log recorded before
// malfunctions existed) stays as it was. One grammar, in the two tables
// below (kMalfunctionParts, kMalfunctionKinds): the parser, the printer, the
// error messages, the page's menu (/api/map), `rms_control --help` and the
// table in docs/sessions.md (`rms_session malfunctions`, held to it by a
// test) are all made from them. A new kind is a row of kMalfunctionKinds
// and what the DCP does with it (rms/dcp_model/malfunctions.h). The grammar
// as users read it: `rms_session malfunctions`, `rms_control malfunction
// --help`.
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

// The part a malfunction acts on, and the part a repair names (all but
// REPAIR all).
enum class MalfunctionPart : int { kJoint = 0, kFinger, kCamera, kInputs, kCount };
struct MalfunctionPartInfo {
  MalfunctionPart part;
  const char* word;    // the first word of its malfunctions and of its repair
  const char* target;  // what its number N names ("" when it has none)
  int count;           // N is 1..count; 0 when it has no number
};
inline constexpr std::array<MalfunctionPartInfo, static_cast<int>(MalfunctionPart::kCount)>
    kMalfunctionParts = {{
        {MalfunctionPart::kJoint, "joint", "joint", ::rms::kNumJoints},
        {MalfunctionPart::kFinger, "finger", "", 0},
        {MalfunctionPart::kCamera, "camera", "camera station", ::rms::kNumCameraStations},
        {MalfunctionPart::kInputs, "inputs", "", 0},
    }};
const MalfunctionPartInfo& PartInfo(MalfunctionPart part);
static_assert(
    [] {
      for (std::size_t i = 0; i < kMalfunctionParts.size(); ++i) {
        if (static_cast<std::size_t>(kMalfunctionParts[i].part) != i) return false;
      }
      return true;
    }(),
    "kMalfunctionParts is in MalfunctionPart's order (PartInfo reads it so)");

// What a kind's text looks like, the part it acts on and what its number
// means (the one table: the parser, the printer, the page's menu and
// docs/sessions.md follow it). The pattern's first word is its part's word;
// N stands for the part's number (when it has one) and V for the value.
struct MalfunctionKindInfo {
  MalfunctionKind kind;
  MalfunctionPart part;
  const char* name;             // identifier, e.g. "joint_stuck" (the page's menu, summary.json)
  const char* pattern;          // the text, with N the target and V the value
  const char* value_word;       // V as the grammar shows it ("DEG_S", "MS"; "" when none)
  const char* value;            // the value's meaning and unit ("" when none)
  double min_value, max_value;  // the value's accepted range (inclusive)
  double typical_value;         // the value the page offers first (0 when none)
  const char* unit;             // the value's unit in docs ("-" when none)
  const char* meaning;          // what fails (docs/sessions.md's table)
};
inline constexpr std::array<MalfunctionKindInfo, static_cast<int>(MalfunctionKind::kCount)>
    kMalfunctionKinds = {{
        {MalfunctionKind::kJointStuck, MalfunctionPart::kJoint, "joint_stuck", "joint N stuck", "",
         "", 0, 0, 0, "-", "joint N stays where it was when it failed, whatever is commanded"},
        {MalfunctionKind::kJointDrift, MalfunctionPart::kJoint, "joint_drift", "joint N drift V",
         "DEG_S", "drift rate, deg/s (signed, not 0)", -20.0, 20.0, 1.0, "deg/s",
         "joint N turns at V deg/s (signed, not 0) whatever is commanded, from where it is each "
         "frame (held by a collision, it does not wind up), within the joint's travel (config "
         "`[arm]` joint limits, within `[inputs.*]`)"},
        {MalfunctionKind::kJointSlow, MalfunctionPart::kJoint, "joint_slow", "joint N slow V",
         "DEG_S", "the joint's rate at most, deg/s", 0.01, 100.0, 1.0, "deg/s",
         "joint N moves toward its command at most V deg/s"},
        {MalfunctionKind::kFingerJammedOpen, MalfunctionPart::kFinger, "finger_jammed_open",
         "finger jammed open", "", "", 0, 0, 0, "-",
         "the finger cannot close past where it was when it jammed (it may still open): it cannot "
         "acquire"},
        {MalfunctionKind::kFingerJammedClosed, MalfunctionPart::kFinger, "finger_jammed_closed",
         "finger jammed closed", "", "", 0, 0, 0, "-",
         "the finger cannot open past where it was: a held payload cannot be released"},
        {MalfunctionKind::kCameraLost, MalfunctionPart::kCamera, "camera_lost", "camera N lost", "",
         "", 0, 0, 0, "-",
         "camera station N sends no picture: when the operator selects it, the DCP sets the "
         "control word's NO VIDEO bit (bit 6) and the ESG draws black with \"NO VIDEO\"; the "
         "instructor's view of the station goes black too"},
        {MalfunctionKind::kInputsDelayed, MalfunctionPart::kInputs, "inputs_delayed",
         "inputs delayed V", "MS", "the delay, ms", 1.0, 3000.0, 500.0, "ms",
         "the operator's inputs reach the DCP V ms late: every input block is answered round(V x "
         "frame rate / 1000) frames late, at least one. When the delay starts, the last block "
         "answered is held until the first delayed one is due; a longer delay holds, a shorter "
         "one drops the oldest blocks; repaired, the next frame answers its own block"},
    }};
const MalfunctionKindInfo& KindInfo(MalfunctionKind kind);
static_assert(
    [] {
      for (std::size_t i = 0; i < kMalfunctionKinds.size(); ++i) {
        if (static_cast<std::size_t>(kMalfunctionKinds[i].kind) != i) return false;
      }
      return true;
    }(),
    "kMalfunctionKinds is in MalfunctionKind's order (KindInfo reads it so)");

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

// What a REPAIR clears: every malfunction, or those of one part (and of its
// number N, for a part that has one).
struct Repair {
  bool all = true;
  MalfunctionPart part = MalfunctionPart::kJoint;  // when not all
  int target = 0;                                  // the joint or camera station; 0 otherwise
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
// The grammars as error messages and help show them, made from the tables:
// "'joint N stuck', ..., or 'inputs delayed MS' (joints 1..6, cameras 1..8)".
std::string MalfunctionGrammar();
std::string RepairGrammar();
// docs/sessions.md's table of malfunctions (markdown), made from the tables.
std::string MalfunctionTableMarkdown();
// The longest malfunction or repair text a command may carry, bytes.
inline constexpr std::size_t kMaxMalfunctionTextBytes = 64;

// The key of a DCP checkpoint (DynamicCollisionProgram::SaveState) under
// which the malfunctions in force are kept (dynamics_proc's Malfunctions),
// and the texts of those in force; none when the state has no such key. For
// readers of RMS_DCP_STATE (the instructor's station, the summary).
inline constexpr const char* kMalfunctionsKey = "malfunctions";
std::vector<std::string> MalfunctionTexts(const nlohmann::json& dcp_state);

}  // namespace rms::wire
