#include "rms/session/export_csv.h"

#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <memory>

#include "rms/base/check.h"
#include "rms/base/config.h"
#include "rms/base/folder_file.h"
#include "rms/base/text.h"
#include "rms/control_answer_t.hpp"
#include "rms/dcp_frame_t.hpp"
#include "rms/dcp_state_t.hpp"
#include "rms/dcp_telemetry_t.hpp"
#include "rms/esg_frame_t.hpp"
#include "rms/operator_input_t.hpp"
#include "rms/operator_state_t.hpp"
#include "rms/process_status_t.hpp"
#include "rms/session/session_folder.h"
#include "rms/session/session_log.h"
#include "rms/session_control_t.hpp"
#include "rms/window_keys_t.hpp"
#include "rms/wire/acquisition_conditions.h"
#include "rms/wire/channels.h"
#include "rms/wire/control_word.h"
#include "rms/wire/input_block.h"
#include "rms/wire/message_io.h"
#include "rms/wire/word_blocks.h"

namespace fs = std::filesystem;

namespace rms::session {

namespace {

// One CSV file: a header row of "name [unit]" columns, then rows; written
// to a temporary file of the export's folder (OutputFolder), in blocks.
class Csv {
 public:
  Csv(OutputFolder* folder, const std::string& name, const std::vector<std::string>& columns)
      : folder_(folder),
        path_(fs::path(folder->path()) / name),
        fd_(folder->Begin(name)),
        n_(columns.size()) {
    Row(columns);
  }
  void Row(const std::vector<std::string>& cells) {
    RMS_CHECK(cells.size() == n_);
    for (std::size_t i = 0; i < cells.size(); ++i) {
      if (i) buf_ += ',';
      buf_ += CsvField(cells[i]);
    }
    buf_ += '\n';
    ++rows_;
    if (buf_.size() >= kFlushBytes) Flush();
  }
  long rows() const { return rows_ - 1; }
  const fs::path& path() const { return path_; }
  // Writes what is left and closes; throws when any of it could not be
  // written (a full disk): the export must not end as if it had.
  void Close() {
    Flush();
    folder_->Close(fd_);
  }

 private:
  static constexpr std::size_t kFlushBytes = std::size_t{1} << 20;
  void Flush() {
    std::size_t done = 0;
    while (done < buf_.size()) {
      const ssize_t n = ::write(fd_, buf_.data() + done, buf_.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0)
        throw InputError("could not write all of '" + path_.string() + "' (" +
                         std::strerror(n < 0 ? errno : EIO) + ")");
      done += static_cast<std::size_t>(n);
    }
    buf_.clear();
  }
  OutputFolder* folder_;
  fs::path path_;
  int fd_;
  std::size_t n_;
  std::string buf_;
  long rows_ = 0;
};

// The shortest text that reads back as exactly v.
std::string N(double v) {
  char buf[40];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}
std::string I(std::int64_t v) { return std::to_string(v); }
std::string B(bool v) { return v ? "1" : "0"; }

double Deg(const arm::SinCos& a) { return std::atan2(a.s, a.c) * 180.0 / M_PI; }

void Add(std::vector<std::string>* v, std::initializer_list<std::string> xs) {
  v->insert(v->end(), xs);
}

std::vector<std::string> ControlColumns(const std::string& p) {
  return {p + "camera_station",       p + "reset",    p + "overlay", p + "mode", p + "collision",
          p + "receptacle_collision", p + "acquired", p + "docked"};
}
void ControlCells(std::vector<std::string>* v, const wire::ControlWord& c) {
  Add(v, {I(c.camera_station), B(c.reset), B(c.overlay), I(c.mode), B(c.collision),
          B(c.receptacle_collision), B(c.acquired), B(c.docked)});
}
// The joints' angle columns, "shoulder_yaw [deg]" ..., from the inputs' names.
std::vector<std::string> AngleColumns(const std::string& prefix = "") {
  std::vector<std::string> v;
  for (int j = 0; j < kNumJoints; ++j)
    v.push_back(prefix + std::string(kAnalogInputNames[j]) + " [deg]");
  return v;
}

std::vector<std::string> Vec3Columns(const std::string& name, const std::string& unit) {
  return {name + "_x [" + unit + "]", name + "_y [" + unit + "]", name + "_z [" + unit + "]"};
}
std::vector<std::string> MatColumns(const std::string& name) {
  std::vector<std::string> v;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) v.push_back(name + "_" + std::to_string(r) + std::to_string(c));
  }
  return v;
}

