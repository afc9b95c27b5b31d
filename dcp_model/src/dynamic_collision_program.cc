#include "rms/dcp_model/dynamic_collision_program.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <spdlog/spdlog.h>

#include "rms/base/check.h"
#include "rms/scene_model/scene_model.h"
#include "rms/wire/dcp_mode.h"
#include "rms/wire/word_codec.h"

#include "program_internal.h"

namespace rms::dcp_model {

using internal::Finite;
using internal::MakeMalfunctions;

arm::ArmSinCos TransmittedArmWords(const std::array<double, 6>& angles_deg) {
  arm::ArmSinCos sc = arm::SinCosFromDegrees(angles_deg);
  for (arm::SinCos& a : sc) {
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

}  // namespace

namespace internal {

// The malfunctions' frame rate and each joint's travel: the arm's joint
// limits within the input's range (config [arm], [inputs.*]).
Malfunctions MakeMalfunctions(const LabConfig& config) {
  std::array<double, 6> lo{}, hi{};
  for (int i = 0; i < kNumJoints; ++i) {
    lo[i] = std::max(config.arm.joint_min_deg[i], config.inputs[i].min);
    hi[i] = std::min(config.arm.joint_max_deg[i], config.inputs[i].max);
  }
  return Malfunctions(config.session.frame_rate_hz, lo, hi);
}

}  // namespace internal

DynamicCollisionProgram::DynamicCollisionProgram(const LabConfig& config, const DcpOptions& options)
    : config_(config), options_(options), malfunctions_(MakeMalfunctions(config)) {
  X_RP_bay_ = arm::MakeIsometry(config.payload.R_RP, config.payload.p_RoPo_R_ft);
  bay_ = MakeCargoBay(config.shuttle);
  cae_ = MakeCaeFrontHalf(config.cae);
  PlacePayload(X_RP_bay_);
  // The substep: at most kMaxSubstepTravelFt, and under half the thinnest
  // solid tested against another (the fingers, the BAR, its posts), so no
  // solid can step through another between two tested poses.
  const auto& ee = config.end_effector;
  double thinnest =
      std::min({ee.finger_thickness_ft, 2 * ee.palm_half_width_ft, 2 * ee.palm_half_height_ft,
                ee.palm_length_ft, ee.finger_length_ft, config.payload.bar_size_P_ft.minCoeff()});
  if (post_count_ > 0)
    thinnest = std::min(thinnest, 2 * scene_model::BarPosts_P(config.payload).half_P.minCoeff());
  substep_ft_ = std::min(kMaxSubstepTravelFt, 0.45 * thinnest);
  // The slave starts at the initial inputs' pose, which must be free.
  const wire::OperatorInputs initial = wire::InitialInputs(config.inputs);
  ArmCommand start;
  for (int i = 0; i < kNumJoints; ++i) start.angles_deg[i] = initial.value[i];
  start.shoulder_height_ft = initial.value[kShoulderHeight];
  start.finger = initial.value[kFinger];
  Evaluate(start, nullptr, slave_);
  if (slave_->collisions) {
    throw InputError("inputs.*.initial: the arm's initial pose collides (" +
                     wire::CollisionNames(slave_->collisions, ", ", "none") +
                     "); the DCP needs a collision-free pose to start from");
  }
  initial_ = start;
  status_.master = status_.slave = start;
  status_.X_RS2 = slave_->pose.X_RS2;
  status_.X_RP = slave_->X_RP;
  status_.finger_gap_ft = slave_->finger_gap_ft;
}

void DynamicCollisionProgram::PlacePayload(const Eigen::Isometry3d& X_RP) {
  X_RP_free_ = X_RP;
  bar_ = MakeBar(config_.payload, X_RP);
  payload_ = MakePayload(payload_shape_, X_RP);
  post_count_ = MakeBarPosts(config_.payload, X_RP, &posts_);
}

ArmCommand DynamicCollisionProgram::SlaveAsItIs() const {
  // In Modes 2 and 3 the finger's gap is clamped to the bar; the lever that
  // gives that gap unclamped, so the slave evaluated in Mode 1 is where it is.
  ArmCommand c = slave_->cmd;
  const auto& e = config_.end_effector;
  c.finger = (e.finger_gap_open_ft - slave_->finger_gap_ft) /
             (e.finger_gap_open_ft - e.finger_gap_closed_ft);
  return c;
}

bool DynamicCollisionProgram::Reset() {
  // The reset scene: Mode 1, the payload in the bay. The arm stays; where it
  // is must be free there, or the reset is refused.
  const Eigen::Isometry3d X_RP_free = X_RP_free_;
  const wire::DcpMode mode = status_.mode;
  const bool acquired = status_.acquired, docked = status_.docked, released = released_;
  const double reach = payload_reach_ft_;
  PlacePayload(X_RP_bay_);
  status_.mode = wire::DcpMode::kAcquisition;
  status_.acquired = status_.docked = false;
  released_ = false;
  payload_reach_ft_ = 0.0;
  Evaluate(SlaveAsItIs(), slave_, spare_);
  if (spare_->collisions) {
    spdlog::warn(
        "reset refused: the arm where it is would collide with the payload in the bay ({}); "
        "move the arm clear and reset again",
        wire::CollisionNames(spare_->collisions, ", ", "none"));
    PlacePayload(X_RP_free);
    status_.mode = mode;
    status_.acquired = acquired;
    status_.docked = docked;
    released_ = released;
    payload_reach_ft_ = reach;
    return false;
  }
  AcceptSpare();
  status_.released = false;
  status_.X_RP = X_RP_bay_;
  return true;
}

double DynamicCollisionProgram::FingerGapFt(double lever) const {
  const auto& e = config_.end_effector;
  return e.finger_gap_open_ft - lever * (e.finger_gap_open_ft - e.finger_gap_closed_ft);
}

bool internal::Finite(const ArmCommand& c) {
  double zero = c.shoulder_height_ft * 0.0 + c.finger * 0.0;
  for (double a : c.angles_deg) zero += a * 0.0;
  return zero == 0.0;
}

namespace {

bool Finite(const PayloadModel& p) {
  double zero = 0.0;
  for (const Eigen::Vector3d& v : p.v) zero += (v.x() + v.y() + v.z()) * 0.0;
  // Without its strips (HeldPayload: only near enough that they are valid).
  for (const Hexahedron& h : p.body) zero += !p.has_body || h.valid ? 0.0 : NAN;
  return zero == 0.0;
}

// TestMotion's answer for a motion beyond kMaxSubsteps: not a collision bit.
constexpr std::uint32_t kTooFast = 1u << 31;

ArmCommand Lerp(const ArmCommand& a, const ArmCommand& b, double t) {
  ArmCommand c;
  for (int i = 0; i < kNumJoints; ++i)
    c.angles_deg[i] = a.angles_deg[i] + t * (b.angles_deg[i] - a.angles_deg[i]);
  c.shoulder_height_ft = a.shoulder_height_ft + t * (b.shoulder_height_ft - a.shoulder_height_ft);
  c.finger = a.finger + t * (b.finger - a.finger);
  return c;
}

}  // namespace

namespace {
// A pair's gap lower bound from its separating plane (0: colliding or none).
double PairGap(const CollisionResult& r, const Hexahedron& a, const Hexahedron& b) {
  if (r.verdict != Verdict::kSeparate || !r.plane_valid) return 0.0;
  return std::max(0.0, GapAlong(a, b, r.plane.n_R));
}
}  // namespace

std::uint32_t DynamicCollisionProgram::BayCollisions(const PayloadModel& p,
                                                     double* clearance_ft) const {
  // The payload lives inside the bay: a vertex not above face c (by more
  // than tau) that is on or beyond a wall or the bottom (within tau:
  // touching counts) collides with it.
  const double tau = ToleranceFt(bay_, bay_, tau_rel_);
  std::uint32_t bits = 0;
  for (const Eigen::Vector3d& v : p.v) {
    const double above = bay_.Beyond(kFaceC, v.x(), v.y(), v.z());
    for (int f : {kFaceA, kFaceB, kFaceD, kFaceE, kFaceF}) {
      const double beyond = bay_.Beyond(f, v.x(), v.y(), v.z());
      if (above <= tau && beyond >= -tau) bits |= static_cast<std::uint32_t>(FaceBit(f)) << 6;
      // The distance to "below face c and beyond this wall" is at least the
      // larger of the height above c and the depth inside the wall.
      *clearance_ft = std::min(*clearance_ft, std::max(above, -beyond));
    }
  }
  return bits;
}

void DynamicCollisionProgram::TestHandAgainstPayload(const Evaluation* prev,
                                                     Evaluation* out) const {
  // EFF HEX 1-3 against the resting payload's BAR, body (seven strips) and
  // the BAR's posts, with each pair's clearance.
  namespace cb = wire::collision_bits;
  Evaluation& e = *out;
  // A pair's options: bounding rejection, and its previous plane as the hint.
  scene_model::SeparatingPlane hints[1 + kBodyStrips][3];
  auto opts = [&](const CollisionResult* last, scene_model::SeparatingPlane* hint) {
    CollideOptions o;
    o.relative_tolerance = tau_rel_;
    o.sphere_reject = o.aabb_reject = options_.bounding_reject;
    if (options_.frame_coherence && prev && last->verdict == Verdict::kSeparate &&
        last->plane_valid) {
      *hint = last->plane;
      o.hint = hint;
    }
    return o;
  };
  CollideOptions plain;
  plain.relative_tolerance = tau_rel_;
  plain.sphere_reject = plain.aabb_reject = options_.bounding_reject;
  e.clearance_ft = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    const Hexahedron& h = e.ee.hex[k];
    if (!h.valid) e.collisions |= cb::kNonFinite;
    e.ee_bar[k] = Collide(h, bar_, opts(prev ? &prev->ee_bar[k] : nullptr, &hints[0][k]));
    if (e.ee_bar[k].verdict != Verdict::kSeparate) e.collisions |= cb::kEffHexRecpt << k;
    e.clearance_ft = std::min(e.clearance_ft, PairGap(e.ee_bar[k], h, bar_));
    for (int j = 0; j < kBodyStrips; ++j) {
      const int i = k * kBodyStrips + j;
      e.ee_body[i] =
          Collide(h, payload_.body[j], opts(prev ? &prev->ee_body[i] : nullptr, &hints[1 + j][k]));
      if (e.ee_body[i].verdict != Verdict::kSeparate) e.collisions |= cb::kEffHexPayload << k;
      e.clearance_ft = std::min(e.clearance_ft, PairGap(e.ee_body[i], h, payload_.body[j]));
    }
    for (int j = 0; j < post_count_; ++j) {
      const CollisionResult r = Collide(h, posts_[j], plain);
      if (r.verdict != Verdict::kSeparate) e.collisions |= cb::kEffHexBarPost;
      e.clearance_ft = std::min(e.clearance_ft, PairGap(r, h, posts_[j]));
    }
  }
}

// Mode 1: EFF HEX 1-3 against the BAR, the payload's body and the BAR's posts.
void DynamicCollisionProgram::EvaluateMode1(const Evaluation* prev, Evaluation* e) const {
  e->ee = MakeEndEffector(config_.end_effector, e->pose.X_RS2, e->finger_gap_ft);
  e->X_RP = X_RP_free_;
  e->payload = payload_;
  TestHandAgainstPayload(prev, e);
  if (options_.mode_pairs_only) return;
  // The pairs of Modes 2 and 3, computed and discarded.
  CollideOptions plain;
  plain.sphere_reject = plain.aabb_reject = options_.bounding_reject;
  plain.want_plane = false;
  for (const Hexahedron& strip : payload_.body) {
    e->extra_collisions |= Collide(strip, bay_, plain).verdict != Verdict::kSeparate;
    e->extra_collisions |= Collide(strip, cae_, plain).verdict != Verdict::kSeparate;
  }
}

// The held payload at X_RP for Modes 2 and 3, which test only its vertices:
// without its seven strips -- unless every pair is tested
// (EvaluateExtraPairs), or it is so far out (beyond kStripsCheckedBeyondFt)
// that the strips' own checks (flatness and face areas against the rounding
// at such coordinates) could refuse it: then with them, so Finite() decides
// exactly as when the strips were always made.
PayloadModel DynamicCollisionProgram::HeldPayload(const Eigen::Isometry3d& X_RP) const {
  if (!options_.mode_pairs_only) return MakePayload(payload_shape_, X_RP, true);
  PayloadModel m = MakePayload(payload_shape_, X_RP, false);
  double largest = 0.0;
  for (const Eigen::Vector3d& v : m.v) largest = std::max(largest, v.cwiseAbs().maxCoeff());
  if (!(largest <= kStripsCheckedBeyondFt) || !payload_strips_valid_)
    m = MakePayload(payload_shape_, X_RP, true);
  return m;
}

// Mode 2: the payload's and probe's vertices against the bay's walls and
// bottom: a vertex below face c that is beyond a wall collides with it.
void DynamicCollisionProgram::EvaluateMode2(Evaluation* e) const {
  e->X_RP = e->pose.X_RS2 * X_S2P_;
  e->payload = HeldPayload(e->X_RP);
  e->clearance_ft = std::numeric_limits<double>::infinity();
  e->collisions |= BayCollisions(e->payload, &e->clearance_ft);
}

// Mode 3: the payload's and probe's vertices against the CAE's front half,
// and still against the bay's walls while any is below face c (lowered back
// toward the bay, it cannot pass through them). Docked: the payload is
// captured by the CAE; let go, the hand is tested against it as in Mode 1
// (it cannot pass back through the bar).
void DynamicCollisionProgram::EvaluateMode3(const Evaluation* prev, Evaluation* e) const {
  if (status_.docked) {
    e->X_RP = X_RP_docked_;
    e->payload = payload_;  // placed at the dock
    e->clearance_ft = std::numeric_limits<double>::infinity();
    if (released_) {
      e->ee = MakeEndEffector(config_.end_effector, e->pose.X_RS2, e->finger_gap_ft);
      TestHandAgainstPayload(prev, e);
    }
    return;
  }
  e->X_RP = e->pose.X_RS2 * X_S2P_;
  e->payload = HeldPayload(e->X_RP);
  const double tau = ToleranceFt(cae_, cae_, tau_rel_);
  e->clearance_ft = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& v : e->payload.v) {
    if (cae_.Word(v, tau) == 0) e->collisions |= wire::collision_bits::kPayloadCae;
    // Outside a convex solid, the farthest face plane is a lower bound on the distance to it.
    double out = -std::numeric_limits<double>::infinity();
    for (int f = 0; f < kNumFaces; ++f) out = std::max(out, cae_.Beyond(f, v.x(), v.y(), v.z()));
    e->clearance_ft = std::min(e->clearance_ft, std::max(0.0, out));
  }
  e->collisions |= BayCollisions(e->payload, &e->clearance_ft);
}

