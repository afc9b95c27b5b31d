// The DCP's state to JSON and back (docs/sessions.md "Freeze, run, step,
// checkpoint"; the checkpoint's "dcp" object, format rmslab-dcp-state-1):
// SaveState, RestoreState and the checks that a restored state is one the
// program could have reached.
#include <cmath>
#include <memory>
#include <spdlog/spdlog.h>

#include "rms/base/check.h"
#include "rms/dcp_model/dynamic_collision_program.h"
#include "rms/wire/dcp_mode.h"

#include "program_internal.h"

namespace rms::dcp_model {

using internal::Finite;
using internal::MakeMalfunctions;

namespace {

nlohmann::json PoseJson(const Eigen::Isometry3d& X) {
  nlohmann::json j = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) j.push_back(X.matrix()(r, c));
  }
  return j;
}

Eigen::Isometry3d PoseFrom(const nlohmann::json& j, const char* key) {
  if (!j.is_array() || j.size() != 12)
    throw InputError(std::string("checkpoint: '") + key + "' must be 12 numbers");
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) X.matrix()(r, c) = j.at(4 * r + c).get<double>();
  }
  return X;
}

nlohmann::json CommandJson(const ArmCommand& a) {
  return {{"angles_deg", a.angles_deg},
          {"shoulder_height_ft", a.shoulder_height_ft},
          {"finger", a.finger}};
}

ArmCommand CommandFrom(const nlohmann::json& j) {
  ArmCommand a;
  a.angles_deg = j.at("angles_deg").get<std::array<double, 6>>();
  a.shoulder_height_ft = j.at("shoulder_height_ft").get<double>();
  a.finger = j.at("finger").get<double>();
  return a;
}

constexpr const char* kCheckpointFormat = "rmslab-dcp-state-1";

// A pair's separating plane (frame coherence's hint): [nx, ny, nz, d], or
// null when the pair had none.
nlohmann::json PlaneJson(const CollisionResult& r) {
  if (r.verdict != Verdict::kSeparate || !r.plane_valid) return nullptr;
  return {r.plane.n_R.x(), r.plane.n_R.y(), r.plane.n_R.z(), r.plane.d_ft};
}

void PlaneFrom(const nlohmann::json& j, CollisionResult* r) {
  if (j.is_null()) return;
  if (!j.is_array() || j.size() != 4)
    throw InputError("checkpoint: a plane must be null or 4 numbers");
  r->verdict = Verdict::kSeparate;
  r->plane_valid = true;
  r->plane = {Eigen::Vector3d(j[0].get<double>(), j[1].get<double>(), j[2].get<double>()),
              j[3].get<double>()};
}

}  // namespace

nlohmann::ordered_json DynamicCollisionProgram::SaveState() const {
  nlohmann::ordered_json j;
  j["format"] = kCheckpointFormat;
  j["mode"] = status_.mode;
  j["acquired"] = status_.acquired;
  j["docked"] = status_.docked;
  j["released"] = released_;
  j["have_slave"] = started_;
  j["slave"] = CommandJson(slave_->cmd);
  j["slave_collisions"] =
      slave_->collisions;  // always 0 (a restore re-tests the slave); kept for older readers
  j["master"] = CommandJson(status_.master);
  j["X_S2P"] = PoseJson(X_S2P_);
  j["X_RP_docked"] = PoseJson(X_RP_docked_);
  j["X_RP_free"] = PoseJson(X_RP_free_);
  j["contact_gap_ft"] = contact_gap_ft_;
  j["acquisition_gap_ft"] = acquisition_gap_ft_;
  j["reset_pressed"] = reset_pressed_;
  // The slave's separating planes, the next frame's hints (frame coherence).
  nlohmann::json bar = nlohmann::json::array(), body = nlohmann::json::array();
  for (int k = 0; k < 3; ++k) bar.push_back(PlaneJson(slave_->ee_bar[k]));
  for (const CollisionResult& r : slave_->ee_body) body.push_back(PlaneJson(r));
  j["planes_ee_bar"] = bar;
  j["planes_ee_body"] = body;
  // Only while one is in force: a state without is as it was before
  // malfunctions existed (older logs' states compare equal).
  if (malfunctions_.any()) j[wire::kMalfunctionsKey] = malfunctions_.ToJson();
  return j;
}