// The columns of each channel's file, units in brackets.
std::vector<std::string> InputColumns(const LabConfig& config) {
  std::vector<std::string> cols = {"log_time [us]", "session_time [s]", "frame", "send_time [us]"};
  for (int i = 0; i < kNumAnalogInputs; ++i) {
    cols.push_back(std::string(kAnalogInputNames[i]) + " [" + config.inputs[i].unit + "]");
  }
  Add(&cols, {"camera_station", "reset", "overlay"});
  return cols;
}

void AddPlaneColumns(std::vector<std::string>* cols) {
  for (int k = 1; k <= 3; ++k) {
    const std::string p = "plane" + std::to_string(k);
    Add(cols, {p + "_valid", p + "_n_x", p + "_n_y", p + "_n_z", p + "_d [ft]"});
  }
}

void AddPoseColumns(std::vector<std::string>* cols, const std::string& p, const std::string& R) {
  for (const auto& c : Vec3Columns(p, "ft")) cols->push_back(c);
  for (const auto& c : MatColumns(R)) cols->push_back(c);
}

std::vector<std::string> DcpColumns() {
  std::vector<std::string> cols = {"log_time [us]",  "session_time [s]", "frame",
                                   "send_time [us]", "input_frame",      "input_send_time [us]"};
  for (const auto& c : AngleColumns()) cols.push_back(c);
  for (const auto& c : ControlColumns("")) cols.push_back(c);
  AddPlaneColumns(&cols);
  Add(&cols, {"shoulder_height [ft]", "finger_gap [ft]", "camera_pan [deg]", "camera_tilt [deg]",
              "camera_zoom [1]"});
  AddPoseColumns(&cols, "p_RoPo_R", "R_RP");
  return cols;
}

std::vector<std::string> EsgColumns() {
  std::vector<std::string> cols = {"log_time [us]",        "session_time [s]", "frame",
                                   "send_time [us]",       "dcp_frame",        "input_frame",
                                   "input_send_time [us]", "num_words",        "frame_count"};
  for (const auto& c : ControlColumns("")) cols.push_back(c);
  Add(&cols, {"priority_dynamic", "priority_fixed"});
  for (const auto& c : AngleColumns()) cols.push_back(c);
  Add(&cols, {"shoulder_height [ft]", "finger_gap [ft]"});
  AddPoseColumns(&cols, "p_RoEye_R", "R_RE");
  cols.push_back("fov [deg]");
  AddPoseColumns(&cols, "p_RoPo_R", "R_RP");
  for (int w = 0; w < wire::esg_words::kPriorityCount; ++w)
    cols.push_back("priority_word_" + std::to_string(w) + " [hex]");
  return cols;
}

std::vector<std::string> TelemetryColumns() {
  std::vector<std::string> cols = {"log_time [us]",
                                   "session_time [s]",
                                   "frame",
                                   "send_time [us]",
                                   "input_frame",
                                   "input_send_time [us]",
                                   "mode",
                                   "acquired",
                                   "docked",
                                   "held",
                                   "finger_held",
                                   "collisions [bits]",
                                   "slave_collisions [bits]"};
  for (int i = 1; i <= wire::kNumAcquisitionConditions; ++i)
    cols.push_back("acquisition_condition_" + std::to_string(i));
  Add(&cols, {"finger_gap [ft]", "palm_to_bar [ft]", "probe_in_envelope", "dock_distance [ft]",
              "dock_angle [deg]"});
  AddPlaneColumns(&cols);
  for (const char* w : {"master_", "slave_"}) {
    for (const auto& c : AngleColumns(w)) cols.push_back(c);
  }
  Add(&cols, {"master_shoulder_height [ft]", "slave_shoulder_height [ft]", "master_finger [1]",
              "slave_finger [1]"});
  AddPoseColumns(&cols, "p_RoA_R", "R_RS2");
  AddPoseColumns(&cols, "p_RoPo_R", "R_RP");
  return cols;
}