// Modes 2 and 3 with every pair (DcpOptions::mode_pairs_only off): the end
// effector against the BAR and the payload where they are now, the payload
// against the bay and the CAE as whole hexahedra, computed and discarded.
void DynamicCollisionProgram::EvaluateExtraPairs(Evaluation* e) const {
  CollideOptions o;
  o.sphere_reject = o.aabb_reject = options_.bounding_reject;
  const EndEffectorModel ee =
      MakeEndEffector(config_.end_effector, e->pose.X_RS2, e->finger_gap_ft);
  const Hexahedron bar = MakeBar(config_.payload, e->X_RP);
  for (int k = 0; k < 3; ++k) {
    e->extra_collisions |= Collide(ee.hex[k], bar, o).verdict != Verdict::kSeparate;
    for (const Hexahedron& strip : e->payload.body)
      e->extra_collisions |= Collide(ee.hex[k], strip, o).verdict != Verdict::kSeparate;
  }
  for (const Hexahedron& strip : e->payload.body) {
    e->extra_collisions |= Collide(strip, bay_, o).verdict != Verdict::kSeparate;
    e->extra_collisions |= Collide(strip, cae_, o).verdict != Verdict::kSeparate;
  }
}

void DynamicCollisionProgram::Evaluate(const ArmCommand& cmd, const Evaluation* prev,
                                       Evaluation* out) const {
  RMS_DASSERT(out != prev);
  Evaluation& e = *out;
  e.scene = Scene();
  e.collisions = 0;
  e.extra_collisions = 0;
  e.ee_bar = {};
  e.ee_body = {};
  e.cmd = cmd;
  e.words = TransmittedArmWords(cmd.angles_deg);
  e.pose = arm::ComputeArmPose(config_.arm, e.words, cmd.shoulder_height_ft);
  e.finger_gap_ft = FingerGapFt(cmd.finger);
  if (status_.mode >= wire::DcpMode::kExtraction && !(status_.docked && released_)) {
    const double widest =
        status_.docked ? config_.end_effector.finger_gap_open_ft : acquisition_gap_ft_;
    e.finger_gap_ft = std::clamp(e.finger_gap_ft, contact_gap_ft_, widest);
  }
  switch (status_.mode) {
    case wire::DcpMode::kAcquisition:
      EvaluateMode1(prev, &e);
      break;
    case wire::DcpMode::kExtraction:
      EvaluateMode2(&e);
      break;
    case wire::DcpMode::kManoeuvring:
      EvaluateMode3(prev, &e);
      break;
  }
  // Non-finite models (a pose from non-finite words or a restored state)
  // are refused as a collision, never read as "no collision".
  if (!Finite(e.payload) || !e.pose.X_RS2.matrix().allFinite())
    e.collisions |= wire::collision_bits::kNonFinite;
  if (e.collisions) e.clearance_ft = 0.0;
  e.mode = status_.mode;
  if (!options_.mode_pairs_only && status_.mode >= wire::DcpMode::kExtraction)
    EvaluateExtraPairs(&e);
}

