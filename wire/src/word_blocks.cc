#include "rms/wire/word_blocks.h"

#include <cmath>
#include <string>

#include "rms/base/check.h"
#include "rms/dcp_frame_t.hpp"

namespace rms::wire {

namespace {

std::int32_t Put(const wire::FixedFormat& f, double v, Counter saturated, Counters* counters) {
  const wire::Encoded e = wire::Encode(f, v);
  if (e.saturated && counters) counters->Add(saturated);
  return static_cast<std::int32_t>(e.word);
}

template <class It>
void PutVec3(It out, const Eigen::Vector3d& v, Counter field, Counters* c) {
  for (int i = 0; i < 3; ++i) out[i] = Put(wire::kFT12, v[i], field, c);
}

template <class It>
void PutRot(It out, const Eigen::Matrix3d& r, Counter field, Counters* c) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out[3 * i + j] = Put(wire::kSC22, r(i, j), field, c);
}

template <class It>
void PutArm(It out, const arm::ArmSinCos& arm, Counters* c) {
  for (int i = 0; i < kNumJoints; ++i) {
    out[2 * i] = Put(wire::kSC22, arm[i].s, Counter::kSaturatedArm, c);
    out[2 * i + 1] = Put(wire::kSC22, arm[i].c, Counter::kSaturatedArm, c);
  }
}

// Decoding helpers: throw InputError naming the block and word.
struct Reader {
  const char* block;
  std::span<const std::int32_t> w;
  int base;  // index of w[0] in the block, for messages

  [[noreturn]] void Fail(int i, const std::string& why) const {
    throw InputError(std::string(block) + " word " + std::to_string(base + i) + ": " + why);
  }
  double Get(const wire::FixedFormat& f, int i) const {
    try {
      return wire::Decode(f, w[i]);
    } catch (const InputError& e) {
      Fail(i, e.what());
    }
  }
  Eigen::Vector3d Vec3(int i) const {
    return {Get(wire::kFT12, i), Get(wire::kFT12, i + 1), Get(wire::kFT12, i + 2)};
  }
  Eigen::Matrix3d Rot(int i) const {
    Eigen::Matrix3d r;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) r(a, b) = Get(wire::kSC22, i + 3 * a + b);
    if (!((r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <= 1e-3) ||
        !(std::abs(r.determinant() - 1.0) <= 1e-3)) {
      Fail(i, "rotation words are not a rotation matrix (orthonormal, det +1, within 1e-3)");
    }
    return r;
  }
  arm::ArmSinCos Arm(int i) const {
    arm::ArmSinCos a;
    for (int k = 0; k < kNumJoints; ++k) {
      a[k].s = Get(wire::kSC22, i + 2 * k);
      a[k].c = Get(wire::kSC22, i + 2 * k + 1);
      if (!(std::abs(std::hypot(a[k].s, a[k].c) - 1.0) <= 1e-3)) {
        Fail(i + 2 * k, "arm sine/cosine pair " + std::to_string(k + 1) +
                            " is not on the unit circle (within 1e-3)");
      }
    }
    return a;
  }
  double Angle(int i) const {
    try {
      return wire::DecodeAngleBam(w[i]);
    } catch (const InputError& e) {
      Fail(i, e.what());
    }
  }
  ControlWord Control(int i) const {
    try {
      return UnpackControlWord(w[i]);
    } catch (const InputError& e) {
      Fail(i, e.what());
    }
  }
};

}  // namespace

// ---------------------------------------------------------------- DCP block

void PackDcpFrame(const DcpFrameData& in, dcp_frame_t* out, Counters* c) {
  out->frame = in.frame;
  out->send_time_us = in.send_time_us;
  out->input_frame = in.input_frame;
  out->input_send_time_us = in.input_send_time_us;
  PutArm(out->arm_words, in.arm, c);
  out->control_word = static_cast<std::int32_t>(PackControlWord(in.control));
  for (int p = 0; p < 3; ++p) {
    for (int k = 0; k < 3; ++k)
      out->plane_words[4 * p + k] =
          Put(wire::kSC22, in.planes[p].n_R[k], Counter::kSaturatedPlane, c);
    out->plane_words[4 * p + 3] = Put(wire::kFT12, in.planes[p].d_ft, Counter::kSaturatedPlane, c);
  }
  RMS_CHECK(in.plane_valid <= 7);
  out->plane_status = static_cast<std::int32_t>(in.plane_valid);
  auto* s = out->state_words;
  s[dcp_state::kShoulderHeight] =
      Put(wire::kFT12, in.shoulder_height_ft, Counter::kSaturatedShoulderHeight, c);
  s[dcp_state::kFingerGap] = Put(wire::kFT12, in.finger_gap_ft, Counter::kSaturatedFingerGap, c);
  s[dcp_state::kCameraPan] = static_cast<std::int32_t>(wire::EncodeAngleBam(in.camera_pan_deg));
  s[dcp_state::kCameraTilt] = static_cast<std::int32_t>(wire::EncodeAngleBam(in.camera_tilt_deg));
  s[dcp_state::kCameraZoom] = Put(wire::kSC22, in.camera_zoom, Counter::kSaturatedCameraZoom, c);
  PutVec3(s + dcp_state::kPayloadPos, in.p_RoPo_R_ft, Counter::kSaturatedPayloadPos, c);
  PutRot(s + dcp_state::kPayloadRot, in.R_RP, Counter::kSaturatedPayloadRot, c);
}

