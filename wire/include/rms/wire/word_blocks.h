#pragma once
// Per-frame word blocks shared by two processes: the DCP's output block
// (dynamics_proc -> scene_proc) and the ESG frame (scene_proc ->
// esg_renderer). docs/protocol.md holds their word-by-word tables; this file
// implements them. Packing saturates and counts ("saturated.FIELD"); unpacking
// validates every word and throws rms::InputError naming the word on the first
// problem (the caller counts the message as malformed and drops it).
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "rms/arm/kinematics.h"
#include "rms/base/counters.h"
#include "rms/dcp_frame_t.hpp"
#include "rms/esg_frame_t.hpp"
#include "rms/scene_model/cluster_pairs.h"
#include "rms/scene_model/scene_model.h"
#include "rms/scene_model/separating_plane.h"
#include "rms/wire/control_word.h"
#include "rms/wire/word_codec.h"

namespace rms::wire {

// ---------------------------------------------------------------- DCP block

// state_words layout (docs/protocol.md "RMS_DCP_FRAME").
namespace dcp_state {
inline constexpr int kShoulderHeight = 0;  // FT12
inline constexpr int kFingerGap = 1;       // FT12
inline constexpr int kCameraPan = 2;       // BAM24
inline constexpr int kCameraTilt = 3;      // BAM24
inline constexpr int kCameraZoom = 4;      // SC22, 0..1
inline constexpr int kPayloadPos = 5;      // 3 x FT12
inline constexpr int kPayloadRot = 8;      // 9 x SC22, row-major
inline constexpr int kCount = 17;
}  // namespace dcp_state

struct DcpFrameData {
  std::int64_t frame = 0;
  std::int64_t send_time_us = 0;
  std::int64_t input_frame = 0;
  std::int64_t input_send_time_us = 0;
  arm::ArmSinCos arm{};  // arm words
  ControlWord control;   // priority bits zero
  std::array<scene_model::SeparatingPlane, 3> planes{};
  std::uint32_t plane_valid = 0;  // bit i: plane i+1 valid
  double shoulder_height_ft = 0.0;
  double finger_gap_ft = 0.0;
  double camera_pan_deg = 0.0;
  double camera_tilt_deg = 0.0;
  double camera_zoom = 0.0;  // 0 widest .. 1 narrowest
  Eigen::Vector3d p_RoPo_R_ft = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_RP = Eigen::Matrix3d::Identity();
};

void PackDcpFrame(const DcpFrameData& in, dcp_frame_t* out, Counters* counters);
DcpFrameData UnpackDcpFrame(const dcp_frame_t& msg);

// ---------------------------------------------------------------- ESG frame

inline constexpr int kEsgMaxWords =
    esg_frame_t::MAX_WORDS;  // the IEU's limit (report, Section III): 64

// Word indices of the ESG frame (docs/protocol.md "RMS_ESG_FRAME").
namespace esg_words {
inline constexpr int kFrameCount = 0;       // U24, frame number mod 2^24
inline constexpr int kControl = 1;          // control word, with priority bits
inline constexpr int kArm = 2;              // 12 x SC22: sin t1, cos t1, ... sin t6, cos t6
inline constexpr int kShoulderHeight = 14;  // FT12
inline constexpr int kFingerGap = 15;       // FT12
inline constexpr int kEye = 16;             // 3 x FT12, p_RoEye_R
inline constexpr int kView = 19;            // 9 x SC22, R_RE row-major
inline constexpr int kFov = 28;             // BAM24, vertical field of view
inline constexpr int kPayloadPos = 29;      // 3 x FT12, p_RoPo_R
inline constexpr int kPayloadRot = 32;      // 9 x SC22, R_RP row-major
// The scene's convex cluster pairs (rms/scene_model/cluster_pairs.h), one
// priority bit a pair: the DCP's 3 in the control word's PRIORITY_DYNAMIC
// bits, the next 7 in its PRIORITY_FIXED bits, the rest here, 24 a word.
inline constexpr int kPriorityBits = scene_model::kNumPairs - 3 - 7;  // 551
inline constexpr int kPriority = 41;  // BITS: visual-priority bits (docs/protocol.md)
inline constexpr int kPriorityCount = (kPriorityBits + 23) / 24;  // 23
inline constexpr int kCount =
    kPriority + kPriorityCount;  // 64 words used; the frame carries exactly these
// Bits of the last priority word beyond the pair bits: must be zero.
inline constexpr std::uint32_t kLastPriorityWordMask =
    (1u << (kPriorityBits - 24 * (kPriorityCount - 1))) - 1;
}  // namespace esg_words
static_assert(esg_words::kCount <= kEsgMaxWords);

struct EsgFrameData {
  std::uint32_t frame_count = 0;
  ControlWord control;
  arm::ArmSinCos arm{};
  double shoulder_height_ft = 0.0;
  double finger_gap_ft = 0.0;
  Eigen::Vector3d p_RoEye_R_ft = Eigen::Vector3d::Zero();  // viewpoint
  Eigen::Matrix3d R_RE =
      Eigen::Matrix3d::Identity();  // eye frame: X line of sight, Y right, Z down
  double fov_deg = 45.0;            // vertical field of view
  Eigen::Vector3d p_RoPo_R_ft = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_RP = Eigen::Matrix3d::Identity();
  // Visual-priority bits beyond the control word's ten (rms/wire/priority_words.h).
  std::array<std::int32_t, esg_words::kPriorityCount> priority_words{};
  // The pose of every moving part the frame carries: what the scene's
  // clusters are posed from (ComputeClusterPoses).
  scene_model::ScenePose scene_pose() const {
    return {arm, shoulder_height_ft, finger_gap_ft, p_RoPo_R_ft, R_RP};
  }
};

std::vector<std::int32_t> PackEsgWords(const EsgFrameData& in, Counters* counters);
// Validates: count, 24-bit words, control word, arm pairs on the unit circle
// (|norm - 1| <= 1e-3), rotations orthonormal within 1e-3, fov in (0, 180).
EsgFrameData UnpackEsgWords(std::span<const std::int32_t> words);

}  // namespace rms::wire