void DynamicCollisionProgram::AcceptSpare() { std::swap(slave_, spare_); }

std::array<double, 6> DynamicCollisionProgram::JointReachFt() const {
  // Joint i turns only what lies beyond it; a moving vertex is at most this
  // far from its axis (the links from the joint out, then the hand: the end
  // effector's farthest vertex from point A, or the held payload's).
  const auto& a = config_.arm;
  const auto& ee = config_.end_effector;
  const double hand = std::max(ee.palm_length_ft + ee.finger_length_ft +
                                   std::hypot(ee.palm_half_width_ft, ee.palm_half_height_ft),
                               payload_reach_ft_);
  const double at_w = a.wrist_to_palm_ft + hand, at_e = a.lower_boom_ft + at_w,
               at_s = a.upper_boom_ft + at_e;
  return {at_s, at_s, at_e, at_w, at_w, at_w};
}

double DynamicCollisionProgram::TravelFt(const ArmCommand& from, const ArmCommand& to) const {
  // A bound on any model vertex's travel along the motion: each joint's
  // angle (rad) times its reach; the shoulder's height moves all alike; the
  // finger moves the movable finger alone.
  const std::array<double, 6> reach = JointReachFt();
  double travel = std::abs(to.shoulder_height_ft - from.shoulder_height_ft);
  for (int i = 0; i < kNumJoints; ++i)
    travel += std::abs(to.angles_deg[i] - from.angles_deg[i]) * (M_PI / 180.0) * reach[i];
  return travel + std::abs(FingerGapFt(to.finger) - FingerGapFt(from.finger));
}