void AddVec3(std::vector<std::string>* row, const Eigen::Vector3d& v) {
  for (int i = 0; i < 3; ++i) row->push_back(N(v[i]));
}
void AddMat(std::vector<std::string>* row, const Eigen::Matrix3d& m) {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) row->push_back(N(m(r, c)));
  }
}

// A message decoded, or InputError ("malformed": counted, not exported).
template <class Msg>
Msg Decoded(const LogMessage& msg) {
  Msg m{};
  if (wire::SafeDecode(msg.data, msg.size, &m) != wire::DecodeError::kNone)
    throw InputError("malformed");
  return m;
}

// Each channel's row; t and st: the log time and the session time, as written.
std::vector<std::string> InputRow(const LogMessage& msg, const std::string& t,
                                  const std::string& st, const LabConfig& config) {
  const auto m = Decoded<operator_input_t>(msg);
  std::array<std::int32_t, wire::kInputWords> words{};
  std::copy(m.words, m.words + wire::kInputWords, words.begin());
  const wire::OperatorInputs in = wire::DecodeInputs(words, config.inputs, nullptr);
  std::vector<std::string> row = {t, st, I(m.frame), I(m.send_time_us)};
  for (int i = 0; i < kNumAnalogInputs; ++i) row.push_back(N(in.value[i]));
  Add(&row, {I(in.camera_station), B(in.reset), B(in.overlay)});
  return row;
}

// The session time of a frame that answers operator frame `input_frame`
// (docs/sessions.md "Session time"): the DCP's, the scene's and the
// telemetry's rows carry the frame they answer and its time, not the time
// the record has them at.
std::string SessionTimeOf(std::int64_t input_frame, double rate_hz) {
  return N(static_cast<double>(input_frame) / rate_hz);
}

std::vector<std::string> DcpRow(const LogMessage& msg, const std::string& t, double rate_hz) {
  const auto m = Decoded<dcp_frame_t>(msg);
  const wire::DcpFrameData d = wire::UnpackDcpFrame(m);
  std::vector<std::string> row = {t,
                                  SessionTimeOf(m.input_frame, rate_hz),
                                  I(m.frame),
                                  I(m.send_time_us),
                                  I(m.input_frame),
                                  I(m.input_send_time_us)};
  for (int i = 0; i < kNumJoints; ++i) row.push_back(N(Deg(d.arm[i])));
  ControlCells(&row, d.control);
  for (int k = 0; k < 3; ++k) {
    Add(&row, {B((d.plane_valid >> k) & 1), N(d.planes[k].n_R.x()), N(d.planes[k].n_R.y()),
               N(d.planes[k].n_R.z()), N(d.planes[k].d_ft)});
  }
  Add(&row, {N(d.shoulder_height_ft), N(d.finger_gap_ft), N(d.camera_pan_deg), N(d.camera_tilt_deg),
             N(d.camera_zoom)});
  AddVec3(&row, d.p_RoPo_R_ft);
  AddMat(&row, d.R_RP);
  return row;
}

std::vector<std::string> EsgRow(const LogMessage& msg, const std::string& t, double rate_hz) {
  const auto m = Decoded<esg_frame_t>(msg);
  const wire::EsgFrameData d = wire::UnpackEsgWords(m.words);
  std::vector<std::string> row = {t,
                                  SessionTimeOf(m.input_frame, rate_hz),
                                  I(m.frame),
                                  I(m.send_time_us),
                                  I(m.dcp_frame),
                                  I(m.input_frame),
                                  I(m.input_send_time_us),
                                  I(m.num_words),
                                  I(d.frame_count)};
  ControlCells(&row, d.control);
  Add(&row, {I(d.control.priority_dynamic), I(d.control.priority_fixed)});
  for (int i = 0; i < kNumJoints; ++i) row.push_back(N(Deg(d.arm[i])));
  Add(&row, {N(d.shoulder_height_ft), N(d.finger_gap_ft)});
  AddVec3(&row, d.p_RoEye_R_ft);
  AddMat(&row, d.R_RE);
  row.push_back(N(d.fov_deg));
  AddVec3(&row, d.p_RoPo_R_ft);
  AddMat(&row, d.R_RP);
  for (std::int32_t w : d.priority_words) {
    char hex[16];
    std::snprintf(hex, sizeof hex, "%06x", static_cast<unsigned>(w));
    row.push_back(hex);
  }
  return row;
}