DcpFrameData UnpackDcpFrame(const dcp_frame_t& m) {
  DcpFrameData d;
  d.frame = m.frame;
  d.send_time_us = m.send_time_us;
  d.input_frame = m.input_frame;
  d.input_send_time_us = m.input_send_time_us;
  d.arm = Reader{"DCP arm", m.arm_words, 0}.Arm(0);
  d.control = Reader{"DCP control", std::span(&m.control_word, 1), 0}.Control(0);
  if (d.control.priority_dynamic || d.control.priority_fixed) {
    throw InputError("DCP control word " + wire::FormatWord(m.control_word) +
                     " has priority bits set (scene_proc sets them)");
  }
  const Reader planes{"DCP plane", m.plane_words, 0};
  for (int p = 0; p < 3; ++p) {
    for (int k = 0; k < 3; ++k) d.planes[p].n_R[k] = planes.Get(wire::kSC22, 4 * p + k);
    d.planes[p].d_ft = planes.Get(wire::kFT12, 4 * p + 3);
  }
  if (m.plane_status < 0 || m.plane_status > 7) {
    throw InputError("DCP plane status " + wire::FormatWord(m.plane_status) + " must be 0-7");
  }
  d.plane_valid = static_cast<std::uint32_t>(m.plane_status);
  const Reader s{"DCP state", m.state_words, 0};
  d.shoulder_height_ft = s.Get(wire::kFT12, dcp_state::kShoulderHeight);
  d.finger_gap_ft = s.Get(wire::kFT12, dcp_state::kFingerGap);
  d.camera_pan_deg = s.Angle(dcp_state::kCameraPan);
  d.camera_tilt_deg = s.Angle(dcp_state::kCameraTilt);
  d.camera_zoom = s.Get(wire::kSC22, dcp_state::kCameraZoom);
  if (!(d.camera_zoom >= 0.0 && d.camera_zoom <= 1.0))
    s.Fail(dcp_state::kCameraZoom, "zoom must be in [0, 1]");
  d.p_RoPo_R_ft = s.Vec3(dcp_state::kPayloadPos);
  d.R_RP = s.Rot(dcp_state::kPayloadRot);
  return d;
}

// ---------------------------------------------------------------- ESG frame

std::vector<std::int32_t> PackEsgWords(const EsgFrameData& in, Counters* c) {
  namespace ew = esg_words;
  std::vector<std::int32_t> w(ew::kCount, 0);
  w[ew::kFrameCount] = static_cast<std::int32_t>(in.frame_count & wire::kWordMask);
  w[ew::kControl] = static_cast<std::int32_t>(PackControlWord(in.control));
  PutArm(w.begin() + ew::kArm, in.arm, c);
  w[ew::kShoulderHeight] =
      Put(wire::kFT12, in.shoulder_height_ft, Counter::kSaturatedShoulderHeight, c);
  w[ew::kFingerGap] = Put(wire::kFT12, in.finger_gap_ft, Counter::kSaturatedFingerGap, c);
  PutVec3(w.begin() + ew::kEye, in.p_RoEye_R_ft, Counter::kSaturatedEye, c);
  PutRot(w.begin() + ew::kView, in.R_RE, Counter::kSaturatedView, c);
  w[ew::kFov] = static_cast<std::int32_t>(wire::EncodeAngleBam(in.fov_deg));
  PutVec3(w.begin() + ew::kPayloadPos, in.p_RoPo_R_ft, Counter::kSaturatedPayloadPos, c);
  PutRot(w.begin() + ew::kPayloadRot, in.R_RP, Counter::kSaturatedPayloadRot, c);
  for (int i = 0; i < ew::kPriorityCount; ++i) {
    RMS_CHECK(wire::IsValidWord(in.priority_words[i]));
    w[ew::kPriority + i] = in.priority_words[i];
  }
  return w;
}

EsgFrameData UnpackEsgWords(std::span<const std::int32_t> w) {
  namespace ew = esg_words;
  if (w.size() != static_cast<std::size_t>(ew::kCount)) {
    throw InputError("ESG frame has " + std::to_string(w.size()) + " words; this layout has " +
                     std::to_string(ew::kCount) + " (at most " + std::to_string(kEsgMaxWords) +
                     ")");
  }
  const int bad = wire::FirstInvalidWord(w);
  if (bad >= 0) {
    throw InputError("ESG frame word " + std::to_string(bad) + " = " + wire::FormatWord(w[bad]) +
                     " has bits above bit 23 set");
  }
  const Reader r{"ESG frame", w, 0};
  EsgFrameData d;
  d.frame_count = static_cast<std::uint32_t>(w[ew::kFrameCount]);
  d.control = r.Control(ew::kControl);
  d.arm = r.Arm(ew::kArm);
  d.shoulder_height_ft = r.Get(wire::kFT12, ew::kShoulderHeight);
  d.finger_gap_ft = r.Get(wire::kFT12, ew::kFingerGap);
  if (!(d.finger_gap_ft >= 0.0)) r.Fail(ew::kFingerGap, "finger gap must be >= 0");
  d.p_RoEye_R_ft = r.Vec3(ew::kEye);
  d.R_RE = r.Rot(ew::kView);
  d.fov_deg = r.Angle(ew::kFov);
  if (!(d.fov_deg > 0.0 && d.fov_deg < 180.0))
    r.Fail(ew::kFov, "field of view must be in (0, 180) deg");
  d.p_RoPo_R_ft = r.Vec3(ew::kPayloadPos);
  d.R_RP = r.Rot(ew::kPayloadRot);
  for (int i = 0; i < ew::kPriorityCount; ++i) d.priority_words[i] = w[ew::kPriority + i];
  if (static_cast<std::uint32_t>(d.priority_words.back()) & ~ew::kLastPriorityWordMask) {
    r.Fail(ew::kPriority + ew::kPriorityCount - 1, "unused priority bits are set");
  }
  return d;
}

}  // namespace rms::wire