double DynamicCollisionProgram::WordSlackFt() const {
  // The arm words' rounding (SC22, 2^-22) moves each tested pose off the
  // straight interpolation by at most this; two poses, twice.
  const std::array<double, 6> reach = JointReachFt();
  double slack = 0.0;
  for (double r : reach) slack += 2.0 * std::ldexp(1.0, -22) * r;
  return 2.0 * slack;
}

int DynamicCollisionProgram::Substeps(double travel_ft) const {
  const double n = std::ceil(travel_ft / substep_ft_);
  if (!(n <= kMaxSubsteps)) return -1;
  return std::max(1, static_cast<int>(n));
}

std::uint32_t DynamicCollisionProgram::TestMotion(const ArmCommand& from, const ArmCommand& to,
                                                  Evaluation* out) {
  Evaluate(to, slave_, out);  // the end pose first: most collisions show there
  status_.substeps = 1;
  if (out->collisions) return out->collisions;
  const double travel = TravelFt(from, to);
  const int n = Substeps(travel);
  if (n < 0) {
    status_.too_fast = true;
    return kTooFast;
  }
  if (travel <= 0.0) return 0;  // nothing moves
  const double step_ft = travel / n, slack_ft = WordSlackFt();
  // The slave's clearance, when it was evaluated in this mode (else unknown).
  double c_prev = slave_->mode == status_.mode ? slave_->clearance_ft : 0.0;
  // The two ends' clearances cover the whole travel: nothing can touch
  // between them (conservative advancement); the usual frame costs one test.
  if (c_prev + out->clearance_ft > travel + slack_ft) return 0;
  for (int k = 1; k <= n; ++k) {
    double c = out->clearance_ft;
    if (k < n) {
      Evaluate(Lerp(from, to, static_cast<double>(k) / n), slave_, scratch_);
      ++status_.substeps;
      if (scratch_->collisions) {
        status_.motion_collision = true;
        return scratch_->collisions;
      }
      c = scratch_->clearance_ft;
    }
    double hit_s = 0.0;
    const std::uint32_t bits =
        Refine(from, to, static_cast<double>(k - 1) / n, static_cast<double>(k) / n, c_prev, c,
               step_ft, slack_ft, 0, &hit_s);
    if (bits) {
      status_.motion_collision = true;
      return bits;
    }
    c_prev = c;
  }
  return 0;
}

std::uint32_t DynamicCollisionProgram::Refine(const ArmCommand& from, const ArmCommand& to,
                                              double s0, double s1, double c0, double c1,
                                              double travel_ft, double slack_ft, int depth,
                                              double* hit_s) {
  if (c0 + c1 > travel_ft + slack_ft || depth >= kRefineDepth) return 0;
  const double sm = 0.5 * (s0 + s1);
  Evaluate(Lerp(from, to, sm), slave_, probe_);
  ++status_.substeps;
  if (probe_->collisions) {
    *hit_s = sm;
    return probe_->collisions;
  }
  const double cm = probe_->clearance_ft;
  if (const std::uint32_t bits =
          Refine(from, to, s0, sm, c0, cm, 0.5 * travel_ft, slack_ft, depth + 1, hit_s)) {
    return bits;
  }
  return Refine(from, to, sm, s1, cm, c1, 0.5 * travel_ft, slack_ft, depth + 1, hit_s);
}