std::vector<std::string> TelemetryRow(const LogMessage& msg, const std::string& t, double rate_hz) {
  const auto m = Decoded<dcp_telemetry_t>(msg);
  std::vector<std::string> row = {t,
                                  SessionTimeOf(m.input_frame, rate_hz),
                                  I(m.frame),
                                  I(m.send_time_us),
                                  I(m.input_frame),
                                  I(m.input_send_time_us),
                                  I(m.mode),
                                  B(m.acquired),
                                  B(m.docked),
                                  B(m.held),
                                  B(m.finger_held),
                                  I(m.collisions),
                                  I(m.slave_collisions)};
  for (int i = 0; i < wire::kNumAcquisitionConditions; ++i)
    row.push_back(B(m.acquisition_conditions[i]));
  Add(&row, {N(m.finger_gap_ft), N(m.palm_to_bar_ft), B(m.probe_in_envelope), N(m.dock_distance_ft),
             N(m.dock_angle_deg)});
  for (int k = 0; k < 3; ++k) {
    Add(&row, {B(m.plane_valid[k]), N(m.plane_n[3 * k]), N(m.plane_n[3 * k + 1]),
               N(m.plane_n[3 * k + 2]), N(m.plane_d_ft[k])});
  }
  for (int i = 0; i < kNumJoints; ++i) row.push_back(N(m.master_angles_deg[i]));
  for (int i = 0; i < kNumJoints; ++i) row.push_back(N(m.slave_angles_deg[i]));
  Add(&row, {N(m.master_shoulder_height_ft), N(m.slave_shoulder_height_ft), N(m.master_finger),
             N(m.slave_finger)});
  for (int i = 0; i < 3; ++i) row.push_back(N(m.p_RoA_R_ft[i]));
  for (int i = 0; i < 9; ++i) row.push_back(N(m.R_RS2[i]));
  for (int i = 0; i < 3; ++i) row.push_back(N(m.p_RoPo_R_ft[i]));
  for (int i = 0; i < 9; ++i) row.push_back(N(m.R_RP[i]));
  return row;
}

std::vector<std::string> OperatorStateColumns() {
  std::vector<std::string> cols = {
      "log_time [us]", "session_time [s]", "frame", "send_time [us]", "source",
      "control_mode",  "command_frame",    "scale", "joint"};
  // x, y, z ft/s; roll, pitch, yaw deg/s (single joint: x is the joint's
  // rate, deg/s; docs/sessions.md "Export").
  for (const char* kind : {"hand_rate_", "achieved_rate_"}) {
    cols.push_back(std::string(kind) + "x [ft/s; single joint: deg/s]");
    for (const char* a : {"y", "z"}) cols.push_back(std::string(kind) + a + " [ft/s]");
    for (const char* a : {"roll", "pitch", "yaw"})
      cols.push_back(std::string(kind) + a + " [deg/s]");
  }
  Add(&cols, {"automatic [bits]", "joints_near_limit [bits]"});
  Add(&cols,
      {"joint_limits [bits]", "singular", "sigma_min [ft]", "guidance_valid", "mode", "target"});
  for (const auto& c : Vec3Columns("offset", "ft")) cols.push_back(c);
  Add(&cols,
      {"rotation_x [deg]", "rotation_y [deg]", "rotation_z [deg]", "distance [ft]", "angle [deg]"});
  for (int i = 1; i <= 6; ++i) cols.push_back("condition_" + std::to_string(i));
  for (int i = 1; i <= 6; ++i) cols.push_back("margin_" + std::to_string(i) + " [ft]");
  Add(&cols, {"close_gap [ft]", "close_ok", "bay_clearance [ft]", "dock_distance [ft]",
              "dock_angle [deg]", "next_axis", "turn_clearance [ft]", "clearance_warning",
              "show_guidance", "key_actions", "rate_limited", "devices"});
  return cols;
}

