#include "dynamic_collision_program.h"

#include <algorithm>
#include <cmath>
#include <spdlog/spdlog.h>

#include "rms/check.h"

#include "rms/word_codec.h"

namespace rms::dcp {

ArmSinCos TransmittedArmWords(const std::array<double, 6>& angles_deg) {
  ArmSinCos sc = SinCosFromDegrees(angles_deg);
  for (SinCos& a : sc) {
    a.s = wire::RoundTrip(wire::kSC22, a.s);
    a.c = wire::RoundTrip(wire::kSC22, a.c);
  }
  return sc;
}

namespace {

bool AllHave(const std::array<LocationWord, 8>& words, int face) {
  for (LocationWord w : words) {
    if (!(w & FaceBit(face))) return false;
  }
  return true;
}

std::string Names(std::uint32_t bits) {
  std::string s;
  for (int b = 0; b < collision_bits::kCount; ++b) {
    if (bits & (1u << b)) s += std::string(s.empty() ? "" : ", ") + CollisionName(b);
  }
  return s.empty() ? "none" : s;
}

}  // namespace

DynamicCollisionProgram::DynamicCollisionProgram(const LabConfig& config, const DcpOptions& options)
    : config_(config), options_(options) {
  X_RP_bay_ = MakeIsometry(config.payload.R_RP, config.payload.p_RoPo_R_ft);
  bar_bay_ = MakeBar(config.payload, X_RP_bay_);
  payload_bay_ = MakePayload(config.payload, X_RP_bay_);
  bay_ = MakeCargoBay(config.shuttle);
  cae_ = MakeCaeFrontHalf(config.cae);
  Reset();
}

void DynamicCollisionProgram::Reset() {
  released_ = false;
  status_.released = false;
  status_.mode = 1;
  status_.acquired = false;
  status_.docked = false;
  status_.X_RP = X_RP_bay_;
  have_slave_ = false;
}

double DynamicCollisionProgram::FingerGapFt(double lever) const {
  const auto& e = config_.end_effector;
  return e.finger_gap_open_ft - lever * (e.finger_gap_open_ft - e.finger_gap_closed_ft);
}

void DynamicCollisionProgram::Evaluate(const ArmCommand& cmd, const Evaluation* prev, Evaluation* out) const {
  RMS_DASSERT(out != prev);
  Evaluation& e = *out;
  e.collisions = 0;
  e.extra_collisions = 0;
  e.ee_bar = {};
  e.ee_body = {};
  // A pair's options: sphere rejection, and its previous plane as the hint.
  SeparatingPlaneHint hints[2][3];
  auto opts = [&](const CollisionResult* last, SeparatingPlaneHint* hint) {
    CollideOptions o;
    o.relative_tolerance = tau_rel_;
    o.sphere_reject = o.aabb_reject = options_.bounding_reject;
    if (options_.frame_coherence && prev && last->verdict == Verdict::kSeparate && last->plane_valid) {
      hint->n = last->n;
      hint->d = last->d;
      o.hint = hint;
    }
    return o;
  };
  e.cmd = cmd;
  e.words = TransmittedArmWords(cmd.angles_deg);
  e.pose = ComputeArmPose(config_.arm, e.words, cmd.shoulder_height_ft);
  e.finger_gap_ft = FingerGapFt(cmd.finger);
  if (status_.mode >= 2) {
    const double widest = status_.docked ? config_.end_effector.finger_gap_open_ft : acquisition_gap_ft_;
    e.finger_gap_ft = std::clamp(e.finger_gap_ft, contact_gap_ft_, widest);
  }
  namespace cb = collision_bits;
  switch (status_.mode) {
    case 1: {
      // EFF HEX 1-3 against the BAR and against the payload's body.
      e.ee = MakeEndEffector(config_.end_effector, e.pose.X_RS2, e.finger_gap_ft);
      e.X_RP = X_RP_bay_;
      e.payload = payload_bay_;
      for (int k = 0; k < 3; ++k) {
        e.ee_bar[k] = Collide(e.ee.hex[k], bar_bay_, opts(prev ? &prev->ee_bar[k] : nullptr, &hints[0][k]));
        if (e.ee_bar[k].verdict != Verdict::kSeparate) e.collisions |= cb::kEffHexRecpt << k;
        // The body's plane serves only as the next frame's hint.
        CollideOptions body = opts(prev ? &prev->ee_body[k] : nullptr, &hints[1][k]);
        body.want_plane = options_.frame_coherence;
        e.ee_body[k] = Collide(e.ee.hex[k], payload_bay_.body, body);
        if (e.ee_body[k].verdict != Verdict::kSeparate) e.collisions |= cb::kEffHexPayload << k;
      }
      if (!options_.mode_pairs_only) {
        // The pairs of Modes 2 and 3, computed and discarded.
        CollideOptions o;
        o.sphere_reject = o.aabb_reject = options_.bounding_reject;
        e.extra_collisions |= Collide(payload_bay_.body, bay_, o).verdict != Verdict::kSeparate;
        e.extra_collisions |= Collide(payload_bay_.body, cae_, o).verdict != Verdict::kSeparate;
      }
      break;
    }
    case 2: {
      // The payload's and probe's vertices against the bay's walls and
      // bottom: a vertex below face c that is beyond a wall collides with it.
      e.X_RP = e.pose.X_RS2 * X_S2P_;
      e.payload = MakePayload(config_.payload, e.X_RP);
      const double tau = tau_rel_ * bay_.scale;
      for (const Eigen::Vector3d& v : e.payload.v) {
        const LocationWord w = bay_.Word(v, tau);
        if (!(w & FaceBit(kFaceC))) e.collisions |= static_cast<std::uint32_t>(w) << 6;
      }
      break;
    }
    default: {
      if (status_.docked) {
        e.X_RP = X_RP_docked_;  // captured by the CAE; the arm is free
        e.payload = MakePayload(config_.payload, e.X_RP);
        break;
      }
      // The payload's and probe's vertices against the CAE's front half.
      e.X_RP = e.pose.X_RS2 * X_S2P_;
      e.payload = MakePayload(config_.payload, e.X_RP);
      const double tau = tau_rel_ * cae_.scale;
      for (const Eigen::Vector3d& v : e.payload.v) {
        if (cae_.Word(v, tau) == 0) e.collisions |= cb::kPayloadCae;
      }
      break;
    }
  }
  if (!options_.mode_pairs_only && status_.mode >= 2) {
    // Every other pair, computed and discarded: the end effector against the
    // BAR and the payload where they are now, the payload against the bay
    // and the CAE as whole hexahedra.
    CollideOptions o;
    o.sphere_reject = o.aabb_reject = options_.bounding_reject;
    const EndEffectorModel ee = MakeEndEffector(config_.end_effector, e.pose.X_RS2, e.finger_gap_ft);
    const Hexahedron bar = MakeBar(config_.payload, e.X_RP);
    for (int k = 0; k < 3; ++k) {
      e.extra_collisions |= Collide(ee.hex[k], bar, o).verdict != Verdict::kSeparate;
      e.extra_collisions |= Collide(ee.hex[k], e.payload.body, o).verdict != Verdict::kSeparate;
    }
    e.extra_collisions |= Collide(e.payload.body, bay_, o).verdict != Verdict::kSeparate;
    e.extra_collisions |= Collide(e.payload.body, cae_, o).verdict != Verdict::kSeparate;
  }
}

void DynamicCollisionProgram::AcceptSpare() {
  std::swap(slave_, spare_);
  have_slave_ = true;
}

DcpFrameData DynamicCollisionProgram::Step(const OperatorInputs& in) {
  ArmCommand master;
  for (int i = 0; i < 6; ++i) master.angles_deg[i] = in.value[i];
  master.shoulder_height_ft = in.value[kShoulderHeight];
  master.finger = in.value[kFinger];
  if (in.reset) {
    Reset();
    spdlog::info("reset: Mode 1, payload in the cargo bay");
  }
  status_.master = master;
  status_.held = false;
  status_.finger_held = false;

  // A docked payload is captured at the port: the arm that holds it keeps
  // its pose and only the finger moves, until opening the finger releases it.
  ArmCommand command = master;
  if (status_.docked && !released_ && have_slave_) {
    if (slave_->finger_gap_ft >= acquisition_gap_ft_ + kReleaseOpeningFt) {
      released_ = true;
      spdlog::info("released: the finger let go of the docked payload; the arm is free");
    } else {
      command.angles_deg = slave_->cmd.angles_deg;
      command.shoulder_height_ft = slave_->cmd.shoulder_height_ft;
    }
  }
  Evaluate(command, have_slave_ ? slave_ : nullptr, spare_);
  const std::uint32_t collisions = spare_->collisions;
  status_.collisions = collisions;
  if (!have_slave_) {
    // The first frame after start or reset: the slave takes the command.
    AcceptSpare();
    if (collisions) spdlog::warn("starting in collision: {}", Names(collisions));
  } else if (collisions == 0) {
    AcceptSpare();
  } else {
    bool moved = false;
    if (status_.mode == 1 && master.finger != slave_->cmd.finger) {
      // The finger is what collides: let the arm follow and hold the finger.
      ArmCommand arm_only = master;
      arm_only.finger = slave_->cmd.finger;
      Evaluate(arm_only, slave_, spare_);
      if (spare_->collisions == 0) {
        AcceptSpare();
        status_.finger_held = true;
        moved = true;
      }
    }
    status_.held = !moved;
  }
  status_.released = released_;
  status_.slave_collisions = slave_->collisions;
  status_.slave = slave_->cmd;
  status_.X_RS2 = slave_->pose.X_RS2;
  status_.X_RP = slave_->X_RP;
  status_.finger_gap_ft = slave_->finger_gap_ft;

  UpdatePlanes();
  const int mode_before = status_.mode;
  UpdateDocking();  // distance and angle every frame; docking in Mode 3
  if (mode_before == 1) UpdateAcquisition();
  else if (mode_before == 2) UpdateExtraction();
  else status_.bay_clearance_ft = BayClearance(slave_->payload);

  DcpFrameData out;
  out.arm = slave_->words;
  out.control.camera_station = in.camera_station;
  out.control.reset = in.reset;
  out.control.overlay = in.overlay;
  out.control.crosshairs = in.crosshairs;
  out.control.mode = status_.mode;
  out.control.collision = (status_.collisions & ~collision_bits::kRecptMask) != 0;
  out.control.receptacle_collision = (status_.collisions & collision_bits::kRecptMask) != 0;
  out.control.acquired = status_.acquired;
  out.control.docked = status_.docked;
  out.shoulder_height_ft = slave_->cmd.shoulder_height_ft;
  out.finger_gap_ft = slave_->finger_gap_ft;
  out.camera_pan_deg = in.value[kCameraPan];
  out.camera_tilt_deg = in.value[kCameraTilt];
  out.camera_zoom = in.value[kCameraZoom];
  out.p_RoPo_R_ft = status_.X_RP.translation();
  out.R_RP = status_.X_RP.linear();
  out.planes = status_.planes;
  out.plane_valid = status_.plane_valid;
  return out;
}

void DynamicCollisionProgram::UpdatePlanes() {
  // The three dynamic separating planes, EFF HEX 1-3 against the BAR (Mode 1).
  // A plane not valid this frame is sent as the default (n = Z, d = 0), so
  // its words do not depend on earlier frames (a valid plane may, through
  // frame coherence; the checkpoint keeps the planes).
  status_.plane_valid = 0;
  status_.planes = {};
  if (status_.mode != 1) return;
  for (int k = 0; k < 3; ++k) {
    const CollisionResult& r = slave_->ee_bar[k];
    if (r.verdict == Verdict::kSeparate && r.plane_valid) {
      // Centred in the gap, to survive rounding to the plane words.
      status_.planes[k] = {r.n, MidGapOffset(slave_->ee.hex[k], bar_bay_, r.n)};
      status_.plane_valid |= 1u << k;
    }
  }
}

void DynamicCollisionProgram::RefreshMeasures() {
  if (!have_slave_) return;
  UpdatePlanes();
  const DockingCheck d = CheckDocking(config_.dcp, config_.cae, cae_, slave_->payload, tau_rel_);
  status_.probe_in_envelope = d.in_envelope;
  status_.envelope_margin_ft = d.envelope_margin_ft;
  status_.dock_distance_ft = d.distance_ft;
  status_.dock_angle_deg = d.angle_deg;
  status_.bay_clearance_ft = BayClearance(slave_->payload);
  status_.acquisition = {};
  status_.acquisition_margin_ft = {};
  status_.palm_to_bar_ft = 0.0;
  if (status_.mode == 1) {
    const AcquisitionCheck c = CheckAcquisition(config_.dcp, slave_->ee, bar_bay_, slave_->finger_gap_ft, tau_rel_);
    status_.acquisition = c.holds;
    status_.acquisition_margin_ft = c.margin_ft;
    status_.palm_to_bar_ft = c.palm_to_bar_ft;
  }
}

double DynamicCollisionProgram::BayClearance(const PayloadModel& p) const {
  // Height above the bay's top face c (its outward normal is +Z_R).
  double lowest = 1e30;
  for (const Eigen::Vector3d& v : p.v) lowest = std::min(lowest, bay_.Beyond(kFaceC, v.x(), v.y(), v.z()));
  return lowest;
}

bool AcquisitionCheck::all() const {
  return std::all_of(holds.begin(), holds.end(), [](bool b) { return b; });
}

AcquisitionCheck CheckAcquisition(const DcpConfig& dcp, const EndEffectorModel& ee, const Hexahedron& bar,
                                  double finger_gap_ft, double relative_tolerance) {
  const Hexahedron& h1 = ee.hex[0];
  const Hexahedron& h2 = ee.hex[1];
  const Hexahedron& h3 = ee.hex[2];
  const double tau = relative_tolerance * std::max(h1.scale, bar.scale);
  AcquisitionCheck c;
  c.finger_gap_ft = finger_gap_ft;
  c.holds[0] = AllHave(h1.Words(bar, tau), kFaceD);
  c.holds[1] = AllHave(h2.Words(bar, tau), kFaceB);
  c.holds[2] = AllHave(h3.Words(bar, tau), kFaceE);
  c.holds[3] = finger_gap_ft < dcp.d3y_ft;
  Eigen::Vector3d top = Eigen::Vector3d::Zero();
  for (int v : kFaceVertices[kFaceC]) top += bar.vertex(v);
  top *= 0.25;
  c.palm_to_bar_ft = h1.Beyond(kFaceD, top.x(), top.y(), top.z());
  // The report's "distance": unsigned (a BAR behind the palm's face d is not
  // near it; condition 1 fails there anyway, so acquisition is unchanged).
  c.holds[4] = std::abs(c.palm_to_bar_ft) < dcp.tpob_ft;
  bool between = true;
  for (LocationWord w : bar.Words(h1, tau)) between = between && !(w & (FaceBit(kFaceA) | FaceBit(kFaceD)));
  c.holds[5] = between;
  // Margins (docs/collision.md "Margins"): least depths, ft.
  auto least_beyond = [](const Hexahedron& h, int face, const Hexahedron& of) {
    double m = 1e30;
    for (int i = 0; i < kNumVertices; ++i) m = std::min(m, h.Beyond(face, of.x[i], of.y[i], of.z[i]));
    return m;
  };
  c.margin_ft[0] = least_beyond(h1, kFaceD, bar);
  c.margin_ft[1] = least_beyond(h2, kFaceB, bar);
  c.margin_ft[2] = least_beyond(h3, kFaceE, bar);
  c.margin_ft[3] = dcp.d3y_ft - finger_gap_ft;
  c.margin_ft[4] = dcp.tpob_ft - std::abs(c.palm_to_bar_ft);
  double inside = 1e30;
  for (int i = 0; i < kNumVertices; ++i) {
    inside = std::min({inside, -bar.Beyond(kFaceA, h1.x[i], h1.y[i], h1.z[i]),
                       -bar.Beyond(kFaceD, h1.x[i], h1.y[i], h1.z[i])});
  }
  c.margin_ft[5] = inside;
  return c;
}

DockingCheck CheckDocking(const DcpConfig& dcp, const CaeConfig& cae, const Hexahedron& front,
                          const PayloadModel& p, double relative_tolerance) {
  DockingCheck d;
  const double tau = relative_tolerance * front.scale;
  const LocationWord sides = FaceBit(kFaceA) | FaceBit(kFaceB) | FaceBit(kFaceD) | FaceBit(kFaceE);
  d.in_envelope = true;
  d.envelope_margin_ft = 1e30;
  for (int i = kProbeFirst; i < kPayloadVertices; ++i) {
    const LocationWord w = front.Word(p.v[i], tau);
    d.in_envelope = d.in_envelope && (w & FaceBit(kFaceC)) && !(w & sides);
    const Eigen::Vector3d& v = p.v[i];
    d.envelope_margin_ft = std::min({d.envelope_margin_ft, front.Beyond(kFaceC, v.x(), v.y(), v.z()),
                                     -front.Beyond(kFaceA, v.x(), v.y(), v.z()), -front.Beyond(kFaceB, v.x(), v.y(), v.z()),
                                     -front.Beyond(kFaceD, v.x(), v.y(), v.z()), -front.Beyond(kFaceE, v.x(), v.y(), v.z())});
  }
  d.distance_ft = (p.probe_tip_centre - cae.p_RoCo_R_ft).norm();
  const double c = std::clamp(p.probe_axis.dot(cae.R_RC.col(1)), -1.0, 1.0);
  d.angle_deg = std::acos(c) * 180.0 / M_PI;
  d.docked = d.in_envelope && d.distance_ft <= dcp.dock_distance_ft && d.angle_deg <= dcp.dock_angle_deg;
  return d;
}

void DynamicCollisionProgram::UpdateAcquisition() {
  // Report IV.A.3: the six conditions, on the slave's (collision-free) pose.
  const AcquisitionCheck c =
      CheckAcquisition(config_.dcp, slave_->ee, bar_bay_, slave_->finger_gap_ft, tau_rel_);
  status_.acquisition = c.holds;
  status_.acquisition_margin_ft = c.margin_ft;
  status_.palm_to_bar_ft = c.palm_to_bar_ft;
  status_.bay_clearance_ft = BayClearance(slave_->payload);
  if (c.all()) {
    status_.mode = 2;
    status_.acquired = true;
    X_S2P_ = slave_->pose.X_RS2.inverse() * X_RP_bay_;
    // The gap at which face e of EFF HEX 3 would touch the bar: from face b
    // of EFF HEX 2 (at Y2 = W - t) to the bar's nearest vertex along -Y2.
    const Hexahedron& bar = bar_bay_;
    double y_min = 1e30;
    for (int i = 0; i < kNumVertices; ++i) {
      y_min = std::min(y_min, slave_->pose.X_RS2.linear().col(1).dot(bar.vertex(i) - slave_->pose.X_RS2.translation()));
    }
    const auto& ee = config_.end_effector;
    acquisition_gap_ft_ = slave_->finger_gap_ft;
    contact_gap_ft_ = std::clamp(ee.palm_half_width_ft - ee.finger_thickness_ft - y_min + kFingerContactClearanceFt,
                                 0.0, acquisition_gap_ft_);
    spdlog::info("acquisition: Mode 1 -> Mode 2 (finger gap {:.3f} ft, palm to bar {:.3f} ft)",
                 c.finger_gap_ft, c.palm_to_bar_ft);
  }
}

void DynamicCollisionProgram::UpdateExtraction() {
  // Report IV.A.3: all payload and probe vertices above the bay's face c.
  // The conditions of acquisition are not evaluated after it.
  status_.acquisition = {};
  status_.acquisition_margin_ft = {};
  status_.palm_to_bar_ft = 0.0;
  status_.bay_clearance_ft = BayClearance(slave_->payload);
  const double tau = tau_rel_ * bay_.scale;
  for (const Eigen::Vector3d& v : slave_->payload.v) {
    if (!(bay_.Word(v, tau) & FaceBit(kFaceC))) return;
  }
  status_.mode = 3;
  spdlog::info("clear of the cargo bay: Mode 2 -> Mode 3");
}

void DynamicCollisionProgram::UpdateDocking() {
  const DockingCheck d = CheckDocking(config_.dcp, config_.cae, cae_, slave_->payload, tau_rel_);
  status_.probe_in_envelope = d.in_envelope;
  status_.envelope_margin_ft = d.envelope_margin_ft;
  status_.dock_distance_ft = d.distance_ft;
  status_.dock_angle_deg = d.angle_deg;
  if (status_.mode == 3 && !status_.docked && d.docked) {
    status_.docked = true;
    X_RP_docked_ = slave_->X_RP;
    spdlog::info("docked: distance {:.3f} ft, angle {:.3f} deg", d.distance_ft, d.angle_deg);
  }
}

namespace {

nlohmann::json PoseJson(const Eigen::Isometry3d& X) {
  nlohmann::json j = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) j.push_back(X.matrix()(r, c));
  }
  return j;
}