// A checkpoint's state, every key read (RestoreState). Keys added after the
// format's first version (X_RP_free, reset_pressed) default to the payload
// in the bay and the button up.
struct DynamicCollisionProgram::RestoredState {
  int mode = 1;
  bool acquired = false, docked = false, released = false, have_slave = false,
       reset_pressed = false;
  Eigen::Isometry3d X_S2P, X_RP_docked, X_RP_free;
  double contact_gap_ft = 0, acquisition_gap_ft = 0;
  ArmCommand master, slave;
  Evaluation hints;  // only its planes
  Malfunctions malfunctions;
  explicit RestoredState(const LabConfig& config) : malfunctions(MakeMalfunctions(config)) {}
};

std::unique_ptr<DynamicCollisionProgram::RestoredState> DynamicCollisionProgram::ReadRestoredState(
    const nlohmann::json& j) const {
  auto p = std::make_unique<RestoredState>(config_);
  try {
    if (j.at("format").get<std::string>() != kCheckpointFormat) {
      throw InputError("checkpoint: format '" + j.at("format").get<std::string>() +
                       "', expected '" + kCheckpointFormat + "'");
    }
    p->mode = j.at("mode").get<int>();
    if (p->mode < wire::DcpMode::kAcquisition || p->mode > wire::DcpMode::kManoeuvring)
      throw InputError("checkpoint: mode must be 1, 2 or 3");
    p->acquired = j.at("acquired").get<bool>();
    p->docked = j.at("docked").get<bool>();
    p->released = j.at("released").get<bool>();
    p->X_S2P = PoseFrom(j.at("X_S2P"), "X_S2P");
    p->X_RP_docked = PoseFrom(j.at("X_RP_docked"), "X_RP_docked");
    p->X_RP_free = j.contains("X_RP_free") ? PoseFrom(j.at("X_RP_free"), "X_RP_free") : X_RP_bay_;
    p->contact_gap_ft = j.at("contact_gap_ft").get<double>();
    p->acquisition_gap_ft = j.at("acquisition_gap_ft").get<double>();
    p->reset_pressed = j.contains("reset_pressed") ? j.at("reset_pressed").get<bool>() : false;
    p->master = CommandFrom(j.at("master"));
    // Absent before malfunctions: none in force.
    if (j.contains(wire::kMalfunctionsKey)) p->malfunctions.FromJson(j.at(wire::kMalfunctionsKey));
    p->have_slave = j.at("have_slave").get<bool>();
    if (p->have_slave) {
      p->slave = CommandFrom(j.at("slave"));
      if (j.contains("planes_ee_bar")) {
        for (int k = 0; k < 3; ++k) PlaneFrom(j.at("planes_ee_bar").at(k), &p->hints.ee_bar[k]);
        // One plane per end-effector hexahedron and body strip (an older
        // checkpoint has three, one per hexahedron: hints for strip 0).
        const nlohmann::json& body = j.at("planes_ee_body");
        if (!body.is_array() || body.size() > p->hints.ee_body.size()) {
          throw InputError("checkpoint: 'planes_ee_body' must be at most 21 planes");
        }
        for (std::size_t i = 0; i < body.size(); ++i) PlaneFrom(body.at(i), &p->hints.ee_body[i]);
      }
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(std::string("checkpoint: ") + e.what());
  }
  return p;
}

// A state the DCP can be in: reachable, finite commands, rigid poses, unit
// plane normals (InputError naming what is not).
void DynamicCollisionProgram::CheckRestoredState(const RestoredState& p) const {
  CheckRestored(p.mode, p.acquired, p.docked, p.released, p.contact_gap_ft, p.acquisition_gap_ft);
  if (!Finite(p.master) || (p.have_slave && !Finite(p.slave)))
    throw InputError("checkpoint: a command is not finite");
  for (const ArmCommand* c : {&p.master, &p.slave}) {
    if (!(std::abs(c->finger) <= 10.0))
      throw InputError("checkpoint: a finger lever is out of range");
  }
  for (const auto& [X, key] : {std::pair{&p.X_S2P, "X_S2P"},
                               {&p.X_RP_free, "X_RP_free"},
                               {&p.X_RP_docked, "X_RP_docked"}}) {
    const Eigen::Matrix3d R = X->linear();
    if (!X->matrix().allFinite() ||
        !((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <= 1e-9)) {
      throw InputError(std::string("checkpoint: '") + key + "' is not a rigid pose");
    }
  }
  auto unit = [](const CollisionResult& r) {
    return !r.plane_valid || std::abs(r.plane.n_R.norm() - 1.0) <= 1e-9;
  };
  for (const CollisionResult& r : p.hints.ee_bar) {
    if (!unit(r)) throw InputError("checkpoint: a plane's normal is not a unit vector");
  }
  for (const CollisionResult& r : p.hints.ee_body) {
    if (!unit(r)) throw InputError("checkpoint: a plane's normal is not a unit vector");
  }
}

void DynamicCollisionProgram::RestoreState(const nlohmann::json& j) {
  // Read every key first; change the state only when all of them are good
  // (a refused checkpoint changes nothing).
  const std::unique_ptr<RestoredState> p = ReadRestoredState(j);
  CheckRestoredState(*p);
  // The slave must be free where the checkpoint puts it: tried on the state
  // it describes, and the old state put back if not.
  const nlohmann::ordered_json before = SaveState();
  status_.mode = static_cast<wire::DcpMode>(p->mode);  // 1..3: CheckRestoredState
  status_.acquired = p->acquired;
  status_.docked = p->docked;
  released_ = status_.released = p->released;
  X_S2P_ = p->X_S2P;
  X_RP_docked_ = p->X_RP_docked;
  contact_gap_ft_ = p->contact_gap_ft;
  acquisition_gap_ft_ = p->acquisition_gap_ft;
  reset_pressed_ = p->reset_pressed;
  malfunctions_ = p->malfunctions;
  started_ = p->have_slave;
  status_.master = p->master;
  PlacePayload(p->docked ? p->X_RP_docked : p->X_RP_free);
  payload_reach_ft_ = p->acquired ? PayloadReachFt(p->X_S2P) : 0.0;
  // The slave's evaluation follows from its command and the state above (a
  // checkpoint saved before the first frame: the initial pose). The saved
  // planes are the hints, as they were for the saved frame.
  const ArmCommand slave = p->have_slave ? p->slave : initial_;
  Evaluate(slave, &p->hints, spare_);
  if (spare_->collisions) {
    const std::string pairs = wire::CollisionNames(spare_->collisions, ", ", "none");
    RestoreState(before);
    throw InputError("checkpoint: its arm pose collides (" + pairs + ")");
  }
  AcceptSpare();
  status_.slave = slave_->cmd;
  status_.X_RS2 = slave_->pose.X_RS2;
  status_.X_RP = slave_->X_RP;
  status_.finger_gap_ft = slave_->finger_gap_ft;
  RefreshMeasures();  // nothing of the frames before the restore
}

void DynamicCollisionProgram::CheckRestored(int mode, bool acquired, bool docked, bool released,
                                            double contact_gap_ft,
                                            double acquisition_gap_ft) const {
  // A state the program could have reached (docs/sessions.md "checkpoint").
  if (acquired != (mode >= wire::DcpMode::kExtraction))
    throw InputError("checkpoint: 'acquired' must be true exactly in Modes 2 and 3");
  if (docked && mode != wire::DcpMode::kManoeuvring)
    throw InputError("checkpoint: 'docked' needs Mode 3");
  if (released && !docked) throw InputError("checkpoint: 'released' needs 'docked'");
  if (!std::isfinite(contact_gap_ft) || !std::isfinite(acquisition_gap_ft)) {
    throw InputError("checkpoint: a finger gap is not finite");
  }
  const auto& e = config_.end_effector;
  if (acquired && !(contact_gap_ft >= 0.0 && contact_gap_ft <= acquisition_gap_ft &&
                    acquisition_gap_ft <= e.finger_gap_open_ft)) {
    throw InputError(
        "checkpoint: the finger gaps must satisfy 0 <= contact_gap_ft <= acquisition_gap_ft <= "
        "the open gap");
  }
}

}  // namespace rms::dcp_model
