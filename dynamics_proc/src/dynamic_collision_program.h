#pragma once
// The DYNAMIC COLLISION PROGRAM (report, Section IV): each frame it processes
// the operator's inputs (IV.B), computes the sines and cosines of the six arm
// angles (the block of 12 words), the arm's pose in Reference coordinates,
// the payload's pose, and the scene generator control word.
//
// Section IV.A (hexahedron collision detection, separating planes,
// acquisition, extraction, docking) plugs in at UpdateModes(); until it does
// the program stays in Mode 1 with no collisions and no separating planes,
// and Reset returns it there.
#include <cstdint>

#include <Eigen/Geometry>

#include "rms/arm_kinematics.h"
#include "rms/config.h"
#include "rms/input_block.h"
#include "rms/word_blocks.h"

namespace rms::dcp {

class DynamicCollisionProgram {
 public:
  explicit DynamicCollisionProgram(const LabConfig& config);

  // One frame. The returned block's frame / time fields are left for the caller.
  DcpFrameData Step(const OperatorInputs& in);

  // Back to the Acquisition Phase (Mode 1), payload in the cargo bay.
  void Reset();

  int mode() const { return mode_; }
  // The arm pose of the last Step, computed from the transmitted arm words.
  const ArmPose& arm_pose() const { return pose_; }
  const Eigen::Isometry3d& X_RP() const { return X_RP_; }

  // The finger gap for a finger lever value (0 open .. 1 closed), ft:
  // the distance between face b of EFF HEX 2 and face e of EFF HEX 3.
  double FingerGapFt(double lever) const;

 private:
  void UpdateModes(const OperatorInputs& in);

  const LabConfig& config_;
  int mode_ = 1;
  Eigen::Isometry3d X_RP_bay_;  // payload in the cargo bay (Mode 1)
  Eigen::Isometry3d X_RP_;      // payload now
  ArmPose pose_{};
};

// The arm words as transmitted: sin/cos of the angles (deg), rounded to SC22
// and read back. The DCP, the scene and the ESG all use these values.
ArmSinCos TransmittedArmWords(const std::array<double, 6>& angles_deg);

}  // namespace rms::dcp