std::uint32_t DynamicCollisionProgram::MoveFinger(double finger) {
  // From the slave's finger toward `finger`, the arm where the slave is: in
  // substeps (refined between them as any motion) to the first colliding
  // position, then bisection to within 1e-5 ft of gap.
  const ArmCommand from = slave_->cmd;
  const double f0 = from.finger;
  ArmCommand to = from;
  to.finger = finger;
  const double span_ft = std::abs(FingerGapFt(finger) - FingerGapFt(f0));
  const int n = Substeps(span_ft);
  if (n < 0 || !(span_ft > 0)) return 0;
  const double slack_ft = WordSlackFt();
  double free_s = 0.0, hit_s = 0.0, c_prev = slave_->clearance_ft;
  std::uint32_t bits = 0;
  for (int k = 1; k <= n && !bits; ++k) {
    const double s = static_cast<double>(k) / n;
    Evaluate(Lerp(from, to, s), slave_, scratch_);
    if (scratch_->collisions) {
      bits = scratch_->collisions;
      hit_s = s;
      break;
    }
    const double c_k = scratch_->clearance_ft;
    bits = Refine(from, to, free_s, s, c_prev, c_k, span_ft / n, slack_ft, 0, &hit_s);
    if (!bits) {
      free_s = s;
      c_prev = c_k;
    }
  }
  while (bits && (hit_s - free_s) * span_ft > 1e-5) {
    const double mid = 0.5 * (free_s + hit_s);
    Evaluate(Lerp(from, to, mid), slave_, scratch_);
    (scratch_->collisions ? hit_s : free_s) = mid;
  }
  if (free_s > 0.0) {
    Evaluate(Lerp(from, to, free_s), slave_, spare_);
    AcceptSpare();
  }
  return bits;
}

namespace {
// Bit for bit (-0 and 0 differ; a NaN equals the same NaN).
bool SameBits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}
template <typename Range>
bool SameBits(const Range& a, const Range& b) {
  return std::equal(std::begin(a), std::end(a), std::begin(b),
                    [](double x, double y) { return SameBits(x, y); });
}
bool SameBits(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b) {
  return std::equal(a.data(), a.data() + 16, b.data(),
                    [](double x, double y) { return SameBits(x, y); });
}
bool SameBits(const ArmCommand& a, const ArmCommand& b) {
  return SameBits(a.angles_deg, b.angles_deg) &&
         SameBits(a.shoulder_height_ft, b.shoulder_height_ft) && SameBits(a.finger, b.finger);
}
}  // namespace

bool DynamicCollisionProgram::SceneKey::operator==(const SceneKey& o) const {
  return mode == o.mode && docked == o.docked && released == o.released &&
         SameBits(contact_gap_ft, o.contact_gap_ft) &&
         SameBits(acquisition_gap_ft, o.acquisition_gap_ft) && SameBits(X_RP_free, o.X_RP_free) &&
         SameBits(X_S2P, o.X_S2P) && SameBits(X_RP_docked, o.X_RP_docked);
}

DynamicCollisionProgram::SceneKey DynamicCollisionProgram::Scene() const {
  SceneKey k;
  k.mode = status_.mode;
  k.docked = status_.docked;
  k.released = released_;
  k.contact_gap_ft = contact_gap_ft_;
  k.acquisition_gap_ft = acquisition_gap_ft_;
  k.X_RP_free = X_RP_free_.matrix();  // the payload, BAR and posts (PlacePayload)
  k.X_S2P = X_S2P_.matrix();
  k.X_RP_docked = X_RP_docked_.matrix();
  return k;
}

void DynamicCollisionProgram::Respond(const ArmCommand& command) {
  namespace cb = wire::collision_bits;
  // A still frame: evaluating the slave's own free pose again, in the same
  // scene, gives what it has (the evaluation is a function of the command
  // and the scene; with frame coherence, its hints are its own planes,
  // which decide as they did). The motion test's one evaluation, kept.
  if (options_.reuse_still && slave_->collisions == 0 && SameBits(command, slave_->cmd) &&
      slave_->scene == Scene()) {
    status_.substeps = 1;
    status_.collisions = 0;
    return;
  }
  const std::uint32_t hit = TestMotion(slave_->cmd, command, spare_);
  status_.collisions = hit & ~kTooFast;
  if (!hit) return AcceptSpare();
  if (status_.too_fast) {
    status_.held = true;
    return;
  }
  if (status_.mode == wire::DcpMode::kAcquisition && command.finger != slave_->cmd.finger) {
    // The finger is what collides: let the arm follow, and move the finger
    // as far as it goes (onto the bar: the essential contact).
    ArmCommand arm_only = command;
    arm_only.finger = slave_->cmd.finger;
    const bool closing = FingerGapFt(command.finger) < FingerGapFt(slave_->cmd.finger);
    const int substeps = status_.substeps;
    if (TestMotion(slave_->cmd, arm_only, spare_) == 0) {
      AcceptSpare();
      status_.finger_held = true;
      const std::uint32_t contact = MoveFinger(command.finger);
      status_.substeps += substeps;
      // Only the movable finger closing onto the BAR is essential; the palm
      // or a finger striking it, or the finger against anything else, is
      // detrimental (report II: "a finger ... contacts the end effector
      // receptacle in the physical relationship required").
      status_.essential_contact = closing && contact == (cb::kEffHexRecpt << 2);
      status_.collisions = contact ? contact : status_.collisions;
      return;
    }
  }
  status_.held = true;
}

void DynamicCollisionProgram::LetGo() {
  // The payload where it is, Mode 1; the arm where it is must be free of it
  // (it is, but for rounding through X_S2P), else the grasp is kept.
  const Eigen::Isometry3d X_RP_free = X_RP_free_;
  status_.mode = wire::DcpMode::kAcquisition;
  status_.acquired = false;
  const double reach = payload_reach_ft_;
  payload_reach_ft_ = 0.0;
  // Re-orthonormalized: a payload let go and grasped again many times must
  // not accumulate rounding in its rotation.
  Eigen::Isometry3d X_RP = slave_->X_RP;
  X_RP.linear() = Eigen::Quaterniond(X_RP.linear()).normalized().toRotationMatrix();
  PlacePayload(X_RP);
  Evaluate(SlaveAsItIs(), slave_, spare_);
  if (spare_->collisions) {
    spdlog::warn(
        "the finger opened but the hand would be in collision with the payload let go ({}): grasp "
        "kept",
        wire::CollisionNames(spare_->collisions, ", ", "none"));
    PlacePayload(X_RP_free);
    status_.mode = slave_->mode;
    status_.acquired = true;
    payload_reach_ft_ = reach;
    return;
  }
  spdlog::info("the finger opened: the payload is let go where it is (Mode 1)");
  status_.let_go = true;
  AcceptSpare();
}

