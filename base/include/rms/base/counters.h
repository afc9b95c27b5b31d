#pragma once
// Non-fatal trouble becomes a counter that is reported, never a silent skip
// (after MuJoCo's warning counters, mjtWarning in mjdata.h): one enumeration
// of every counter a process keeps, and one table of their names -- as they
// appear on RMS_STATUS and in a session's stats/PROCESS.json -- who counts
// them and what they mean. docs/sessions.md "Process counters" is printed
// from this table (`rms_session counters`); a test holds the two together.
//
// Families (one counter per member of another table) are contiguous, in
// that table's order: clamped.INPUT in rms/base/analog_inputs.h's,
// dropped.DECODE_ERROR in rms/wire/message_io.h's, collisions.KIND in
// rms/wire/collision_bits.h's; the tables' own headers check it.
#include <array>
#include <bitset>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rms/base/analog_inputs.h"

namespace rms {

enum class Counter : std::uint16_t {
  kPublished,
  kPublishFailed,
  kReceived,
  kGaps,
  kResyncs,
  kTransportErrors,
  kInputMissing,
  kDcpMissing,
  kEsgMissing,
  kDroppedTooLarge,
  kDroppedWrongType,
  kDroppedTruncated,
  kDroppedTrailingBytes,
  kDroppedBadCount,
  kDroppedBadFrame,
  kDroppedBadTime,
  kDroppedBadWord,
  kDroppedWordCount,
  kDroppedDuplicate,
  kDroppedStale,
  kDroppedFarAhead,
  kDroppedLate,
  kDroppedOtherSession,
  kDroppedOtherSender,
  kDroppedBadMac,
  kDroppedReplayed,
  kDroppedControlMalformed,
  kDroppedStatusMalformed,
  kDroppedStatusRefused,
  kDroppedStateMalformed,
  kDroppedAnswerMalformed,
  kDroppedTelemetryTooLarge,
  kDroppedTelemetryWrongType,
  kDroppedTelemetryTruncated,
  kDroppedTelemetryTrailingBytes,
  kDroppedTelemetryBadCount,
  kDroppedTelemetryFrame,
  kDroppedTelemetryTime,
  kDroppedTelemetryMode,
  kDroppedTelemetryCollisionBits,
  kDroppedTelemetryNonFinite,
  kDroppedWindowKeysTooLarge,
  kDroppedWindowKeysWrongType,
  kDroppedWindowKeysTruncated,
  kDroppedWindowKeysTrailingBytes,
  kDroppedWindowKeysBadCount,
  kDroppedWindowKeysStale,
  kDroppedOperatorStateTooLarge,
  kDroppedOperatorStateWrongType,
  kDroppedOperatorStateTruncated,
  kDroppedOperatorStateTrailingBytes,
  kDroppedOperatorStateBadCount,
  kDroppedOperatorStateStale,
  kDroppedOperatorStateNonFinite,
  kClampedShoulderYaw,
  kClampedShoulderPitch,
  kClampedElbowPitch,
  kClampedWristPitch,
  kClampedWristYaw,
  kClampedWristRoll,
  kClampedFinger,
  kClampedShoulderHeight,
  kClampedCameraPan,
  kClampedCameraTilt,
  kClampedCameraZoom,
  kClampedCameraStation,
  kClampedAdcShoulderYaw,
  kClampedAdcShoulderPitch,
  kClampedAdcElbowPitch,
  kClampedAdcWristPitch,
  kClampedAdcWristYaw,
  kClampedAdcWristRoll,
  kClampedAdcFinger,
  kClampedAdcShoulderHeight,
  kClampedAdcCameraPan,
  kClampedAdcCameraTilt,
  kClampedAdcCameraZoom,
  kJointLimitShoulderYaw,
  kJointLimitShoulderPitch,
  kJointLimitElbowPitch,
  kJointLimitWristPitch,
  kJointLimitWristYaw,
  kJointLimitWristRoll,
  kSaturatedArm,
  kSaturatedCameraZoom,
  kSaturatedEye,
  kSaturatedFingerGap,
  kSaturatedPayloadPos,
  kSaturatedPayloadRot,
  kSaturatedPlane,
  kSaturatedShoulderHeight,
  kSaturatedView,
  kFramesTotal,
  kFramesLate,
  kFramesHeld,
  kFramesFingerHeld,
  kFramesMotionHeld,
  kFramesTooFast,
  kFramesEssentialContact,
  kMode,
  kModeChanges,
  kCollisionsEffHex1Recpt,
  kCollisionsEffHex2Recpt,
  kCollisionsEffHex3Recpt,
  kCollisionsEffHex1Payload,
  kCollisionsEffHex2Payload,
  kCollisionsEffHex3Payload,
  kCollisionsPayloadBayA,
  kCollisionsPayloadBayB,
  kCollisionsPayloadBayC,
  kCollisionsPayloadBayD,
  kCollisionsPayloadBayE,
  kCollisionsPayloadBayF,
  kCollisionsPayloadCae,
  kCollisionsEffHexBarPost,
  kCollisionsNonFinite,
  kCollisionFramesEffHex1Recpt,
  kCollisionFramesEffHex2Recpt,
  kCollisionFramesEffHex3Recpt,
  kCollisionFramesEffHex1Payload,
  kCollisionFramesEffHex2Payload,
  kCollisionFramesEffHex3Payload,
  kCollisionFramesPayloadBayA,
  kCollisionFramesPayloadBayB,
  kCollisionFramesPayloadBayC,
  kCollisionFramesPayloadBayD,
  kCollisionFramesPayloadBayE,
  kCollisionFramesPayloadBayF,
  kCollisionFramesPayloadCae,
  kCollisionFramesEffHexBarPost,
  kCollisionFramesNonFinite,
  kResetsRefused,
  kInputsNonFinite,
  kGraspsLetGo,
  kResumed,
  kStateFileWrites,
  kStateFileErrors,
  kStatePublished,
  kControlFreezes,
  kControlRuns,
  kControlSteps,
  kControlCheckpoints,
  kControlRestores,
  kControlResets,
  kControlRefused,
  kControlRateLimited,
  kControlMalfunctions,
  kControlRepairs,
  kNotFollowing,
  kFrozenInputsIgnored,
  kRestarted,
  kKeyActions,
  kIncrementsBlocked,
  kSingleJointPressesIgnored,
  kCameraRefused,
  kLessonEvents,
  kControlModeChanges,
  kControlFrameChanges,
  kControlScaleChanges,
  kControlStops,
  kControlNulls,
  kControlSquareUps,
  kControlUnwinds,
  kControlStows,
  kJointNearLimit,
  kClearanceWarnings,
  kDeviceDisconnected,
  kTelemetryStale,
  kTelemetryBeforeReset,
  kWindowKeysTimeouts,
  kAutopilotDocked,
  kAutopilotCollisionsRelieved,
  kAutopilotGraspCorrections,
  kAutopilotGraspRetries,
  kAutopilotDockCorrections,
  kAutopilotViaPoints,
  kAutopilotUnplanned,
  kPriorityDynamicSearches,
  kPriorityUnresolved,
  kPriorityCyclesBroken,
  kRendered,
  kRenderedScenes,
  kSkippedUnchanged,
  kSuperseded,
  kClustersDrawn,
  kClustersCulled,
  kTrianglesSubmitted,
  kPngWritten,
  kPngFailed,
  kVideoFrames,
  kVideoDropped,
  kWindowFrames,
  kWindowKeysMessages,
  kWindowKeysPressed,
  kViewsRendered,
  kHttpRequests,
  kHttpRefused,
  kControlSent,
  kJournalEvents,
  kJournalFailed,
  kNumCounters
};
inline constexpr int kNumCounters = static_cast<int>(Counter::kNumCounters);

struct CounterInfo {
  Counter id;
  std::string_view name;       // on RMS_STATUS and in stats/PROCESS.json
  std::string_view processes;  // who counts it: O operator_station, D dynamics_proc, S scene_proc,
                               // E esg_renderer, I instructor_station
  std::string_view meaning;
};

inline constexpr std::array<CounterInfo, kNumCounters> kCounterTable = {{
    {Counter::kPublished, "published", "O, D, S, E, I",
     "messages published on the process's output channel"},
    {Counter::kPublishFailed, "publish_failed", "O, D, S, E, I",
     "messages the transport refused to send, or beyond their type's bounds"},
    {Counter::kReceived, "received", "D, S, E, I",
     "messages received on the process's input channel"},
    {Counter::kGaps, "gaps", "D, S, E, I",
     "times a frame number skipped ahead (the frames are in input.missing, dcp.missing, "
     "esg.missing)"},
    {Counter::kResyncs, "resyncs", "O, D, S, E, I",
     "frame numbering followed again after 30 frames beyond the last in a row (docs/protocol.md "
     "\"Frame numbers\")"},
    {Counter::kTransportErrors, "transport_errors", "O, D, S, E, I", "LCM receive errors"},
    {Counter::kInputMissing, "input.missing", "D", "operator frames lost on the way in"},
    {Counter::kDcpMissing, "dcp.missing", "S, I", "DCP frames lost on the way in"},
    {Counter::kEsgMissing, "esg.missing", "E", "ESG frames lost on the way in"},
    {Counter::kDroppedTooLarge, "dropped.too_large", "D, S, E, I",
     "input frames dropped: larger than any message of its type"},
    {Counter::kDroppedWrongType, "dropped.wrong_type", "D, S, E, I",
     "input frames dropped: not of the channel's type (fingerprint)"},
    {Counter::kDroppedTruncated, "dropped.truncated", "D, S, E, I",
     "input frames dropped: ended before the message did"},
    {Counter::kDroppedTrailingBytes, "dropped.trailing_bytes", "D, S, E, I",
     "input frames dropped: bytes left after the message"},
    {Counter::kDroppedBadCount, "dropped.bad_count", "D, S, E, I",
     "input frames dropped: a count or a string beyond its bound"},
    {Counter::kDroppedBadFrame, "dropped.bad_frame", "D, S, E, I",
     "input frames dropped: a frame number no sender can produce (negative, beyond 2^48)"},
    {Counter::kDroppedBadTime, "dropped.bad_time", "D, S, E, I",
     "input frames dropped: a send time outside [0, 2^62) us"},
    {Counter::kDroppedBadWord, "dropped.bad_word", "D, S, E",
     "input frames dropped: a word the block's own checks refuse"},
    {Counter::kDroppedWordCount, "dropped.word_count", "E",
     "ESG frames dropped: a word count other than 1..64"},
    {Counter::kDroppedDuplicate, "dropped.duplicate", "D, S, E, I",
     "input frames dropped: a frame number seen before"},
    {Counter::kDroppedStale, "dropped.stale", "D, S, E, I",
     "input frames dropped: older than the last frame"},
    {Counter::kDroppedFarAhead, "dropped.far_ahead", "O, D, S, E, I",
     "frames dropped: a frame number beyond the session's clock"},
    {Counter::kDroppedLate, "dropped.late", "D, S, E",
     "frames dropped: waited too long to act on (docs/protocol.md \"Frame numbers and times\")"},
    {Counter::kDroppedOtherSession, "dropped.other_session", "O, D, S, E, I",
     "messages of another session (or of none) dropped (docs/protocol.md \"Senders\")"},
    {Counter::kDroppedOtherSender, "dropped.other_sender", "O, D, S, E, I",
     "an impostor's messages on a one-publisher channel dropped"},
    {Counter::kDroppedBadMac, "dropped.bad_mac", "O, D, S, E, I",
     "messages with the session's id whose tag is not the session key's dropped "
     "(docs/security.md \"Authenticated messages\")"},
    {Counter::kDroppedReplayed, "dropped.replayed", "O, D, I",
     "RMS_CONTROL commands dropped: taken before, or sent more than 30 s from now"},
    {Counter::kDroppedControlMalformed, "dropped.control_malformed", "O, D, I",
     "RMS_CONTROL messages that could not be decoded"},
    {Counter::kDroppedStatusMalformed, "dropped.status_malformed", "O, I",
     "RMS_STATUS messages that could not be decoded"},
    {Counter::kDroppedStatusRefused, "dropped.status_refused", "I",
     "RMS_STATUS messages whose process name or pid is not their sender's, or from a new process "
     "beyond the ones the station keeps (docs/instructor.md \"Bounds\")"},
    {Counter::kDroppedStateMalformed, "dropped.state_malformed", "I",
     "RMS_DCP_STATE messages that could not be decoded or whose checkpoint could not be read"},
    {Counter::kDroppedAnswerMalformed, "dropped.answer_malformed", "I",
     "RMS_CONTROL_ANSWER messages that could not be decoded"},
    {Counter::kDroppedTelemetryTooLarge, "dropped.telemetry_too_large", "O, I",
     "telemetry dropped: larger than any message of its type"},
    {Counter::kDroppedTelemetryWrongType, "dropped.telemetry_wrong_type", "O, I",
     "telemetry dropped: not of the channel's type (fingerprint)"},
    {Counter::kDroppedTelemetryTruncated, "dropped.telemetry_truncated", "O, I",
     "telemetry dropped: ended before the message did"},
    {Counter::kDroppedTelemetryTrailingBytes, "dropped.telemetry_trailing_bytes", "O, I",
     "telemetry dropped: bytes left after the message"},
    {Counter::kDroppedTelemetryBadCount, "dropped.telemetry_bad_count", "O, I",
     "telemetry dropped: a count or a string beyond its bound"},
    {Counter::kDroppedTelemetryFrame, "dropped.telemetry_frame", "O",
     "telemetry dropped: a frame number no sender can produce"},
    {Counter::kDroppedTelemetryTime, "dropped.telemetry_time", "O",
     "telemetry dropped: a send time outside [0, 2^62) us"},
    {Counter::kDroppedTelemetryMode, "dropped.telemetry_mode", "O",
     "telemetry dropped: a mode other than 1, 2, 3"},
    {Counter::kDroppedTelemetryCollisionBits, "dropped.telemetry_collision_bits", "O",
     "telemetry dropped: collision bits beyond the defined ones"},
    {Counter::kDroppedTelemetryNonFinite, "dropped.telemetry_non_finite", "O, I",
     "telemetry dropped: a number that is not finite"},
    {Counter::kDroppedWindowKeysTooLarge, "dropped.window_keys_too_large", "O",
     "the live window's keys dropped: larger than any message of its type"},
    {Counter::kDroppedWindowKeysWrongType, "dropped.window_keys_wrong_type", "O",
     "the live window's keys dropped: not of the channel's type (fingerprint)"},
    {Counter::kDroppedWindowKeysTruncated, "dropped.window_keys_truncated", "O",
     "the live window's keys dropped: ended before the message did"},
    {Counter::kDroppedWindowKeysTrailingBytes, "dropped.window_keys_trailing_bytes", "O",
     "the live window's keys dropped: bytes left after the message"},
    {Counter::kDroppedWindowKeysBadCount, "dropped.window_keys_bad_count", "O",
     "the live window's keys dropped: a count or a string beyond its bound"},
    {Counter::kDroppedWindowKeysStale, "dropped.window_keys_stale", "O",
     "the live window's keys dropped: older than the last"},
    {Counter::kDroppedOperatorStateTooLarge, "dropped.operator_state_too_large", "E",
     "the operator's state dropped: larger than any message of its type"},
    {Counter::kDroppedOperatorStateWrongType, "dropped.operator_state_wrong_type", "E",
     "the operator's state dropped: not of the channel's type (fingerprint)"},
    {Counter::kDroppedOperatorStateTruncated, "dropped.operator_state_truncated", "E",
     "the operator's state dropped: ended before the message did"},
    {Counter::kDroppedOperatorStateTrailingBytes, "dropped.operator_state_trailing_bytes", "E",
     "the operator's state dropped: bytes left after the message"},
    {Counter::kDroppedOperatorStateBadCount, "dropped.operator_state_bad_count", "E",
     "the operator's state dropped: a count or a string beyond its bound"},
    {Counter::kDroppedOperatorStateStale, "dropped.operator_state_stale", "E",
     "the operator's state dropped: older than the last"},
    {Counter::kDroppedOperatorStateNonFinite, "dropped.operator_state_non_finite", "E",
     "the operator's state dropped: a number that is not finite"},
    {Counter::kClampedShoulderYaw, "clamped.shoulder_yaw", "O, D, S",
     "values of shoulder_yaw clamped to its calibrated range (config [inputs.shoulder_yaw])"},
    {Counter::kClampedShoulderPitch, "clamped.shoulder_pitch", "O, D, S",
     "values of shoulder_pitch clamped to its calibrated range (config [inputs.shoulder_pitch])"},
    {Counter::kClampedElbowPitch, "clamped.elbow_pitch", "O, D, S",
     "values of elbow_pitch clamped to its calibrated range (config [inputs.elbow_pitch])"},
    {Counter::kClampedWristPitch, "clamped.wrist_pitch", "O, D, S",
     "values of wrist_pitch clamped to its calibrated range (config [inputs.wrist_pitch])"},
    {Counter::kClampedWristYaw, "clamped.wrist_yaw", "O, D, S",
     "values of wrist_yaw clamped to its calibrated range (config [inputs.wrist_yaw])"},
    {Counter::kClampedWristRoll, "clamped.wrist_roll", "O, D, S",
     "values of wrist_roll clamped to its calibrated range (config [inputs.wrist_roll])"},
    {Counter::kClampedFinger, "clamped.finger", "O, D, S",
     "values of finger clamped to its calibrated range (config [inputs.finger])"},
    {Counter::kClampedShoulderHeight, "clamped.shoulder_height", "O, D, S",
     "values of shoulder_height clamped to its calibrated range (config [inputs.shoulder_height])"},
    {Counter::kClampedCameraPan, "clamped.camera_pan", "O, D, S",
     "values of camera_pan clamped to its calibrated range (config [inputs.camera_pan])"},
    {Counter::kClampedCameraTilt, "clamped.camera_tilt", "O, D, S",
     "values of camera_tilt clamped to its calibrated range (config [inputs.camera_tilt])"},
    {Counter::kClampedCameraZoom, "clamped.camera_zoom", "O, D, S",
     "values of camera_zoom clamped to its calibrated range (config [inputs.camera_zoom])"},
    {Counter::kClampedCameraStation, "clamped.camera_station", "O, D",
     "camera stations outside 1..8 clamped"},
    {Counter::kClampedAdcShoulderYaw, "clamped.adc.shoulder_yaw", "D",
     "converter counts of shoulder_yaw clamped to ADC16"},
    {Counter::kClampedAdcShoulderPitch, "clamped.adc.shoulder_pitch", "D",
     "converter counts of shoulder_pitch clamped to ADC16"},
    {Counter::kClampedAdcElbowPitch, "clamped.adc.elbow_pitch", "D",
     "converter counts of elbow_pitch clamped to ADC16"},
    {Counter::kClampedAdcWristPitch, "clamped.adc.wrist_pitch", "D",
     "converter counts of wrist_pitch clamped to ADC16"},
    {Counter::kClampedAdcWristYaw, "clamped.adc.wrist_yaw", "D",
     "converter counts of wrist_yaw clamped to ADC16"},
    {Counter::kClampedAdcWristRoll, "clamped.adc.wrist_roll", "D",
     "converter counts of wrist_roll clamped to ADC16"},
    {Counter::kClampedAdcFinger, "clamped.adc.finger", "D",
     "converter counts of finger clamped to ADC16"},
    {Counter::kClampedAdcShoulderHeight, "clamped.adc.shoulder_height", "D",
     "converter counts of shoulder_height clamped to ADC16"},
    {Counter::kClampedAdcCameraPan, "clamped.adc.camera_pan", "D",
     "converter counts of camera_pan clamped to ADC16"},
    {Counter::kClampedAdcCameraTilt, "clamped.adc.camera_tilt", "D",
     "converter counts of camera_tilt clamped to ADC16"},
    {Counter::kClampedAdcCameraZoom, "clamped.adc.camera_zoom", "D",
     "converter counts of camera_zoom clamped to ADC16"},
    {Counter::kJointLimitShoulderYaw, "joint_limit.shoulder_yaw", "O",
     "hand-controller commands that met the limit of shoulder_yaw (config arm.joint_min_deg, "
     "joint_max_deg)"},
    {Counter::kJointLimitShoulderPitch, "joint_limit.shoulder_pitch", "O",
     "hand-controller commands that met the limit of shoulder_pitch (config arm.joint_min_deg, "
     "joint_max_deg)"},
    {Counter::kJointLimitElbowPitch, "joint_limit.elbow_pitch", "O",
     "hand-controller commands that met the limit of elbow_pitch (config arm.joint_min_deg, "
     "joint_max_deg)"},
    {Counter::kJointLimitWristPitch, "joint_limit.wrist_pitch", "O",
     "hand-controller commands that met the limit of wrist_pitch (config arm.joint_min_deg, "
     "joint_max_deg)"},
    {Counter::kJointLimitWristYaw, "joint_limit.wrist_yaw", "O",
     "hand-controller commands that met the limit of wrist_yaw (config arm.joint_min_deg, "
     "joint_max_deg)"},
    {Counter::kJointLimitWristRoll, "joint_limit.wrist_roll", "O",
     "hand-controller commands that met the limit of wrist_roll (config arm.joint_min_deg, "
     "joint_max_deg)"},
    {Counter::kSaturatedArm, "saturated.arm", "D, S",
     "values clamped to the range of their word format: arm"},
    {Counter::kSaturatedCameraZoom, "saturated.camera_zoom", "D, S",
     "values clamped to the range of their word format: camera_zoom"},
    {Counter::kSaturatedEye, "saturated.eye", "D, S",
     "values clamped to the range of their word format: eye"},
    {Counter::kSaturatedFingerGap, "saturated.finger_gap", "D, S",
     "values clamped to the range of their word format: finger_gap"},
    {Counter::kSaturatedPayloadPos, "saturated.payload_pos", "D, S",
     "values clamped to the range of their word format: payload_pos"},
    {Counter::kSaturatedPayloadRot, "saturated.payload_rot", "D, S",
     "values clamped to the range of their word format: payload_rot"},
    {Counter::kSaturatedPlane, "saturated.plane", "D, S",
     "values clamped to the range of their word format: plane"},
    {Counter::kSaturatedShoulderHeight, "saturated.shoulder_height", "D, S",
     "values clamped to the range of their word format: shoulder_height"},
    {Counter::kSaturatedView, "saturated.view", "D, S",
     "values clamped to the range of their word format: view"},
    {Counter::kFramesTotal, "frames.total", "O", "frames published"},
    {Counter::kFramesLate, "frames.late", "O, D, S, E",
     "O: frames published after their deadline; D, S, E: frames reaching the process more than a "
     "frame period after the operator sent them"},
    {Counter::kFramesHeld, "frames.held", "D",
     "frames the slave arm held its last collision-free pose"},
    {Counter::kFramesFingerHeld, "frames.finger_held", "D",
     "frames only the finger held (it stopped on the bar)"},
    {Counter::kFramesMotionHeld, "frames.motion_held", "D",
     "frames held because the motion between frames would collide"},
    {Counter::kFramesTooFast, "frames.too_fast", "D",
     "frames held because the motion needed more than 4096 substeps"},
    {Counter::kFramesEssentialContact, "frames.essential_contact", "D",
     "frames with the movable finger on the BAR (the essential contact)"},
    {Counter::kMode, "mode", "D", "the current mode (1, 2, 3)"},
    {Counter::kModeChanges, "mode_changes", "D", "mode changes"},
    {Counter::kCollisionsEffHex1Recpt, "collisions.eff_hex_1-recpt", "D",
     "collisions eff_hex_1-recpt begun"},
    {Counter::kCollisionsEffHex2Recpt, "collisions.eff_hex_2-recpt", "D",
     "collisions eff_hex_2-recpt begun"},
    {Counter::kCollisionsEffHex3Recpt, "collisions.eff_hex_3-recpt", "D",
     "collisions eff_hex_3-recpt begun"},
    {Counter::kCollisionsEffHex1Payload, "collisions.eff_hex_1-payload", "D",
     "collisions eff_hex_1-payload begun"},
    {Counter::kCollisionsEffHex2Payload, "collisions.eff_hex_2-payload", "D",
     "collisions eff_hex_2-payload begun"},
    {Counter::kCollisionsEffHex3Payload, "collisions.eff_hex_3-payload", "D",
     "collisions eff_hex_3-payload begun"},
    {Counter::kCollisionsPayloadBayA, "collisions.payload-bay_a", "D",
     "collisions payload-bay_a begun"},
    {Counter::kCollisionsPayloadBayB, "collisions.payload-bay_b", "D",
     "collisions payload-bay_b begun"},
    {Counter::kCollisionsPayloadBayC, "collisions.payload-bay_c", "D",
     "collisions payload-bay_c begun"},
    {Counter::kCollisionsPayloadBayD, "collisions.payload-bay_d", "D",
     "collisions payload-bay_d begun"},
    {Counter::kCollisionsPayloadBayE, "collisions.payload-bay_e", "D",
     "collisions payload-bay_e begun"},
    {Counter::kCollisionsPayloadBayF, "collisions.payload-bay_f", "D",
     "collisions payload-bay_f begun"},
    {Counter::kCollisionsPayloadCae, "collisions.payload-cae", "D", "collisions payload-cae begun"},
    {Counter::kCollisionsEffHexBarPost, "collisions.eff_hex-bar_post", "D",
     "collisions eff_hex-bar_post begun"},
    {Counter::kCollisionsNonFinite, "collisions.non-finite", "D", "collisions non-finite begun"},
    {Counter::kCollisionFramesEffHex1Recpt, "collision_frames.eff_hex_1-recpt", "D",
     "frames in collision eff_hex_1-recpt"},
    {Counter::kCollisionFramesEffHex2Recpt, "collision_frames.eff_hex_2-recpt", "D",
     "frames in collision eff_hex_2-recpt"},
    {Counter::kCollisionFramesEffHex3Recpt, "collision_frames.eff_hex_3-recpt", "D",
     "frames in collision eff_hex_3-recpt"},
    {Counter::kCollisionFramesEffHex1Payload, "collision_frames.eff_hex_1-payload", "D",
     "frames in collision eff_hex_1-payload"},
    {Counter::kCollisionFramesEffHex2Payload, "collision_frames.eff_hex_2-payload", "D",
     "frames in collision eff_hex_2-payload"},
    {Counter::kCollisionFramesEffHex3Payload, "collision_frames.eff_hex_3-payload", "D",
     "frames in collision eff_hex_3-payload"},
    {Counter::kCollisionFramesPayloadBayA, "collision_frames.payload-bay_a", "D",
     "frames in collision payload-bay_a"},
    {Counter::kCollisionFramesPayloadBayB, "collision_frames.payload-bay_b", "D",
     "frames in collision payload-bay_b"},
    {Counter::kCollisionFramesPayloadBayC, "collision_frames.payload-bay_c", "D",
     "frames in collision payload-bay_c"},
    {Counter::kCollisionFramesPayloadBayD, "collision_frames.payload-bay_d", "D",
     "frames in collision payload-bay_d"},
    {Counter::kCollisionFramesPayloadBayE, "collision_frames.payload-bay_e", "D",
     "frames in collision payload-bay_e"},
    {Counter::kCollisionFramesPayloadBayF, "collision_frames.payload-bay_f", "D",
     "frames in collision payload-bay_f"},
    {Counter::kCollisionFramesPayloadCae, "collision_frames.payload-cae", "D",
     "frames in collision payload-cae"},
    {Counter::kCollisionFramesEffHexBarPost, "collision_frames.eff_hex-bar_post", "D",
     "frames in collision eff_hex-bar_post"},
    {Counter::kCollisionFramesNonFinite, "collision_frames.non-finite", "D",
     "frames in collision non-finite"},
    {Counter::kResetsRefused, "resets.refused", "D",
     "resets refused: the arm's reset pose would collide"},
    {Counter::kInputsNonFinite, "inputs.non_finite", "D",
     "input blocks whose values were not finite: the last command held"},
    {Counter::kGraspsLetGo, "grasps.let_go", "D",
     "payloads let go by opening the finger before docking"},
    {Counter::kResumed, "resumed", "D",
     "this run resumed from the state file (docs/sessions.md \"Faults\")"},
    {Counter::kStateFileWrites, "state_file.writes", "D", "state file writes"},
    {Counter::kStateFileErrors, "state_file.errors", "D", "state file writes that failed"},
    {Counter::kStatePublished, "state.published", "D",
     "RMS_DCP_STATE messages sent (docs/protocol.md)"},
    {Counter::kControlFreezes, "control.freezes", "O", "freezes taken (RMS_CONTROL)"},
    {Counter::kControlRuns, "control.runs", "O", "runs taken"},
    {Counter::kControlSteps, "control.steps", "O",
     "STEP commands heard (each one of 1..100000 frames; refused while running)"},
    {Counter::kControlCheckpoints, "control.checkpoints", "D", "checkpoints saved"},
    {Counter::kControlRestores, "control.restores", "O, D", "restores taken"},
    {Counter::kControlResets, "control.resets", "O",
     "resets taken from RMS_CONTROL (the reset button pressed for one frame)"},
    {Counter::kControlRefused, "control.refused", "O, D",
     "checkpoint, restore, malfunction and repair commands refused (docs/security.md \"The "
     "control channel\")"},
    {Counter::kControlRateLimited, "control.rate_limited", "O, D",
     "checkpoint and restore commands beyond 2 a second; malfunction and repair commands beyond "
     "2 a second"},
    {Counter::kControlMalfunctions, "control.malfunctions", "D",
     "malfunctions injected (RMS_CONTROL MALFUNCTION; docs/sessions.md \"Malfunctions\")"},
    {Counter::kControlRepairs, "control.repairs", "D", "repairs taken (RMS_CONTROL REPAIR)"},
    {Counter::kNotFollowing, "arm.not_following", "O",
     "times a joint or the finger stopped following its command (a failure seen in the "
     "telemetry)"},
    {Counter::kFrozenInputsIgnored, "frozen.inputs_ignored", "O",
     "operator inputs ignored while frozen"},
    {Counter::kRestarted, "restarted", "O", "this run was a restart by the launcher"},
    {Counter::kKeyActions, "key_actions", "O", "key presses that acted"},
    {Counter::kIncrementsBlocked, "increments.blocked", "O",
     "key increments given up when the arm stalled (at a limit, a singularity or a hold)"},
    {Counter::kSingleJointPressesIgnored, "single_joint.presses_ignored", "O",
     "presses on a translation or rotation key in single-joint control"},
    {Counter::kCameraRefused, "camera.refused", "O",
     "camera stations asked for outside the bindings' camera set ([control] cameras)"},
    {Counter::kLessonEvents, "lesson.events", "O, I",
     "a lesson's scripted events sent (--lesson; the instructor's page)"},
    {Counter::kControlModeChanges, "control.mode_changes", "O",
     "changes between manual augmented and single-joint control"},
    {Counter::kControlFrameChanges, "control.frame_changes", "O", "changes of the command frame"},
    {Counter::kControlScaleChanges, "control.scale_changes", "O",
     "changes of the rate scale (coarse, vernier, fine)"},
    {Counter::kControlStops, "control.stops", "O", "stops of every motion (space)"},
    {Counter::kControlNulls, "control.nulls", "O",
     "axes flown to their guidance's 0 by the null keys (shift and the axis's key)"},
    {Counter::kControlSquareUps, "control.square_ups", "O",
     "square-ups: the guidance's whole turn flown in one rotation (h)"},
    {Counter::kControlUnwinds, "control.unwinds", "O",
     "unwinds: the wrist's joints flown to the middle of their travel (b)"},
    {Counter::kControlStows, "control.stows", "O",
     "stows: every joint flown back to where the session started it (z; Mode 1)"},
    {Counter::kJointNearLimit, "joint.near_limit", "O",
     "times a wrist joint came within 10 deg of a limit of its travel (warned)"},
    {Counter::kClearanceWarnings, "guidance.clearance_warnings", "O",
     "times the payload went, or a turn would take it, under 2 ft above the orbiter's sill line"},
    {Counter::kDeviceDisconnected, "device.disconnected", "O", "devices that went away"},
    {Counter::kTelemetryStale, "telemetry.stale", "O",
     "telemetry duplicated or older than the last taken"},
    {Counter::kTelemetryBeforeReset, "telemetry.before_reset", "O",
     "telemetry from before a reset ignored"},
    {Counter::kWindowKeysTimeouts, "window.keys_timeouts", "O",
     "the live window's held keys released after it fell silent"},
    {Counter::kAutopilotDocked, "autopilot.docked", "O", "the autopilot docked"},
    {Counter::kAutopilotCollisionsRelieved, "autopilot.collisions_relieved", "O",
     "collisions the autopilot relieved"},
    {Counter::kAutopilotGraspCorrections, "autopilot.grasp_corrections", "O",
     "the autopilot's corrections of the descent onto the bar"},
    {Counter::kAutopilotGraspRetries, "autopilot.grasp_retries", "O",
     "grasps the autopilot opened and tried again"},
    {Counter::kAutopilotDockCorrections, "autopilot.dock_corrections", "O",
     "the autopilot's corrections of the approach to the port"},
    {Counter::kAutopilotViaPoints, "autopilot.via_points", "O",
     "via points the autopilot planned around obstacles"},
    {Counter::kAutopilotUnplanned, "autopilot.unplanned", "O",
     "approaches with no clear path found: made through the stowed pose"},
    {Counter::kPriorityDynamicSearches, "priority.dynamic_searches", "S",
     "separating planes searched afresh (docs/scene.md)"},
    {Counter::kPriorityUnresolved, "priority.unresolved", "S",
     "cluster pairs no plane separated: ordered by distance"},
    {Counter::kPriorityCyclesBroken, "priority.cycles_broken", "E",
     "priority cycles broken when ordering clusters"},
    {Counter::kRendered, "rendered", "E", "frames rendered"},
    {Counter::kRenderedScenes, "rendered.scenes", "E", "scenes drawn (frames whose words changed)"},
    {Counter::kSkippedUnchanged, "skipped.unchanged", "E",
     "frames whose words did not change: the last image reused"},
    {Counter::kSuperseded, "superseded", "E",
     "frames overtaken by a newer one before they were drawn"},
    {Counter::kClustersDrawn, "clusters.drawn", "E", "clusters drawn"},
    {Counter::kClustersCulled, "clusters.culled", "E",
     "clusters outside the view volume, not drawn"},
    {Counter::kTrianglesSubmitted, "triangles.submitted", "E", "triangles sent to GL"},
    {Counter::kPngWritten, "png_written", "E", "PNG frames written"},
    {Counter::kPngFailed, "png_failed", "E", "PNG frames that could not be written"},
    {Counter::kVideoFrames, "video.frames", "E", "frames sent to the video encoder"},
    {Counter::kVideoDropped, "video.dropped", "E",
     "frames the video encoder could not take (docs/esg.md \"Video\")"},
    {Counter::kWindowFrames, "window.frames", "E", "frames shown in the live window"},
    {Counter::kWindowKeysMessages, "window.keys_messages", "E", "RMS_WINDOW_KEYS messages sent"},
    {Counter::kWindowKeysPressed, "window.keys_pressed", "E", "key presses in the live window"},
    {Counter::kViewsRendered, "views.rendered", "I",
     "camera stations' views rendered for the web page's viewers (docs/instructor.md)"},
    {Counter::kHttpRequests, "http.requests", "I", "web requests answered"},
    {Counter::kHttpRefused, "http.refused", "I",
     "web requests refused: no or a wrong token, a bad path or parameter (docs/security.md)"},
    {Counter::kControlSent, "control.sent", "I",
     "RMS_CONTROL commands sent from the web page (docs/instructor.md)"},
    {Counter::kJournalEvents, "journal.events", "O, D, S, E, I",
     "messages this run wrote whole to its journal, every channel (docs/sessions.md \"The "
     "record\")"},
    {Counter::kJournalFailed, "journal.failed", "O, D, S, E, I",
     "messages its journal could not hold (a full disk): the record has them only if the "
     "recorder heard them"},
}};

constexpr bool CounterTableInOrder() {
  for (int i = 0; i < kNumCounters; ++i) {
    if (static_cast<int>(kCounterTable[i].id) != i) return false;
  }
  return true;
}
static_assert(CounterTableInOrder(),
              "kCounterTable lists every Counter once, in the enumeration's order");

constexpr std::string_view CounterName(Counter c) {
  return kCounterTable[static_cast<int>(c)].name;
}
// The counter of that name, or nothing.
std::optional<Counter> CounterNamed(std::string_view name);
// The i-th member of a family that starts at `first`.
constexpr Counter CounterAt(Counter first, int i) {
  return static_cast<Counter>(static_cast<int>(first) + i);
}

// Every message dropped (dropped.*) and every input clamped (clamped.*):
// contiguous families, first through last, and their names' prefix.
inline constexpr Counter kDroppedFirst = Counter::kDroppedTooLarge;
inline constexpr Counter kDroppedLast = Counter::kDroppedOperatorStateNonFinite;
inline constexpr std::string_view kDroppedPrefix = "dropped.";
inline constexpr Counter kClampedFirst = Counter::kClampedShoulderYaw;
inline constexpr Counter kClampedLast = Counter::kClampedAdcCameraZoom;
inline constexpr std::string_view kClampedPrefix = "clamped.";
// Exactly the counters of [first, last] have names starting with prefix.
constexpr bool FamilyIsPrefix(Counter first, Counter last, std::string_view prefix) {
  for (int i = 0; i < kNumCounters; ++i) {
    const bool in = i >= static_cast<int>(first) && i <= static_cast<int>(last);
    if (in != (kCounterTable[i].name.substr(0, prefix.size()) == prefix)) return false;
  }
  return true;
}
static_assert(FamilyIsPrefix(kDroppedFirst, kDroppedLast, kDroppedPrefix));
static_assert(FamilyIsPrefix(kClampedFirst, kClampedLast, kClampedPrefix));
// clamped.INPUT and clamped.adc.INPUT for an analog input (AnalogInput).
constexpr Counter ClampedCounter(int input) {
  return CounterAt(Counter::kClampedShoulderYaw, input);
}
constexpr Counter ClampedAdcCounter(int input) {
  return CounterAt(Counter::kClampedAdcShoulderYaw, input);
}
// joint_limit.JOINT for the six joints (AnalogInput 0-5).
constexpr Counter JointLimitCounter(int joint) {
  return CounterAt(Counter::kJointLimitShoulderYaw, joint);
}

constexpr bool FamilyFollows(Counter first, std::string_view prefix,
                             const std::string_view* members, int count) {
  for (int i = 0; i < count; ++i) {
    const std::string_view n = CounterName(CounterAt(first, i));
    if (n.substr(0, prefix.size()) != prefix || n.substr(prefix.size()) != members[i]) return false;
  }
  return true;
}
static_assert(FamilyFollows(Counter::kClampedShoulderYaw, "clamped.", kAnalogInputNames.data(),
                            kNumAnalogInputs));
static_assert(FamilyFollows(Counter::kClampedAdcShoulderYaw, "clamped.adc.",
                            kAnalogInputNames.data(), kNumAnalogInputs));
static_assert(FamilyFollows(Counter::kJointLimitShoulderYaw, "joint_limit.",
                            kAnalogInputNames.data(), 6));

// A process's counters: one slot a counter. Only the counters it has touched
// (added to or set, even to 0) are reported.
class Counters {
 public:
  void Add(Counter c, std::int64_t n = 1) {
    values_[static_cast<int>(c)] += n;
    touched_.set(static_cast<int>(c));
  }
  void Set(Counter c, std::int64_t v) {
    values_[static_cast<int>(c)] = v;
    touched_.set(static_cast<int>(c));
  }
  std::int64_t Get(Counter c) const { return values_[static_cast<int>(c)]; }
  // The sum of a family's counters, first through last.
  std::int64_t Sum(Counter first, Counter last) const;
  // Adds every counter another keeps (a part's counters into its owner's).
  void AddAll(const Counters& other);
  // The touched counters by name, in name order: what RMS_STATUS and the
  // stats file carry.
  std::map<std::string, std::int64_t> ByName() const;

