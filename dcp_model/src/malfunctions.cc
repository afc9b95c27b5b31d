#include "rms/dcp_model/malfunctions.h"

#include <algorithm>
#include <cmath>

#include "rms/base/check.h"

namespace rms::dcp_model {

using wire::MalfunctionKind;
using wire::MalfunctionPart;

Malfunctions::Malfunctions(double frame_rate_hz,
                           const std::array<double, kNumJoints>& joint_min_deg,
                           const std::array<double, kNumJoints>& joint_max_deg)
    : frame_rate_hz_(frame_rate_hz), joint_min_deg_(joint_min_deg), joint_max_deg_(joint_max_deg) {
  RMS_CHECK(frame_rate_hz > 0.0);
}

void Malfunctions::Inject(const wire::Malfunction& m,
                          const std::array<double, kNumJoints>& slave_angles_deg,
                          double slave_finger) {
  const wire::MalfunctionPart part = wire::KindInfo(m.kind).part;
  RMS_CHECK(m.target >= 0 && m.target <= wire::PartInfo(part).count);
  switch (part) {
    case MalfunctionPart::kJoint:
      joints_[m.target - 1] = JointFault{m.kind, m.value, slave_angles_deg[m.target - 1]};
      break;
    case MalfunctionPart::kFinger:
      finger_ = FingerFault{m.kind == MalfunctionKind::kFingerJammedOpen, slave_finger};
      break;
    case MalfunctionPart::kCamera:
      cameras_lost_ |= 1u << (m.target - 1);
      break;
    case MalfunctionPart::kInputs: {
      delay_ms_ = m.value;
      delay_frames_ = std::max(1, static_cast<int>(std::lround(m.value * frame_rate_hz_ / 1000.0)));
      // A longer delay holds the oldest block due for the extra frames; a
      // shorter one drops the oldest (the arm jumps ahead to them).
      const wire::OperatorInputs hold = line_.empty() ? last_ : line_.front();
      if (have_last_ || !line_.empty()) {
        while (static_cast<int>(line_.size()) < delay_frames_) line_.push_front(hold);
      }
      while (static_cast<int>(line_.size()) > delay_frames_) line_.pop_front();
      break;
    }
    case MalfunctionPart::kCount:
      RMS_CHECK(false);
  }
}

void Malfunctions::Repair(const wire::Repair& r) {
  for (const wire::Malfunction& m : active()) {
    if (!wire::Clears(r, m)) continue;
    switch (wire::KindInfo(m.kind).part) {
      case MalfunctionPart::kJoint:
        joints_[m.target - 1].reset();
        break;
      case MalfunctionPart::kFinger:
        finger_.reset();
        break;
      case MalfunctionPart::kCamera:
        cameras_lost_ &= ~(1u << (m.target - 1));
        break;
      case MalfunctionPart::kInputs:
        delay_ms_ = 0.0;
        delay_frames_ = 0;
        line_.clear();  // the next frame answers its own block
        break;
      case MalfunctionPart::kCount:
        break;
    }
  }
}

const wire::OperatorInputs& Malfunctions::Delay(const wire::OperatorInputs& in) {
  if (delay_frames_ == 0) {
    last_ = in;
    have_last_ = true;
    return last_;
  }
  line_.push_back(in);
  // Injected before any frame: nothing to hold, the line fills from the
  // first blocks (the first delay_frames_ frames answer the first block).
  while (static_cast<int>(line_.size()) <= delay_frames_) line_.push_front(line_.front());
  last_ = line_.front();
  line_.pop_front();
  have_last_ = true;
  return last_;
}

void Malfunctions::Apply(const std::array<double, kNumJoints>& slave_angles_deg,
                         std::array<double, kNumJoints>* angles_deg, double* finger) {
  const double dt_s = 1.0 / frame_rate_hz_;
  for (int i = 0; i < kNumJoints; ++i) {
    if (!joints_[i]) continue;
    JointFault& f = *joints_[i];
    double& q = (*angles_deg)[i];
    switch (f.kind) {
      case MalfunctionKind::kJointStuck:
        q = f.anchor_deg;
        break;
      case MalfunctionKind::kJointDrift:
        // From where the slave is (a held arm does not wind the drift up).
        q = std::clamp(slave_angles_deg[i] + f.value * dt_s, joint_min_deg_[i], joint_max_deg_[i]);
        break;
      case MalfunctionKind::kJointSlow: {
        const double step = f.value * dt_s;
        q = slave_angles_deg[i] + std::clamp(q - slave_angles_deg[i], -step, step);
        break;
      }
      case MalfunctionKind::kFingerJammedOpen:  // not a joint's: never in joints_
      case MalfunctionKind::kFingerJammedClosed:
      case MalfunctionKind::kCameraLost:
      case MalfunctionKind::kInputsDelayed:
      case MalfunctionKind::kCount:
        RMS_CHECK(false);
    }
  }
  if (finger_) {
    *finger = finger_->open ? std::min(*finger, finger_->anchor_lever)
                            : std::max(*finger, finger_->anchor_lever);
  }
}

bool Malfunctions::any() const {
  return finger_ || cameras_lost_ != 0 || delay_frames_ > 0 ||
         std::any_of(joints_.begin(), joints_.end(), [](const auto& j) { return j.has_value(); });
}

std::vector<wire::Malfunction> Malfunctions::active() const {
  std::vector<wire::Malfunction> out;
  for (int i = 0; i < kNumJoints; ++i) {
    if (joints_[i]) out.push_back({joints_[i]->kind, i + 1, joints_[i]->value});
  }
  if (finger_) {
    out.push_back(
        {finger_->open ? MalfunctionKind::kFingerJammedOpen : MalfunctionKind::kFingerJammedClosed,
         0, 0.0});
  }
  for (int k = 1; k <= kNumCameraStations; ++k) {
    if (CameraLost(k)) out.push_back({MalfunctionKind::kCameraLost, k, 0.0});
  }
  if (delay_frames_ > 0) out.push_back({MalfunctionKind::kInputsDelayed, 0, delay_ms_});
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) {
    return static_cast<int>(a.kind) < static_cast<int>(b.kind);
  });
  return out;
}

