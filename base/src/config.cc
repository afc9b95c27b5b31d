#include "rms/base/config.h"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <toml++/toml.h>

#include "rms/base/check.h"
#include "rms/base/text.h"
#include "rms/base/toml_reader.h"

#include "config_table.h"

#ifndef RMSLAB_DEFAULT_CONFIG
#error "RMSLAB_DEFAULT_CONFIG must be defined by the build"
#endif

namespace rms {

using TableReader = TomlReader;

std::string DefaultConfigPath() { return RMSLAB_DEFAULT_CONFIG; }

namespace {

CameraMount ParseMount(TableReader& r) {
  const std::string m = r.String("mount");
  if (m == "shuttle") return CameraMount::kShuttle;
  if (m == "elbow") return CameraMount::kElbow;
  if (m == "wrist") return CameraMount::kWrist;
  if (m == "cae") return CameraMount::kCae;
  r.Fail("mount", "must be one of \"shuttle\", \"elbow\", \"wrist\", \"cae\"; got \"" + m + "\"");
}

// Bounds on the physical keys (docs/config.md "Bounds"): what the models
// and the wire hold, with room for any design a lab would try. The 24-bit
// FT12 word holds +-2048 ft; a position is kept within kMaxPositionFt so the
// arm's reach and the models around it stay within it.
constexpr double kMaxPositionFt = 1000.0;  // any coordinate of a base, payload, port
constexpr double kMaxSceneFt = 200.0;      // a cargo bay's or the CAE's extent
constexpr double kMaxBoomFt = 100.0;       // a boom: twice the flown arm's 50 ft 3 in
constexpr double kMaxWristFt = 20.0;       // wrist to palm
constexpr double kMaxPartFt = 10.0;        // the end effector's parts, the boom's diameter
constexpr double kMaxProbeFt = 20.0;       // the payload's docking probe
constexpr double kMaxTpobFt = 5.0;         // TPOB
constexpr double kMaxDockDistanceFt = 10.0;

// [session]
void ReadSession(TableReader& top, LabConfig* config) {
  LabConfig& c = *config;
  TableReader r = top.Sub("session");
  c.session.frame_rate_hz = r.Number("frame_rate_hz", 1.0, 1000.0);
  r.Finish();
}

// [shuttle]: the cargo bay
void ReadShuttle(TableReader& top, LabConfig* config) {
  LabConfig& c = *config;
  TableReader r = top.Sub("shuttle");
  c.shuttle.bay_length_ft = r.Positive("bay_length_ft", kMaxSceneFt);
  c.shuttle.bay_width_ft = r.Positive("bay_width_ft", kMaxSceneFt);
  c.shuttle.bay_depth_ft = r.Positive("bay_depth_ft", kMaxSceneFt);
  c.shuttle.door_open_deg = r.Number("door_open_deg", 0.0, 180.0);
  r.Finish();
}

// [arm]: the vertical fixed arm, the booms, the joints' travel
void ReadArm(TableReader& top, LabConfig* config) {
  LabConfig& c = *config;
  TableReader r = top.Sub("arm");
  c.arm.p_RoB_R_ft = r.Vec3("base_position_ft", kMaxPositionFt);
  c.arm.upper_boom_ft = r.Positive("upper_boom_ft", kMaxBoomFt);
  c.arm.lower_boom_ft = r.Positive("lower_boom_ft", kMaxBoomFt);
  c.arm.wrist_to_palm_ft = r.Positive("wrist_to_palm_ft", kMaxWristFt);
  c.arm.boom_diameter_ft = r.Positive("boom_diameter_ft", kMaxPartFt);
  const std::vector<double> lo = r.Numbers("joint_min_deg", 6, -180.0, 180.0);
  const std::vector<double> hi = r.Numbers("joint_max_deg", 6, -180.0, 180.0);
  for (int i = 0; i < kNumJoints; ++i) {
    if (!(lo[i] < hi[i])) {
      r.Fail("joint_max_deg", "joint " + std::to_string(i + 1) + " (" +
                                  std::string(kAnalogInputNames[i]) + "): max " +
                                  FormatNumber(hi[i]) + " must be greater than min " +
                                  FormatNumber(lo[i]));
    }
    c.arm.joint_min_deg[i] = lo[i];
    c.arm.joint_max_deg[i] = hi[i];
  }
  r.Finish();
}

// [end_effector]: EFF HEX 1-3
void ReadEndEffector(TableReader& top, LabConfig* config) {
  LabConfig& c = *config;
  TableReader r = top.Sub("end_effector");
  auto& e = c.end_effector;
  e.palm_length_ft = r.Positive("palm_length_ft", kMaxPartFt);
  e.palm_half_width_ft = r.Positive("palm_half_width_ft", kMaxPartFt);
  e.palm_half_height_ft = r.Positive("palm_half_height_ft", kMaxPartFt);
  e.finger_length_ft = r.Positive("finger_length_ft", kMaxPartFt);
  e.finger_thickness_ft = r.Positive("finger_thickness_ft", kMaxPartFt);
  e.finger_gap_open_ft = r.Positive("finger_gap_open_ft", kMaxPartFt);
  e.finger_gap_closed_ft = r.Number("finger_gap_closed_ft", 0.0, kMaxPartFt);
  if (e.finger_gap_closed_ft >= e.finger_gap_open_ft) {
    r.Fail("finger_gap_closed_ft", "must be less than end_effector.finger_gap_open_ft");
  }
  if (e.finger_gap_open_ft + 2 * e.finger_thickness_ft > 2 * e.palm_half_width_ft + 1e-9) {
    r.Fail("finger_gap_open_ft",
           "the open fingers (gap + 2 x finger_thickness_ft) must fit within the palm's width "
           "(2 x palm_half_width_ft)");
  }
  r.Finish();
}

// [payload]: the body, the BAR, the probe
void ReadPayload(TableReader& top, LabConfig* config) {
  LabConfig& c = *config;
  TableReader r = top.Sub("payload");
  auto& p = c.payload;
  // The payload rides in the bay in Mode 1: it must fit in it.
  p.diameter_ft = r.Positive("diameter_ft", c.shuttle.bay_width_ft);
  p.length_ft = r.Positive("length_ft", c.shuttle.bay_length_ft);
  p.probe_diameter_ft = r.Positive("probe_diameter_ft", kMaxProbeFt);
  if (p.probe_diameter_ft >= p.diameter_ft)
    r.Fail("probe_diameter_ft", "must be less than payload.diameter_ft");
  p.probe_length_ft = r.Positive("probe_length_ft", kMaxProbeFt);
  p.p_RoPo_R_ft = r.Vec3("position_ft", kMaxPositionFt);
  p.R_RP = r.Rotation("y_axis", "z_axis");
  p.p_PoBar_P_ft = r.Vec3("bar_center_ft", kMaxSceneFt);
  p.bar_size_P_ft = r.Vec3("bar_size_ft", kMaxPartFt);
  for (int i = 0; i < 3; ++i) {
    if (!(p.bar_size_P_ft[i] > 0)) r.Fail("bar_size_ft", "every extent must be > 0");
  }
  r.Finish();
}

// [cae]: the central assembly element and its port
void ReadCae(TableReader& top, LabConfig* config) {
  LabConfig& c = *config;
  TableReader r = top.Sub("cae");
  auto& a = c.cae;
  a.p_RoCo_R_ft = r.Vec3("port_position_ft", kMaxPositionFt);
  a.R_RC = r.Rotation("y_axis", "z_axis");
  a.across_flats_ft = r.Positive("across_flats_ft", kMaxSceneFt);
  a.length_ft = r.Positive("length_ft", kMaxSceneFt);
  a.port_diameter_ft = r.Positive("port_diameter_ft", a.across_flats_ft);
  r.Finish();
}

// [dcp]: D3Y, TPOB and the docking tolerances, checked against the end effector and the BAR
void ReadDcp(TableReader& top, LabConfig* config) {
  LabConfig& c = *config;
  TableReader r = top.Sub("dcp");
  c.dcp.d3y_ft = r.Positive("d3y_ft", kMaxPartFt);
  c.dcp.tpob_ft = r.Positive("tpob_ft", kMaxTpobFt);
  c.dcp.dock_distance_ft = r.Positive("dock_distance_ft", kMaxDockDistanceFt);
  c.dcp.dock_angle_deg = r.Number("dock_angle_deg", 0.0, 90.0, true);
  if (c.dcp.d3y_ft <= c.end_effector.finger_gap_closed_ft) {
    r.Fail("d3y_ft",
           "must be greater than end_effector.finger_gap_closed_ft, or no gap could satisfy it");
  }
  // The finger must close onto the bar within D3Y, and open past it to let go.
  const double bar_width = c.payload.bar_size_P_ft.y();
  if (c.dcp.d3y_ft <= bar_width) {
    r.Fail("d3y_ft", "must be greater than the bar's width (payload.bar_size_ft[1] = " +
                         HumanNumber(bar_width) +
                         " ft), or the finger could never close onto the bar within D3Y: "
                         "acquisition impossible");
  }
  if (c.dcp.d3y_ft + kReleaseOpeningFt > c.end_effector.finger_gap_open_ft) {
    r.Fail("d3y_ft", "must be at most end_effector.finger_gap_open_ft - 0.05 ft (" +
                         HumanNumber(c.end_effector.finger_gap_open_ft - kReleaseOpeningFt) +
                         "), or opening the finger could not let the payload go");
  }
  if (c.end_effector.finger_gap_closed_ft >= bar_width) {
    r.Fail(
        "d3y_ft",
        "needs end_effector.finger_gap_closed_ft below the bar's width (payload.bar_size_ft[1] = " +
            HumanNumber(bar_width) + " ft), or the finger could not close onto the bar");
  }
  r.Finish();
}

// [inputs.NAME]: each analog input's calibration
void ReadInputs(TableReader& top, LabConfig* config) {
  LabConfig& c = *config;
  TableReader inputs = top.Sub("inputs");
  for (int i = 0; i < kNumAnalogInputs; ++i) {
    TableReader r = inputs.Sub(kAnalogInputNames[i]);
    InputCalibration& cal = c.inputs[i];
    cal.unit = r.String("unit");
    cal.units_per_count = r.Number("units_per_count", -1e6, 1e6);
    if (cal.units_per_count == 0.0) r.Fail("units_per_count", "must not be zero");
    cal.zero_count = r.Number("zero_count", -32768.0, 32767.0);
    cal.min = r.Number("min", -1e6, 1e6);
    cal.max = r.Number("max", -1e6, 1e6);
    if (!(cal.min < cal.max)) r.Fail("max", "must be greater than min");
    cal.initial = r.Number("initial", cal.min, cal.max);
    // The range must be reachable by the 15-bit-plus-sign converter.
    for (double v : {cal.min, cal.max}) {
      const double counts = v / cal.units_per_count + cal.zero_count;
      if (counts < -32768.5 || counts > 32767.5) {
        r.Fail(v == cal.min ? "min" : "max",
               "value " + FormatNumber(v) + " needs " + FormatNumber(counts) +
                   " counts, outside the ADC's [-32768, 32767]; change units_per_count");
      }
    }
    r.Finish();
  }
  inputs.Finish();
}

// [[cameras]]: the eight camera stations
void ReadCameras(TableReader& top, LabConfig* config) {
  LabConfig& c = *config;
  const toml::array* cams = top.Array("cameras");
  if (cams->size() != kNumCameraStations) {
    top.Fail("cameras", "must list exactly " + std::to_string(kNumCameraStations) +
                            " camera stations ([[cameras]] tables), got " +
                            std::to_string(cams->size()));
  }
  int i = 0;
  for (const toml::node& n : *cams) {
    ++i;
    const toml::table* t = n.as_table();
    // Indexed from 0, as a TOML path and `--set cameras[2].tilt_deg=...`
    // name it (station i is cameras[i - 1]).
    const std::string path = "cameras[" + std::to_string(i - 1) + "]";
    if (t == nullptr) top.Fail("cameras", "entry " + std::to_string(i - 1) + " must be a table");
    TableReader r(t, path, &c.source);
    CameraStationConfig cam;
    cam.name = r.String("name");
    cam.mount = ParseMount(r);
    cam.p_MoCam_M_ft = r.Vec3("position_ft");
    cam.p_MoAim_M_ft = r.Vec3("aim_at_ft");
    const Eigen::Vector3d look = cam.p_MoAim_M_ft - cam.p_MoCam_M_ft;
    if (look.norm() < 1e-3) r.Fail("aim_at_ft", "must differ from position_ft");
    if (std::abs(look.normalized().z()) > 0.999) {
      r.Fail("aim_at_ft", "the default aim must not be along the mount's z axis (the camera's up)");
    }
    std::tie(cam.pan_min_deg, cam.pan_max_deg) = r.Range("pan_deg", -180.0, 180.0);
    std::tie(cam.tilt_min_deg, cam.tilt_max_deg) = r.Range("tilt_deg", -89.0, 89.0);
    std::tie(cam.fov_min_deg, cam.fov_max_deg) = r.Range("fov_deg", 1.0, 120.0);
    const std::vector<double> rates = r.Numbers("rates", 3, 0.0, 1000.0);
    if (!(rates[0] > 0 && rates[1] > 0 && rates[2] > 0)) {
      r.Fail("rates", "[pan deg/s, tilt deg/s, zoom 1/s] must all be > 0");
    }
    cam.pan_rate_deg_s = rates[0];
    cam.tilt_rate_deg_s = rates[1];
    cam.zoom_rate_per_s = rates[2];
    r.Finish();
    c.cameras.push_back(std::move(cam));
  }
}

}  // namespace

namespace internal {

LabConfig ConfigFromTable(toml::table* root, const std::string& source) {
  LabConfig c;
  c.source = source;
  TableReader top(root, "", &c.source);
  // In the file's order; [dcp] is checked against [end_effector] and [payload].
  for (auto read : {ReadSession, ReadShuttle, ReadArm, ReadEndEffector, ReadPayload, ReadCae,
                    ReadDcp, ReadInputs, ReadCameras}) {
    read(top, &c);
  }
  top.Finish();
  return c;
}

}  // namespace internal

LabConfig ParseConfig(std::string_view text, const std::string& source) {
  toml::table root = ParseToml(text, source);
  return internal::ConfigFromTable(&root, source);
}

LabConfig LoadConfig(const std::string& path) {
  return ParseConfig(ReadTextFile(path, "the configuration file"), path);
}

}  // namespace rms
