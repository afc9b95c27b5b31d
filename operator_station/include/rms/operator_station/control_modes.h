#pragma once
// The hand controllers' control modes and command frames, as the flown
// shuttle arm's operators had them (docs/operator.md "Control modes").
#include <optional>
#include <string_view>

namespace rms::operator_station {

enum class ControlMode : int {
  kSingleJoint = 1,  // one joint at a time, at a rate (the translational controller's x drives it)
  kManualAugmented = 2,  // resolved rate: the hand controllers move the point of resolution
};

// Manual augmented control's frames: the axes the hand controllers' x, y, z
// and roll, pitch, yaw are about (docs/operator.md "Command frames").
enum class CommandFrame : int {
  kEndEffector = 1,  // the wrist camera's view: x forward (X2), y image right, z image down
  kOrbiter = 2,  // the orbiter's body axes: x to the nose (-X_R), y starboard (Y_R), z down (-Z_R)
  kPayload = 3,  // the payload's axes x_P, y_P (toward the probe), z_P (toward the bar); once held
};

// The hand controllers' rate scales (docs/operator.md "Rates: coarse,
// vernier and fine"): the full-scale rates and a terminal press's increment.
enum class RateScale : int {
  kCoarse = 1,   // the long way: 2 ft/s, 8 deg/s; a press 5 ft, 20 deg
  kVernier = 2,  // a tenth
  kFine = 3,     // the last hundredths: vernier's rates, a press 0.05 ft, 0.2 deg
};

// The hand controllers' six axes: the translational controller's (THC) x,
// y, z and the rotational one's (RHC) roll, pitch, yaw about the command
// frame's x, y, z.
enum HandAxis : int { kThcX = 0, kThcY, kThcZ, kRhcRoll, kRhcPitch, kRhcYaw, kNumHandAxes };
inline constexpr std::string_view kHandAxisNames[kNumHandAxes] = {
    "thc_x", "thc_y", "thc_z", "rhc_roll", "rhc_pitch", "rhc_yaw"};

std::string_view ControlModeName(ControlMode m);    // "single joint", "manual augmented"
std::string_view CommandFrameName(CommandFrame f);  // "end effector", "orbiter", "payload"
std::string_view RateScaleName(RateScale s);        // "coarse", "vernier", "fine"
// The next scale of the scale key: coarse, vernier, fine, coarse...
RateScale NextRateScale(RateScale s);
// From the bindings file's words: "single_joint", "manual_augmented";
// "end_effector", "orbiter", "payload".
std::optional<ControlMode> ParseControlMode(std::string_view s);
std::optional<CommandFrame> ParseCommandFrame(std::string_view s);
std::optional<RateScale> ParseRateScale(std::string_view s);  // "coarse", "vernier", "fine"
int HandAxisIndex(std::string_view name);                     // -1 when none

}  // namespace rms::operator_station