nlohmann::ordered_json Malfunctions::ToJson() const {
  nlohmann::ordered_json j;
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const wire::Malfunction& m : active()) {
    nlohmann::ordered_json a;
    a["text"] = wire::MalfunctionText(m);
    const wire::MalfunctionPart part = wire::KindInfo(m.kind).part;
    if (part == MalfunctionPart::kJoint) {
      a["anchor"] = joints_[m.target - 1]->anchor_deg;
    } else if (part == MalfunctionPart::kFinger) {
      a["anchor"] = finger_->anchor_lever;
    }
    list.push_back(a);
  }
  j["active"] = list;
  nlohmann::ordered_json line = nlohmann::ordered_json::array();
  for (const wire::OperatorInputs& in : line_) line.push_back(wire::InputsJson(in));
  j["delay_line"] = line;
  j["last_inputs"] = have_last_ ? nlohmann::ordered_json(wire::InputsJson(last_))
                                : nlohmann::ordered_json(nullptr);
  return j;
}

void Malfunctions::FromJson(const nlohmann::json& j) {
  Malfunctions next(frame_rate_hz_, joint_min_deg_, joint_max_deg_);
  try {
    if (!j.is_object()) throw InputError("must be an object");
    if (j.contains("last_inputs") && !j.at("last_inputs").is_null()) {
      next.last_ = wire::InputsFromJson(j.at("last_inputs"));
      next.have_last_ = true;
    }
    for (const auto& a : j.at("active")) {
      const wire::Malfunction m = wire::ParseMalfunction(a.at("text").get<std::string>());
      const wire::MalfunctionPart part = wire::KindInfo(m.kind).part;
      const bool anchored = part == MalfunctionPart::kJoint || part == MalfunctionPart::kFinger;
      const double anchor = anchored ? a.at("anchor").get<double>() : 0.0;
      if (!std::isfinite(anchor)) throw InputError("an anchor is not finite");
      std::array<double, kNumJoints> q{};
      q.fill(anchor);
      next.Inject(m, q, anchor);
    }
    next.line_.clear();
    for (const auto& in : j.at("delay_line")) next.line_.push_back(wire::InputsFromJson(in));
    if (static_cast<int>(next.line_.size()) > next.delay_frames_)
      throw InputError("the delay line is longer than the delay");
  } catch (const InputError& e) {
    throw InputError(std::string("checkpoint: '") + wire::kMalfunctionsKey + "': " + e.what());
  } catch (const nlohmann::json::exception& e) {
    throw InputError(std::string("checkpoint: '") + wire::kMalfunctionsKey + "': " + e.what());
  }
  *this = std::move(next);
}

}  // namespace rms::dcp_model