Eigen::Isometry3d PoseFrom(const nlohmann::json& j, const char* key) {
  if (!j.is_array() || j.size() != 12) throw InputError(std::string("checkpoint: '") + key + "' must be 12 numbers");
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) X.matrix()(r, c) = j.at(4 * r + c).get<double>();
  }
  return X;
}

nlohmann::json CommandJson(const ArmCommand& a) {
  return {{"angles_deg", a.angles_deg}, {"shoulder_height_ft", a.shoulder_height_ft}, {"finger", a.finger}};
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
  return {r.n.x(), r.n.y(), r.n.z(), r.d};
}

void PlaneFrom(const nlohmann::json& j, CollisionResult* r) {
  if (j.is_null()) return;
  if (!j.is_array() || j.size() != 4) throw InputError("checkpoint: a plane must be null or 4 numbers");
  r->verdict = Verdict::kSeparate;
  r->plane_valid = true;
  r->n = Eigen::Vector3d(j[0].get<double>(), j[1].get<double>(), j[2].get<double>());
  r->d = j[3].get<double>();
}

}  // namespace

nlohmann::ordered_json DynamicCollisionProgram::SaveState() const {
  nlohmann::ordered_json j;
  j["format"] = kCheckpointFormat;
  j["mode"] = status_.mode;
  j["acquired"] = status_.acquired;
  j["docked"] = status_.docked;
  j["released"] = released_;
  j["have_slave"] = have_slave_;
  j["slave"] = CommandJson(slave_->cmd);
  j["slave_collisions"] = slave_->collisions;
  j["master"] = CommandJson(status_.master);
  j["X_S2P"] = PoseJson(X_S2P_);
  j["X_RP_docked"] = PoseJson(X_RP_docked_);
  j["contact_gap_ft"] = contact_gap_ft_;
  j["acquisition_gap_ft"] = acquisition_gap_ft_;
  // The slave's separating planes, the next frame's hints (frame coherence).
  nlohmann::json bar = nlohmann::json::array(), body = nlohmann::json::array();
  for (int k = 0; k < 3; ++k) {
    bar.push_back(PlaneJson(slave_->ee_bar[k]));
    body.push_back(PlaneJson(slave_->ee_body[k]));
  }
  j["planes_ee_bar"] = bar;
  j["planes_ee_body"] = body;
  return j;
}