std::vector<std::string> OperatorStateRow(const LogMessage& msg, const std::string& t,
                                          double rate_hz) {
  const auto m = Decoded<operator_state_t>(msg);
  std::vector<std::string> row = {t,
                                  SessionTimeOf(m.frame, rate_hz),
                                  I(m.frame),
                                  I(m.send_time_us),
                                  I(m.source),
                                  I(m.control_mode),
                                  I(m.command_frame),
                                  I(m.scale),
                                  I(m.joint)};
  for (double r : m.hand_rate) row.push_back(N(r));
  for (double r : m.achieved_rate) row.push_back(N(r));
  Add(&row, {I(m.automatic), I(m.joints_near_limit)});
  Add(&row, {I(m.joint_limits), B(m.singular), N(m.sigma_min_ft), B(m.guidance_valid), I(m.mode),
             I(m.target)});
  for (double v : m.offset_ft) row.push_back(N(v));
  for (double v : m.rotation_deg) row.push_back(N(v));
  Add(&row, {N(m.distance_ft), N(m.angle_deg)});
  for (bool c : m.conditions) row.push_back(B(c));
  for (double v : m.margin_ft) row.push_back(N(v));
  std::string devices;
  for (int i = 0; i < m.num_devices; ++i)
    devices += (i ? "; " : "") + m.device_names[i] + " " + I(m.device_actions[i]);
  Add(&row, {N(m.close_gap_ft), B(m.close_ok), N(m.bay_clearance_ft), N(m.dock_distance_ft),
             N(m.dock_angle_deg), I(m.next_axis), N(m.turn_clearance_ft), B(m.clearance_warning),
             B(m.show_guidance), I(m.key_actions), B(m.rate_limited), devices});
  return row;
}

// The DCP's logged state (its checkpoint a JSON text, in one cell).
std::vector<std::string> DcpStateRow(const LogMessage& msg, const std::string& t,
                                     const std::string& st) {
  const auto m = Decoded<dcp_state_t>(msg);
  static constexpr const char* kReasons[] = {"?",       "start",  "periodic",
                                             "restore", "resume", "malfunction"};
  return {t,
          st,
          I(m.send_time_us),
          m.reason >= 1 && m.reason <= 5 ? kReasons[m.reason] : "?",
          I(m.next_frame),
          I(m.input_frame),
          B(m.resume_pending),
          I(m.resume_dcp_frame),
          I(m.resume_input_frame),
          m.checkpoint};
}

std::vector<std::string> WindowKeysRow(const LogMessage& msg, const std::string& t,
                                       const std::string& st) {
  const auto m = Decoded<window_keys_t>(msg);
  auto keys = [](const std::vector<std::int16_t>& v) {
    std::string out;
    for (std::size_t i = 0; i < v.size(); ++i) out += (i ? " " : "") + I(v[i]);
    return out;
  };
  return {t, st, I(m.send_time_us), I(m.sequence), keys(m.held), keys(m.pressed), B(m.focused)};
}

// The session's files, one a channel.
struct ChannelFiles {
  Csv in, dcp, esg, tm, st, ctl, answer, op_state, dcp_state, keys;
  ChannelFiles(OutputFolder* out, const LabConfig& config)
      : in(out, "operator_input.csv", InputColumns(config)),
        dcp(out, "dcp_frame.csv", DcpColumns()),
        esg(out, "esg_frame.csv", EsgColumns()),
        tm(out, "dcp_telemetry.csv", TelemetryColumns()),
        st(out, "status.csv",
           {"log_time [us]", "session_time [s]", "send_time [us]", "process", "host", "pid",
            "frame", "final", "counter", "value"}),
        ctl(out, "control.csv",
            {"log_time [us]", "session_time [s]", "send_time [us]", "process", "pid", "sequence",
             "command", "name"}),
        answer(out, "control_answer.csv",
               {"log_time [us]", "session_time [s]", "send_time [us]", "process", "command_process",
                "command_pid", "command_sequence", "command", "outcome", "frame", "text"}),
        op_state(out, "operator_state.csv", OperatorStateColumns()),
        dcp_state(out, "dcp_state.csv",
                  {"log_time [us]", "session_time [s]", "send_time [us]", "reason", "next_frame",
                   "input_frame", "resume_pending", "resume_dcp_frame", "resume_input_frame",
                   "checkpoint [json]"}),
        keys(out, "window_keys.csv",
             {"log_time [us]", "session_time [s]", "send_time [us]", "sequence", "held [key codes]",
              "pressed [key codes]", "focused"}) {}

