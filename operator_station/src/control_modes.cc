#include "rms/operator_station/control_modes.h"

namespace rms::operator_station {

std::string_view ControlModeName(ControlMode m) {
  switch (m) {
    case ControlMode::kSingleJoint:
      return "single joint";
    case ControlMode::kManualAugmented:
      return "manual augmented";
  }
  return "?";
}

std::string_view CommandFrameName(CommandFrame f) {
  switch (f) {
    case CommandFrame::kEndEffector:
      return "end effector";
    case CommandFrame::kOrbiter:
      return "orbiter";
    case CommandFrame::kPayload:
      return "payload";
  }
  return "?";
}

std::string_view RateScaleName(RateScale s) {
  switch (s) {
    case RateScale::kCoarse:
      return "coarse";
    case RateScale::kVernier:
      return "vernier";
    case RateScale::kFine:
      return "fine";
  }
  return "?";
}

RateScale NextRateScale(RateScale s) {
  return s == RateScale::kCoarse    ? RateScale::kVernier
         : s == RateScale::kVernier ? RateScale::kFine
                                    : RateScale::kCoarse;
}

std::optional<RateScale> ParseRateScale(std::string_view s) {
  for (RateScale r : {RateScale::kCoarse, RateScale::kVernier, RateScale::kFine})
    if (s == RateScaleName(r)) return r;
  return std::nullopt;
}

std::optional<ControlMode> ParseControlMode(std::string_view s) {
  if (s == "single_joint") return ControlMode::kSingleJoint;
  if (s == "manual_augmented") return ControlMode::kManualAugmented;
  return std::nullopt;
}

std::optional<CommandFrame> ParseCommandFrame(std::string_view s) {
  if (s == "end_effector") return CommandFrame::kEndEffector;
  if (s == "orbiter") return CommandFrame::kOrbiter;
  if (s == "payload") return CommandFrame::kPayload;
  return std::nullopt;
}

int HandAxisIndex(std::string_view name) {
  for (int i = 0; i < kNumHandAxes; ++i) {
    if (kHandAxisNames[i] == name) return i;
  }
  return -1;
}

}  // namespace rms::operator_station