void DynamicCollisionProgram::RestoreState(const nlohmann::json& j) {
  try {
    if (j.at("format").get<std::string>() != kCheckpointFormat) {
      throw InputError("checkpoint: format '" + j.at("format").get<std::string>() + "', expected '" +
                       kCheckpointFormat + "'");
    }
    const int mode = j.at("mode").get<int>();
    if (mode < 1 || mode > 3) throw InputError("checkpoint: mode must be 1, 2 or 3");
    status_.mode = mode;
    status_.acquired = j.at("acquired").get<bool>();
    status_.docked = j.at("docked").get<bool>();
    released_ = j.at("released").get<bool>();
    status_.released = released_;
    X_S2P_ = PoseFrom(j.at("X_S2P"), "X_S2P");
    X_RP_docked_ = PoseFrom(j.at("X_RP_docked"), "X_RP_docked");
    contact_gap_ft_ = j.at("contact_gap_ft").get<double>();
    acquisition_gap_ft_ = j.at("acquisition_gap_ft").get<double>();
    status_.master = CommandFrom(j.at("master"));
    have_slave_ = j.at("have_slave").get<bool>();
    if (have_slave_) {
      // The slave's evaluation follows from its command and the state above.
      // The saved planes are the hints, as they were for the saved frame.
      Evaluation prev;
      if (j.contains("planes_ee_bar")) {
        for (int k = 0; k < 3; ++k) {
          PlaneFrom(j.at("planes_ee_bar").at(k), &prev.ee_bar[k]);
          PlaneFrom(j.at("planes_ee_body").at(k), &prev.ee_body[k]);
        }
      }
      Evaluate(CommandFrom(j.at("slave")), &prev, slave_);
      slave_->collisions = j.at("slave_collisions").get<std::uint32_t>();
      status_.slave = slave_->cmd;
      status_.X_RS2 = slave_->pose.X_RS2;
      status_.X_RP = slave_->X_RP;
      status_.finger_gap_ft = slave_->finger_gap_ft;
      RefreshMeasures();  // nothing of the frames before the restore
    } else {
      status_.X_RP = X_RP_bay_;
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(std::string("checkpoint: ") + e.what());
  }
}

}  // namespace rms::dcp