  void Write(const LogMessage& msg, const LabConfig& config) {
    const std::string_view base = msg.base;
    const std::string t = I(msg.log_us), st_s = N(msg.session_time_s);
    if (base == wire::channels::kOperatorInput) {
      in.Row(InputRow(msg, t, st_s, config));
    } else if (base == wire::channels::kDcpFrame) {
      dcp.Row(DcpRow(msg, t, config.session.frame_rate_hz));
    } else if (base == wire::channels::kEsgFrame) {
      esg.Row(EsgRow(msg, t, config.session.frame_rate_hz));
    } else if (base == wire::channels::kDcpTelemetry) {
      tm.Row(TelemetryRow(msg, t, config.session.frame_rate_hz));
    } else if (base == wire::channels::kStatus) {
      const auto m = Decoded<process_status_t>(msg);
      for (int i = 0; i < m.num_counters; ++i) {
        st.Row({t, st_s, I(m.send_time_us), m.process, m.host, I(m.pid), I(m.frame), B(m.final),
                m.counter_names[i], I(m.counter_values[i])});
      }
    } else if (base == wire::channels::kControl) {
      const auto m = Decoded<session_control_t>(msg);
      ctl.Row({t, st_s, I(m.send_time_us), wire::ProcessCodeName(m.sender.process), I(m.sender.pid),
               I(m.sequence), wire::ControlCommandName(m.command), m.name});
    } else if (base == wire::channels::kControlAnswer) {
      const auto m = Decoded<control_answer_t>(msg);
      answer.Row({t, st_s, I(m.send_time_us), wire::ProcessCodeName(m.sender.process),
                  wire::ProcessCodeName(m.command_process), I(m.command_pid), I(m.command_sequence),
                  wire::ControlCommandName(m.command),
                  m.outcome == control_answer_t::DONE ? "done" : "refused", I(m.frame), m.text});
    } else if (base == wire::channels::kOperatorState) {
      op_state.Row(OperatorStateRow(msg, t, config.session.frame_rate_hz));
    } else if (base == wire::channels::kDcpState) {
      dcp_state.Row(DcpStateRow(msg, t, st_s));
    } else if (base == wire::channels::kWindowKeys) {
      keys.Row(WindowKeysRow(msg, t, st_s));
    }
  }
};

}  // namespace

std::vector<std::pair<std::string, long>> ExportCsv(
    const std::string& session_dir, const std::string& out_dir,
    const std::function<void(const std::string&)>& progress, ExportRead* read) {
  const fs::path root(session_dir), out(out_dir);
  const LabConfig config = LoadSessionConfig(session_dir);
  // The CSVs are written whole or not at all: a failure part way (a full
  // disk) leaves none of this export's files, and the last export's as
  // they were (docs/sessions.md "Export").
  const bool inside = fs::path(out_dir).lexically_normal() == (root / "csv").lexically_normal();
  OutputFolder folder(out_dir, inside ? Links::kRefuse : Links::kFollow);
  ChannelFiles files(&folder, config);
  long skipped = 0, events = 0;
  SessionLog log(session_dir);  // only the session's own messages (docs/security.md)
  log.Read({}, [&](const LogMessage& msg) {
    if (++events % 100000 == 0 && progress)
      progress("export: " + std::to_string(events) + " messages");
    try {
      files.Write(msg, config);
    } catch (const std::exception&) {
      ++skipped;  // a malformed message: counted, not exported
    }
  });
  std::vector<std::pair<std::string, long>> written;
  try {
    for (Csv* c : {&files.in, &files.dcp, &files.esg, &files.tm, &files.st, &files.ctl,
                   &files.op_state, &files.dcp_state, &files.keys}) {
      c->Close();
      written.emplace_back(c->path().string(), c->rows());
    }
    folder.Commit();
  } catch (const InputError& e) {
    throw InputError(std::string(e.what()) + ": none of this export's files were kept");
  }
  if (read) *read = {events, log.unread_bytes(), log.skipped_bytes()};
  written.emplace_back("skipped (malformed)", skipped);
  written.emplace_back("not exported (not the session's own: other sessions, other senders)",
                       static_cast<long>(log.check().ignored_total()));
  return written;
}

}  // namespace rms::session