// The master arm's command from the inputs (the last one held when these
// are not finite), and the reset button acted on as it is pressed.
ArmCommand DynamicCollisionProgram::TakeInputs(const wire::OperatorInputs& in) {
  ArmCommand master;
  for (int i = 0; i < kNumJoints; ++i) master.angles_deg[i] = in.value[i];
  master.shoulder_height_ft = in.value[kShoulderHeight];
  master.finger = in.value[kFinger];
  status_.input_refused = !Finite(master);
  if (status_.input_refused) master = status_.master;  // hold the last command
  status_.reset_refused = false;
  status_.let_go = false;
  if (in.reset && !reset_pressed_) {
    if (Reset())
      spdlog::info("reset: Mode 1, payload in the cargo bay");
    else
      status_.reset_refused = true;
  }
  reset_pressed_ = in.reset;
  status_.master = master;
  status_.held = status_.finger_held = status_.essential_contact = false;
  status_.finger_contact = false;  // Mode 1's, set by UpdateAcquisition
  status_.motion_collision = status_.too_fast = false;
  status_.substeps = 0;
  return master;
}

// What the slave is commanded: the master's, but a docked payload is
// captured at the port (the arm keeps its pose and only the finger moves,
// until opening it releases it), and a grasp lasts only while the finger
// stays closed.
ArmCommand DynamicCollisionProgram::SlaveCommand(const ArmCommand& master) {
  ArmCommand command = master;
  if (status_.docked && !released_) {
    if (slave_->finger_gap_ft >= acquisition_gap_ft_ + kReleaseOpeningFt) {
      released_ = true;
      PlacePayload(X_RP_docked_);  // the hand is tested against it from now on
      spdlog::info("released: the finger let go of the docked payload; the arm is free");
    } else {
      command.angles_deg = slave_->cmd.angles_deg;
      command.shoulder_height_ft = slave_->cmd.shoulder_height_ft;
    }
  } else if (status_.mode >= wire::DcpMode::kExtraction && !status_.docked &&
             FingerGapFt(master.finger) >= acquisition_gap_ft_ + kReleaseOpeningFt) {
    LetGo();
  }
  return command;
}

// The first frame after start: nothing to move from but the initial pose,
// which the command need not be near. Its pose is tested where it is, and
// taken only when free.
void DynamicCollisionProgram::FirstFrame(const ArmCommand& command) {
  Evaluate(command, nullptr, spare_);
  status_.collisions = spare_->collisions;
  status_.substeps = 1;
  if (spare_->collisions == 0) {
    AcceptSpare();
  } else {
    status_.held = true;
    spdlog::warn("the first command collides ({}): not taken; the arm stays at its initial pose",
                 wire::CollisionNames(spare_->collisions, ", ", "none"));
  }
  started_ = true;
}