 private:
  std::array<std::int64_t, kNumCounters> values_{};
  std::bitset<kNumCounters> touched_;
};

// Latency (or any duration) samples in microseconds, in a fixed-size
// histogram: bounded memory for sessions of any length. 1 us bins below 1 ms,
// 10 us bins to 100 ms, 1 ms bins to 10 s, then one overflow bin.
class LatencyHistogram {
 public:
  LatencyHistogram();
  void Add(std::int64_t us);
  std::int64_t count() const { return count_; }
  // Percentile q in [0, 1], us: exact below 1 ms, within 5 us below 100 ms,
  // within 0.5 ms above; 0 when empty.
  double Percentile(double q) const;
  double max_us() const { return static_cast<double>(max_); }
  double mean_us() const { return count_ ? static_cast<double>(sum_) / count_ : 0.0; }
  void Reset();

 private:
  static int BinOf(std::int64_t us);
  static double Representative(int bin);
  std::vector<std::int64_t> bins_;
  std::int64_t count_ = 0;
  std::int64_t sum_ = 0;
  std::int64_t max_ = 0;
};

// Timing health (docs/sessions.md "Timing health"): a frame is late at a
// stage when it reaches it more than one frame period after the operator
// sent it. Adds the end-to-end latency to `histogram` and counts
// frames.late.
void RecordEndToEnd(std::int64_t latency_us, double frame_rate_hz, LatencyHistogram* histogram,
                    Counters* counters);

// The counter table as markdown (docs/sessions.md "Process counters").
std::string CounterTableMarkdown();

}  // namespace rms
