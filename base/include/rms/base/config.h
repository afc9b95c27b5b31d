#pragma once
// The experimenter's configuration file (the report's Section VI,
// "Operational modifications": the physical characteristics of every
// component). docs/config.md documents every key with meaning and unit;
// config/rmslab.toml is the default. Loading validates everything and refuses
// the file with the key and the reason (rms::InputError) on the first problem,
// unknown keys included.
#include <Eigen/Geometry>
#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "rms/base/analog_inputs.h"

namespace rms {

// [session]
struct SessionConfig {
  double frame_rate_hz = 0;  // operator / DCP / scene frame rate, Hz
};

// [shuttle]: the cargo bay's box model in Reference coordinates. The bay's
// top face c is the plane z = 0; it spans x in [0, bay_length], y in
// [-bay_width/2, bay_width/2], z in [-bay_depth, 0].
struct ShuttleConfig {
  double bay_length_ft = 0;
  double bay_width_ft = 0;
  double bay_depth_ft = 0;
  double door_open_deg = 0;  // payload-bay doors' opening angle (rendering)
};

// [arm]: the vertical fixed arm and the booms. docs/kinematics.md.
struct ArmGeometry {
  Eigen::Vector3d p_RoB_R_ft = Eigen::Vector3d::Zero();  // foot B of the vertical fixed arm, in R
  double upper_boom_ft = 0;                              // shoulder S to elbow E
  double lower_boom_ft = 0;                              // elbow E to wrist W
  double wrist_to_palm_ft = 0;                           // wrist W to point A (System Two origin)
  double boom_diameter_ft = 0;                           // rendering
  // The joints' travel, shoulder yaw .. wrist roll, deg (the arm as flown:
  // docs/config.md). The operator station's motions (hand controllers,
  // autopilot) stop a joint at its limit and say so; the DCP takes what it is
  // given (its inputs' ranges are [inputs.*]).
  std::array<double, 6> joint_min_deg{};
  std::array<double, 6> joint_max_deg{};
};

// [end_effector]: EFF HEX 1 (palm) and the fingers, System Two dimensions.
// The report's W and H are half-dimensions (v1 = A - W UY2 - H UZ2).
struct EndEffectorConfig {
  double palm_length_ft = 0;        // L of EFF HEX 1, along X2 from A
  double palm_half_width_ft = 0;    // W of EFF HEX 1, along Y2
  double palm_half_height_ft = 0;   // H of EFF HEX 1, along Z2
  double finger_length_ft = 0;      // EFF HEX 2/3 extent beyond the palm along X2
  double finger_thickness_ft = 0;   // EFF HEX 2/3 thickness along Y2
  double finger_gap_open_ft = 0;    // gap between faces b (HEX 2) and e (HEX 3), finger lever 0
  double finger_gap_closed_ft = 0;  // the same gap, finger lever 1 (fully closed)
};

// [payload]: the payload body, its bar receptacle (BAR / RECPT) and docking
// probe; pose in the cargo bay during Mode 1. Payload frame P: origin at the
// body's centre, y_P along the long axis toward the probe, z_P toward the
// receptacle.
struct PayloadConfig {
  double diameter_ft = 0;
  double length_ft = 0;
  double probe_diameter_ft = 0;
  double probe_length_ft = 0;
  Eigen::Vector3d p_RoPo_R_ft = Eigen::Vector3d::Zero();  // body centre in the bay (Mode 1)
  Eigen::Matrix3d R_RP = Eigen::Matrix3d::Identity();     // from y_axis, z_axis
  // The bar receptacle (BAR), a box in P: centre, and extents along x_P, y_P, z_P.
  Eigen::Vector3d p_PoBar_P_ft = Eigen::Vector3d::Zero();
  Eigen::Vector3d bar_size_P_ft = Eigen::Vector3d::Zero();
};

// [cae]: the space-station central assembly element, a hexagonal prism; its
// docking port is on face c. CAE frame C: origin at the port's centre, y_C
// into the CAE along the port axis, z_C along the module's long axis.
struct CaeConfig {
  Eigen::Vector3d p_RoCo_R_ft = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_RC = Eigen::Matrix3d::Identity();  // from y_axis, z_axis
  double across_flats_ft = 0;
  double length_ft = 0;
  double port_diameter_ft = 0;
};

// Opening the finger this far past its gap at acquisition lets the payload
// go (docs/collision.md "The finger after acquisition"); D3Y must leave room
// for it below the open gap.
inline constexpr double kReleaseOpeningFt = 0.05;

// [dcp]: the Dynamic Collision Program's selected values (report IV.A.3).
struct DcpConfig {
  double d3y_ft = 0;   // D3Y: acquisition needs the finger gap below this
  double tpob_ft = 0;  // TPOB: acquisition needs EFF HEX 1's face d within this of the BAR's face c
  double dock_distance_ft = 0;  // docking: port centre to probe tip centre at most this
  double dock_angle_deg =
      0;  // docking: angle between the probe's and the port's y axes at most this
};

// [[cameras]]: one of the eight camera stations. docs/scene.md.
enum class CameraMount { kShuttle, kElbow, kWrist, kCae };
struct CameraStationConfig {
  std::string name;
  CameraMount mount = CameraMount::kShuttle;
  Eigen::Vector3d p_MoCam_M_ft = Eigen::Vector3d::Zero();  // position in the mount frame
  Eigen::Vector3d p_MoAim_M_ft = Eigen::Vector3d::Zero();  // default aim point, mount frame
  double pan_min_deg = 0, pan_max_deg = 0;
  double tilt_min_deg = 0, tilt_max_deg = 0;
  double fov_min_deg = 0, fov_max_deg = 0;         // vertical field of view at zoom 1 and 0
  double pan_rate_deg_s = 0, tilt_rate_deg_s = 0;  // the camera drive's slew rates
  double zoom_rate_per_s = 0;                      // zoom lever travel per second
};

struct LabConfig {
  std::string source;  // file the configuration came from
  SessionConfig session;
  ShuttleConfig shuttle;
  ArmGeometry arm;
  EndEffectorConfig end_effector;
  PayloadConfig payload;
  CaeConfig cae;
  DcpConfig dcp;
  InputCalibrations inputs;
  std::vector<CameraStationConfig> cameras;  // exactly kNumCameraStations
};

// The camera stations (docs/scene.md): their one count. The control word
// carries the station in 3 bits (rms/wire/control_word.h), which
// static_asserts that the count fits.
inline constexpr int kNumCameraStations = 8;

// Every key of the file is required: config/rmslab.toml is the one place
// the default values live (documented in docs/config.md).
// Loads and validates; throws rms::InputError "FILE: key 'a.b': reason".
LabConfig LoadConfig(const std::string& path);
LabConfig ParseConfig(std::string_view toml_text, const std::string& source);

// The built-in default path (config/rmslab.toml of the source tree), used
// when a process is given no --config.
std::string DefaultConfigPath();

}  // namespace rms