// The DCP's output block for this frame (report IV.B: the arm words, the
// control word with the six bits the DCP generates, the planes, the state).
wire::DcpFrameData DynamicCollisionProgram::FrameOut(const wire::OperatorInputs& in) const {
  wire::DcpFrameData out;
  out.arm = slave_->words;
  out.control.camera_station = in.camera_station;
  out.control.reset = in.reset;
  out.control.overlay = in.overlay;
  out.control.crosshairs = in.crosshairs;
  out.control.no_video = malfunctions_.CameraLost(in.camera_station);
  out.control.mode = wire::ModeNumber(status_.mode);
  // COLLISION: a detrimental collision; RECPT: the essential contact.
  const std::uint32_t essential =
      status_.essential_contact ? wire::collision_bits::kEffHexRecpt << 2 : 0u;
  out.control.collision = (status_.collisions & ~essential) != 0;
  out.control.receptacle_collision = status_.essential_contact;
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

void DynamicCollisionProgram::Inject(const wire::Malfunction& m) {
  const ArmCommand& slave = started_ ? slave_->cmd : initial_;
  malfunctions_.Inject(m, slave.angles_deg, slave.finger);
}

wire::DcpFrameData DynamicCollisionProgram::Step(const wire::OperatorInputs& raw) {
  // docs/sessions.md "Malfunctions": the inputs due, the operator's command
  // (the master's, as telemetered) and what the failed parts let through.
  const wire::OperatorInputs& in = malfunctions_.Delay(raw);
  const ArmCommand master = TakeInputs(in);
  ArmCommand failed = master;
  if (started_) malfunctions_.Apply(slave_->cmd.angles_deg, &failed.angles_deg, &failed.finger);
  const ArmCommand command = SlaveCommand(failed);
  if (started_)
    Respond(command);
  else
    FirstFrame(command);
  status_.released = released_;
  status_.slave_collisions = slave_->collisions;
  status_.slave = slave_->cmd;
  status_.X_RS2 = slave_->pose.X_RS2;
  status_.X_RP = slave_->X_RP;
  status_.finger_gap_ft = slave_->finger_gap_ft;
  UpdatePlanes();
  const wire::DcpMode mode_before = status_.mode;
  UpdateDocking();  // distance and angle every frame; docking in Mode 3
  if (mode_before == wire::DcpMode::kAcquisition)
    UpdateAcquisition();
  else if (mode_before == wire::DcpMode::kExtraction)
    UpdateExtraction();
  else
    status_.bay_clearance_ft = BayClearance(slave_->payload);
  return FrameOut(in);
}

void DynamicCollisionProgram::UpdatePlanes() {
  // The three dynamic separating planes, EFF HEX 1-3 against the BAR (Mode 1).
  // A plane not valid this frame is sent as the default (n = Z, d = 0), so
  // its words do not depend on earlier frames (a valid plane may, through
  // frame coherence; the checkpoint keeps the planes).
  status_.plane_valid = 0;
  status_.planes = {};
  if (status_.mode != wire::DcpMode::kAcquisition) return;
  for (int k = 0; k < 3; ++k) {
    const CollisionResult& r = slave_->ee_bar[k];
    if (r.verdict == Verdict::kSeparate && r.plane_valid) {
      // Centred in the gap, to survive rounding to the plane words.
      status_.planes[k] = {r.plane.n_R, MidGapOffset(slave_->ee.hex[k], bar_, r.plane.n_R)};
      status_.plane_valid |= 1u << k;
    }
  }
}

void DynamicCollisionProgram::RefreshMeasures() {
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
  status_.finger_contact = false;
  if (status_.mode == wire::DcpMode::kAcquisition) {
    const AcquisitionCheck c =
        CheckAcquisition(config_.dcp, slave_->ee, bar_, slave_->finger_gap_ft, tau_rel_);
    status_.acquisition = c.holds;
    status_.acquisition_margin_ft = c.margin_ft;
    status_.palm_to_bar_ft = c.palm_to_bar_ft;
    status_.finger_contact = c.margin_ft[wire::kBarBeyondFingerFaceE] <= kFingerContactToleranceFt;
  }
}

double DynamicCollisionProgram::BayClearance(const PayloadModel& p) const {
  // Height above the bay's top face c (its outward normal is +Z_R).
  double lowest = 1e30;
  for (const Eigen::Vector3d& v : p.v)
    lowest = std::min(lowest, bay_.Beyond(kFaceC, v.x(), v.y(), v.z()));
  return lowest;
}

bool AcquisitionCheck::all() const {
  return std::all_of(holds.begin(), holds.end(), [](bool b) { return b; });
}

AcquisitionCheck CheckAcquisition(const DcpConfig& dcp, const EndEffectorModel& ee,
                                  const Hexahedron& bar, double finger_gap_ft,
                                  double relative_tolerance) {
  const Hexahedron& h1 = ee.hex[0];
  const Hexahedron& h2 = ee.hex[1];
  const Hexahedron& h3 = ee.hex[2];
  const double tau = ToleranceFt(h1, bar, relative_tolerance);
  AcquisitionCheck c;
  c.finger_gap_ft = finger_gap_ft;
  c.holds[wire::kBarBeyondPalmFaceD] = AllHave(h1.Words(bar, tau), kFaceD);
  c.holds[wire::kBarBeyondFingerFaceB] = AllHave(h2.Words(bar, tau), kFaceB);
  c.holds[wire::kBarBeyondFingerFaceE] = AllHave(h3.Words(bar, tau), kFaceE);
  c.holds[wire::kFingerGapBelowD3Y] = finger_gap_ft < dcp.d3y_ft;
  Eigen::Vector3d top = Eigen::Vector3d::Zero();
  for (int v : kFaceVertices[kFaceC]) top += bar.vertex(v);
  top *= 0.25;
  c.palm_to_bar_ft = h1.Beyond(kFaceD, top.x(), top.y(), top.z());
  // The report's "distance": unsigned (a BAR behind the palm's face d is not
  // near it; condition 1 fails there anyway, so acquisition is unchanged).
  c.holds[wire::kPalmWithinTpob] = std::abs(c.palm_to_bar_ft) < dcp.tpob_ft;
  bool between = true;
  for (LocationWord w : bar.Words(h1, tau))
    between = between && !(w & (FaceBit(kFaceA) | FaceBit(kFaceD)));
  c.holds[wire::kBetweenBarEnds] = between;
  // Margins (docs/collision.md "Margins"): least depths, ft.
  auto least_beyond = [](const Hexahedron& h, int face, const Hexahedron& of) {
    double m = 1e30;
    for (int i = 0; i < kNumVertices; ++i)
      m = std::min(m, h.Beyond(face, of.x[i], of.y[i], of.z[i]));
    return m;
  };
  c.margin_ft[wire::kBarBeyondPalmFaceD] = least_beyond(h1, kFaceD, bar);
  c.margin_ft[wire::kBarBeyondFingerFaceB] = least_beyond(h2, kFaceB, bar);
  c.margin_ft[wire::kBarBeyondFingerFaceE] = least_beyond(h3, kFaceE, bar);
  c.margin_ft[wire::kFingerGapBelowD3Y] = dcp.d3y_ft - finger_gap_ft;
  c.margin_ft[wire::kPalmWithinTpob] = dcp.tpob_ft - std::abs(c.palm_to_bar_ft);
  double inside = 1e30;
  for (int i = 0; i < kNumVertices; ++i) {
    inside = std::min({inside, -bar.Beyond(kFaceA, h1.x[i], h1.y[i], h1.z[i]),
                       -bar.Beyond(kFaceD, h1.x[i], h1.y[i], h1.z[i])});
  }
  c.margin_ft[wire::kBetweenBarEnds] = inside;
  // Condition 3 at the essential contact: the movable finger on the bar. A
  // bar slightly askew touches face e at one corner while its far corner,
  // beyond the finger's edge, may lie a hair behind the face's plane: within
  // the contact tolerance it counts as on the face (docs/collision.md "The
  // essential contact").
  c.holds[wire::kBarBeyondFingerFaceE] =
      c.holds[wire::kBarBeyondFingerFaceE] ||
      c.margin_ft[wire::kBarBeyondFingerFaceE] > -kFingerContactToleranceFt;
  return c;
}

DockingCheck CheckDocking(const DcpConfig& dcp, const CaeConfig& cae, const Hexahedron& front,
                          const PayloadModel& p, double relative_tolerance) {
  DockingCheck d;
  const double tau = ToleranceFt(front, front, relative_tolerance);
  const LocationWord sides = FaceBit(kFaceA) | FaceBit(kFaceB) | FaceBit(kFaceD) | FaceBit(kFaceE);
  d.in_envelope = true;
  d.envelope_margin_ft = 1e30;
  for (int i = kProbeFirst; i < kPayloadVertices; ++i) {
    const LocationWord w = front.Word(p.v[i], tau);
    d.in_envelope = d.in_envelope && (w & FaceBit(kFaceC)) && !(w & sides);
    const Eigen::Vector3d& v = p.v[i];
    d.envelope_margin_ft = std::min(
        {d.envelope_margin_ft, front.Beyond(kFaceC, v.x(), v.y(), v.z()),
         -front.Beyond(kFaceA, v.x(), v.y(), v.z()), -front.Beyond(kFaceB, v.x(), v.y(), v.z()),
         -front.Beyond(kFaceD, v.x(), v.y(), v.z()), -front.Beyond(kFaceE, v.x(), v.y(), v.z())});
  }
  d.distance_ft = (p.probe_tip_centre - cae.p_RoCo_R_ft).norm();
  const double c = std::clamp(p.probe_axis.dot(cae.R_RC.col(1)), -1.0, 1.0);
  d.angle_deg = std::acos(c) * 180.0 / M_PI;
  d.docked =
      d.in_envelope && d.distance_ft <= dcp.dock_distance_ft && d.angle_deg <= dcp.dock_angle_deg;
  return d;
}

void DynamicCollisionProgram::UpdateAcquisition() {
  // Report IV.A.3: the six conditions, on the slave's (collision-free) pose,
  // and the essential contact: the movable finger on the bar (face e of EFF
  // HEX 3 within kFingerContactToleranceFt of it; docs/collision.md).
  const AcquisitionCheck c =
      CheckAcquisition(config_.dcp, slave_->ee, bar_, slave_->finger_gap_ft, tau_rel_);
  status_.acquisition = c.holds;
  status_.acquisition_margin_ft = c.margin_ft;
  status_.palm_to_bar_ft = c.palm_to_bar_ft;
  status_.bay_clearance_ft = BayClearance(slave_->payload);
  status_.finger_contact = c.margin_ft[wire::kBarBeyondFingerFaceE] <= kFingerContactToleranceFt;
  if (!(c.all() && status_.finger_contact)) return;
  status_.mode = wire::DcpMode::kExtraction;
  status_.acquired = true;
  X_S2P_ = slave_->pose.X_RS2.inverse() * X_RP_free_;
  // The gap at which face e of EFF HEX 3 would touch the bar: from face b
  // of EFF HEX 2 (at Y2 = W - t) to the bar's nearest vertex along -Y2.
  const Eigen::Isometry3d& X_RS2 = slave_->pose.X_RS2;
  double y_min = 1e30;
  for (int i = 0; i < kNumVertices; ++i)
    y_min = std::min(y_min, X_RS2.linear().col(1).dot(bar_.vertex(i) - X_RS2.translation()));
  const auto& ee = config_.end_effector;
  acquisition_gap_ft_ = slave_->finger_gap_ft;
  contact_gap_ft_ =
      std::clamp(ee.palm_half_width_ft - ee.finger_thickness_ft - y_min + kFingerContactClearanceFt,
                 0.0, acquisition_gap_ft_);
  payload_reach_ft_ = PayloadReachFt(X_S2P_);  // bounds the held payload's travel
  if (!ReevaluateSlave()) {
    status_.mode = wire::DcpMode::kAcquisition;
    status_.acquired = false;
    payload_reach_ft_ = 0.0;
    return;
  }
  spdlog::info("acquisition: Mode 1 -> Mode 2 (finger gap {:.3f} ft, palm to bar {:.3f} ft)",
               c.finger_gap_ft, c.palm_to_bar_ft);
}

bool DynamicCollisionProgram::ReevaluateSlave() {
  // The slave where it is, tested in the mode just entered: a pose that
  // collides there keeps the mode it was in (reported, never shown).
  Evaluate(slave_->cmd, slave_, spare_);
  if (spare_->collisions) {
    spdlog::warn("Mode {} not entered: the arm where it is would collide there ({})",
                 wire::ModeNumber(status_.mode),
                 wire::CollisionNames(spare_->collisions, ", ", "none"));
    return false;
  }
  AcceptSpare();
  return true;
}

void DynamicCollisionProgram::UpdateExtraction() {
  // Report IV.A.3: all payload and probe vertices above the bay's face c.
  // The conditions of acquisition are not evaluated after it.
  status_.acquisition = {};
  status_.acquisition_margin_ft = {};
  status_.palm_to_bar_ft = 0.0;
  status_.bay_clearance_ft = BayClearance(slave_->payload);
  const double tau = ToleranceFt(bay_, bay_, tau_rel_);
  for (const Eigen::Vector3d& v : slave_->payload.v) {
    if (!(bay_.Word(v, tau) & FaceBit(kFaceC))) return;
  }
  status_.mode = wire::DcpMode::kManoeuvring;
  if (!ReevaluateSlave()) {
    status_.mode = wire::DcpMode::kExtraction;
    return;
  }
  spdlog::info("clear of the cargo bay: Mode 2 -> Mode 3");
}

void DynamicCollisionProgram::UpdateDocking() {
  const DockingCheck d = CheckDocking(config_.dcp, config_.cae, cae_, slave_->payload, tau_rel_);
  status_.probe_in_envelope = d.in_envelope;
  status_.envelope_margin_ft = d.envelope_margin_ft;
  status_.dock_distance_ft = d.distance_ft;
  status_.dock_angle_deg = d.angle_deg;
  if (status_.mode == wire::DcpMode::kManoeuvring && !status_.docked && d.docked) {
    status_.docked = true;
    X_RP_docked_ = slave_->X_RP;
    PlacePayload(X_RP_docked_);
    spdlog::info("docked: distance {:.3f} ft, angle {:.3f} deg", d.distance_ft, d.angle_deg);
  }
}

double DynamicCollisionProgram::PayloadReachFt(const Eigen::Isometry3d& X_S2P) const {
  // The payload in System Two: its vertices' distances from point A.
  const PayloadModel m = MakePayload(payload_shape_, X_S2P, /*with_body=*/false);
  double reach = 0.0;
  for (const Eigen::Vector3d& v : m.v) reach = std::max(reach, v.norm());
  return reach;
}

}  // namespace rms::dcp_model
