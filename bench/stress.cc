// rms_stress: numerical stability under stress (docs/performance.md
// "Numerical stability under stress").
//
//   rms_stress [--pairs N] [--poses N] [--frames N] [--seed S] [--md FILE]
//
// 1. Collision pairs: every family of the reference generators (random,
//    touching exactly and after rotation, parallel edges, nested, rods
//    through slabs, near contact, general hexahedra) plus near-parallel
//    edges (one box turned by 1e-15..1e-3 rad about an edge of the other)
//    and faces at +-1e-12 x scale, at scales from 1e-6 to 1e6 ft. Each pair:
//    a verdict for finite input; a returned plane is finite, unit and
//    separates (within the band); the verdict is the same with the roles
//    swapped, with bounding-sphere rejection off, and with one solid moved by
//    1e-12 x scale -- or the pair lies in the documented band (|separation|
//    <= 1e-9 x scale, measured in long double when needed); box verdicts
//    agree with the long double separating-axis test outside the band.
// 2. Arm poses: random, singular wrists (yaw +-90 deg, pitch and roll axes
//    aligned), angles at +-180, extreme and out-of-range shoulder heights
//    (through the input words, clamped): finite, rotations orthonormal to
//    1e-12, the end effector's hexahedra valid.
// 3. A soak of random operator input through the words and the DCP, from
//    Mode 1 and from checkpoints of Modes 2 and 3 (payload held): no NaN, no
//    drift (System Two orthonormal, the held payload rigid to 1e-9 ft, the
//    state after a reset equal to the first), the slave never shown in
//    collision, every plane sent separating its pair.
// Exit status 0 when every check holds.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <random>
#include <spdlog/spdlog.h>
#include <sstream>

#include "rms/base/command_line.h"
#include "rms/base/text.h"
#include "rms/dcp_model/dcp_telemetry.h"
#include "rms/dcp_model/dynamic_collision_program.h"
#include "rms/reference/exact_hull.h"
#include "rms/reference/generators.h"
#include "rms/sim/closed_loop.h"
#include "rms/sim/random_operator.h"
#include "rms/wire/dcp_mode.h"

namespace {

using namespace rms;
using namespace rms::dcp_model;
using rms::reference::Pair;

constexpr double kBand = 1e-9;

struct Failures {
  std::map<std::string, long> count;
  std::map<std::string, std::string> first;
  void Add(const std::string& what, const std::string& detail) {
    if (count[what]++ == 0) first[what] = detail;
  }
  long total() const {
    long t = 0;
    for (const auto& [k, v] : count) t += v;
    return t;
  }
};

// |separation| of the pair in long double (SAT for boxes, brute force for
// hexahedra).
long double Separation(const Pair& p) {
  if (p.a.is_box && p.b.is_box) return rms::reference::BoxSatSeparation(p.a.box, p.b.box);
  const auto topo = rms::reference::StandardTopology();
  return rms::reference::ExactHullsIntersect(p.a.v, p.b.v)
             ? -rms::reference::PenetrationDepth(p.a.v, p.b.v, topo)
             : rms::reference::HullDistance(p.a.v, p.b.v, topo);
}

double Scale(const Pair& p) { return std::max(p.a.hex.scale, p.b.hex.scale); }

rms::reference::Solid Moved(const rms::reference::Solid& s, const Eigen::Vector3d& d) {
  rms::reference::Solid m = s;
  std::array<Eigen::Vector3d, 8> v;
  for (int i = 0; i < 8; ++i) v[i] = s.v[i] + d;
  if (s.is_box) {
    Eigen::Matrix3d R;
    for (int k = 0; k < 3; ++k) R.col(k) = s.box.axis[k].cast<double>();
    m = rms::reference::Box(s.box.centre.cast<double>() + d, R,
                            Eigen::Vector3d(s.box.half[0], s.box.half[1], s.box.half[2]));
  } else {
    m.hex = FromVertices(v);
    m.v = v;
  }
  return m;
}

// Near-parallel edges: B is a copy of A turned by a tiny angle about one of
// A's edges, then pushed off along the edge's outward bisector by a gap.
Pair NearParallel(std::mt19937_64& rng, double s) {
  std::uniform_real_distribution<double> h(0.05, 0.5), lg(-15, -3), gap(-12, -6);
  std::uniform_int_distribution<int> sign(0, 1);
  const Eigen::Matrix3d R = rms::reference::RandomRotation(rng);
  const Eigen::Vector3d half = s * Eigen::Vector3d(h(rng), h(rng), h(rng));
  const Eigen::Vector3d c(0, 0, 0);
  rms::reference::Solid a = rms::reference::Box(c, R, half);
  // A's edge along its x axis at (+y, +z).
  const Eigen::Vector3d edge_mid = R * Eigen::Vector3d(0, half.y(), half.z());
  const Eigen::Vector3d out = (R * Eigen::Vector3d(0, half.y() > 0 ? 1 : -1, 1)).normalized();
  const double angle = (sign(rng) ? 1 : -1) * std::pow(10.0, lg(rng));
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(angle, R.col(0)).toRotationMatrix();
  // B: the same box reflected through the edge (sharing it), turned a little.
  const Eigen::Vector3d cb =
      edge_mid + turn * (edge_mid - c) + (sign(rng) ? 1 : -1) * s * std::pow(10.0, gap(rng)) * out;
  return {a, rms::reference::Box(cb, turn * R, half), "near-parallel edges"};
}

Pair FacesAt1e12(std::mt19937_64& rng, double s) {
  std::uniform_real_distribution<double> h(0.05, 0.5), p(-0.8, 0.8);
  std::uniform_int_distribution<int> sel(-1, 1);
  const Eigen::Matrix3d R = rms::reference::RandomRotation(rng);
  const Eigen::Vector3d ha = s * Eigen::Vector3d(h(rng), h(rng), h(rng)),
                        hb = s * Eigen::Vector3d(h(rng), h(rng), h(rng));
  const Eigen::Vector3d ca = s * Eigen::Vector3d(p(rng), p(rng), p(rng));
  const Eigen::Vector3d cb_local(ha.x() + hb.x() + sel(rng) * 1e-12 * s, 0.3 * ha.y(),
                                 -0.2 * ha.z());
  return {rms::reference::Box(ca, R, ha), rms::reference::Box(ca + R * cb_local, R, hb),
          "faces at +-1e-12 scale"};
}

struct PairStats {
  long pairs = 0, collide = 0, in_band = 0, sat_checked = 0;
  std::map<std::string, long> by_kind;
};

void StressPairs(long n, std::uint64_t seed, PairStats* st, Failures* fail) {
  rms::reference::PairGenerator gen(seed);
  std::mt19937_64 rng(seed + 1);
  std::uniform_real_distribution<double> lscale(-6, 6);
  std::normal_distribution<double> nd(0, 1);
  for (long i = 0; i < n; ++i) {
    const double s = std::pow(10.0, lscale(rng));
    Pair p = i % 10 == 8   ? NearParallel(rng, s)
             : i % 10 == 9 ? FacesAt1e12(rng, s)
                           : gen.Next(s, false);
    ++st->pairs;
    ++st->by_kind[p.kind];
    const double scale = Scale(p);
    const auto detail = [&](const char* what) {
      return Sprintf("pair %ld (%s, scale %.3g): %s", i, p.kind.c_str(), scale, what);
    };
    const CollisionResult r = Collide(p.a.hex, p.b.hex);
    if (r.verdict == Verdict::kInvalid) {
      fail->Add("invalid verdict for finite input", detail("kInvalid"));
      continue;
    }
    st->collide += r.verdict == Verdict::kCollide;
    bool band_known = false, in_band = false;
    auto band = [&] {
      if (!band_known) {
        in_band = std::fabs(static_cast<double>(Separation(p))) <= kBand * scale;
        band_known = true;
      }
      return in_band;
    };
    if (r.verdict == Verdict::kSeparate) {
      if (!r.plane_valid)
        fail->Add("separate without a plane", detail("no plane"));
      else if (!r.plane.n_R.allFinite() || !std::isfinite(r.plane.d_ft) ||
               std::fabs(r.plane.n_R.norm() - 1) > 1e-12)
        fail->Add("plane not finite or not unit", detail("bad plane"));
      else if (!PlaneSeparates(p.a.hex, p.b.hex, r.plane.n_R, r.plane.d_ft, kBand * scale))
        fail->Add("plane does not separate", detail("plane"));
    }
    const auto same_or_band = [&](Verdict v, const char* what) {
      if (v == r.verdict) return;
      if (band()) return;
      fail->Add(what, detail(what));
    };
    same_or_band(Collide(p.b.hex, p.a.hex, {.want_plane = false}).verdict,
                 "roles swapped change the verdict");
    same_or_band(Collide(p.a.hex, p.b.hex,
                         {.want_plane = false, .sphere_reject = false, .aabb_reject = false})
                     .verdict,
                 "bounding-volume rejection changes the verdict");
    const Eigen::Vector3d d =
        Eigen::Vector3d(nd(rng), nd(rng), nd(rng)).normalized() * 1e-12 * scale;
    const rms::reference::Solid moved = Moved(p.b, d);
    same_or_band(Collide(p.a.hex, moved.hex, {.want_plane = false}).verdict,
                 "a 1e-12 x scale move flips the verdict");
    if (p.a.is_box && p.b.is_box) {
      ++st->sat_checked;
      const long double sep = rms::reference::BoxSatSeparation(p.a.box, p.b.box);
      const bool exact_collide = sep <= 0;
      if (exact_collide != (r.verdict == Verdict::kCollide) &&
          std::fabs(static_cast<double>(sep)) > kBand * scale)
        fail->Add("box verdict differs from long double SAT outside the band", detail("SAT"));
    }
    if (band_known && in_band) ++st->in_band;
  }
}

bool Orthonormal(const Eigen::Matrix3d& R, double tol) {
  return ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <= tol) &&
         R.determinant() > 0;
}

void StressPoses(const LabConfig& config, long n, std::uint64_t seed, Failures* fail) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_int_distribution<int> kind(0, 4);
  Counters counters;
  const auto& cal = config.inputs;
  for (long i = 0; i < n; ++i) {
    wire::OperatorInputs in = wire::InitialInputs(cal);
    const int k = kind(rng);
    for (int j = 0; j < 6; ++j) in.value[j] = 180 * u(rng);
    if (k == 0) in.value[4] = u(rng) > 0 ? 90 : -90;  // wrist yaw: pitch and roll axes aligned
    if (k == 1)
      for (int j = 0; j < 6; ++j) in.value[j] = u(rng) > 0 ? 180 : -180;  // every angle at +-180
    if (k == 2)
      in.value[kShoulderHeight] = u(rng) > 0 ? cal[kShoulderHeight].max : cal[kShoulderHeight].min;
    if (k == 3) in.value[kShoulderHeight] = 1e6 * u(rng);  // far out of range: clamped by the words
    if (k == 4) in.value[4] = (u(rng) > 0 ? 90 : -90) + 1e-9 * u(rng);
    const wire::OperatorInputs dec =
        wire::DecodeInputs(wire::EncodeInputs(in, cal, &counters), cal, &counters);
    arm::ArmSinCos sc = dcp_model::TransmittedArmWords(
        {dec.value[0], dec.value[1], dec.value[2], dec.value[3], dec.value[4], dec.value[5]});
    const arm::ArmPose pose = arm::ComputeArmPose(config.arm, sc, dec.value[kShoulderHeight]);
    const std::string what = Sprintf("pose %ld (kind %d)", i, k);
    if (!pose.X_RS2.matrix().allFinite())
      fail->Add("pose not finite", what);
    else if (!Orthonormal(pose.X_RS2.linear(), 1e-12))
      fail->Add("System Two not orthonormal to 1e-12", what);
    const double gap =
        config.end_effector.finger_gap_closed_ft +
        0.5 * (u(rng) + 1) *
            (config.end_effector.finger_gap_open_ft - config.end_effector.finger_gap_closed_ft);
    const EndEffectorModel ee = MakeEndEffector(config.end_effector, pose.X_RS2, gap);
    for (int h = 0; h < 3; ++h)
      if (!ee.hex[h].valid) fail->Add("end effector hexahedron invalid", what);
  }
}

struct SoakStats {
  long frames = 0, resets = 0, restores = 0, held = 0, planes = 0;
  std::array<long, 4> frames_in_mode{};
  double worst_orthonormal = 0, worst_rigid_ft = 0;
};

// Checkpoints of Modes 2 and 3 from the autopilot's mission, each a little
// after entering the mode.
std::vector<nlohmann::json> MissionCheckpoints(const LabConfig& config, Failures* fail) {
  std::vector<wire::OperatorInputs> inputs;
  rms::sim::FlyAutopilot(config, {}, 20000, 1, &inputs);
  std::vector<nlohmann::json> checkpoints;
  DynamicCollisionProgram d(config);
  wire::DcpMode last_mode = wire::DcpMode::kAcquisition;
  for (std::size_t f = 0; f < inputs.size(); ++f) {
    d.Step(inputs[f]);
    if (d.mode() != last_mode && d.mode() >= wire::DcpMode::kExtraction && !d.status().docked) {
      for (int k = 0; k < 30 && f + 1 < inputs.size(); ++k) d.Step(inputs[++f]);
      checkpoints.push_back(d.SaveState());
    }
    last_mode = d.mode();
  }
  if (checkpoints.size() < 2)
    fail->Add("no Mode 2 / Mode 3 checkpoint from the mission", "autopilot");
  return checkpoints;
}

std::array<double, 12> EdgeLengths(const Hexahedron& h) {
  std::array<double, 12> l;
  for (int e = 0; e < 12; ++e) l[e] = (h.vertex(kEdges[e][0]) - h.vertex(kEdges[e][1])).norm();
  return l;
}

// One soak frame's state: finite, rotations orthonormal, a held payload
// rigid, the slave free (but right after a start, reset or restore), every
// plane sent separating its pair. False when the state is not finite.
bool CheckSoakFrame(const LabConfig& config, const DynamicCollisionProgram& dcp,
                    const wire::DcpFrameData& out, bool fresh, bool reset, const std::string& what,
                    SoakStats* st, Failures* fail) {
  const DcpStatus& s = dcp.status();
  if (!s.X_RS2.matrix().allFinite() || !s.X_RP.matrix().allFinite() ||
      !std::isfinite(s.finger_gap_ft) || !std::isfinite(s.dock_distance_ft) ||
      !std::isfinite(s.dock_angle_deg)) {
    fail->Add("NaN or infinity in the DCP's state", what);
    return false;
  }
  const double orth =
      (s.X_RS2.linear().transpose() * s.X_RS2.linear() - Eigen::Matrix3d::Identity())
          .cwiseAbs()
          .maxCoeff();
  const double orth_p =
      (s.X_RP.linear().transpose() * s.X_RP.linear() - Eigen::Matrix3d::Identity())
          .cwiseAbs()
          .maxCoeff();
  st->worst_orthonormal = std::max({st->worst_orthonormal, orth, orth_p});
  if (orth > 1e-12 || orth_p > 1e-12)
    fail->Add("a rotation drifted from orthonormal (1e-12)", what);
  if (s.mode >= wire::DcpMode::kExtraction) {
    const Eigen::Isometry3d X_RP_bay =
        arm::MakeIsometry(config.payload.R_RP, config.payload.p_RoPo_R_ft);
    const auto l0 = EdgeLengths(MakePayload(config.payload, X_RP_bay).body[0]);
    const auto l = EdgeLengths(MakePayload(config.payload, s.X_RP).body[0]);
    for (int e = 0; e < 12; ++e)
      st->worst_rigid_ft = std::max(st->worst_rigid_ft, std::fabs(l[e] - l0[e]));
    if (st->worst_rigid_ft > 1e-9) fail->Add("the held payload is not rigid (1e-9 ft)", what);
  }
  if (s.slave_collisions != 0 && !fresh && !reset)
    fail->Add("the slave shown in collision",
              what + Sprintf(": bits 0x%x, held %d, finger held %d, reset %d", s.slave_collisions,
                             s.held, s.finger_held, reset));
  const Hexahedron bar_bay =
      MakeBar(config.payload, arm::MakeIsometry(config.payload.R_RP, config.payload.p_RoPo_R_ft));
  for (int k = 0; k < 3; ++k) {
    if (!(out.plane_valid & (1u << k))) continue;
    ++st->planes;
    const EndEffectorModel ee = MakeEndEffector(config.end_effector, s.X_RS2, s.finger_gap_ft);
    const double tol =
        1e-9 * std::max(ee.hex[k].scale, bar_bay.scale);  // the same size wherever it rests
    // The bar where the payload rests (the bay, or where the finger let it go).
    const Hexahedron bar = MakeBar(config.payload, s.X_RP);
    if (!PlaneSeparates(ee.hex[k], bar, out.planes[k].n_R, out.planes[k].d_ft, tol))
      fail->Add("a plane sent does not separate its pair", what);
  }
  return true;
}

void Soak(const LabConfig& config, long frames, std::uint64_t seed, SoakStats* st, Failures* fail) {
  const std::vector<nlohmann::json> checkpoints = MissionCheckpoints(config, fail);
  DynamicCollisionProgram dcp(config);
  rms::sim::RandomOperator op(config.inputs, seed);
  Counters counters;
  bool fresh = true;  // the next frame follows a start, a reset or a restore
  for (long f = 0; f < frames; ++f) {
    if (f > 0 && f % 5000 == 0 && !checkpoints.empty()) {
      dcp.RestoreState(checkpoints[(f / 5000) % checkpoints.size()]);
      ++st->restores;
    }
    const wire::OperatorInputs in = op.Next();
    const auto words = wire::EncodeInputs(in, config.inputs, &counters);
    const wire::OperatorInputs dec = wire::DecodeInputs(words, config.inputs, &counters);
    if (dec.reset) ++st->resets;
    const wire::DcpFrameData out = dcp.Step(dec);
    ++st->frames;
    const DcpStatus& s = dcp.status();
    ++st->frames_in_mode[wire::ModeNumber(s.mode)];
    st->held += s.held;
    (void)MakeTelemetry(s, out);  // the telemetry is made from every state
    if (!CheckSoakFrame(config, dcp, out, fresh, dec.reset,
                        Sprintf("frame %ld (mode %d)", f, wire::ModeNumber(s.mode)), st, fail)) {
      continue;
    }
    // Until the slave first takes a collision-free command it may start in collision.
    fresh = dec.reset || (fresh && s.slave_collisions != 0);
  }
  // Drift over the soak: nothing accumulates; the slave's pose is its
  // command's, through the transmitted words, bit for bit.
  const DcpStatus& end = dcp.status();
  const rms::arm::ArmPose pose = rms::arm::ComputeArmPose(
      config.arm, TransmittedArmWords(end.slave.angles_deg), end.slave.shoulder_height_ft);
  if (!(pose.X_RS2.matrix() == end.X_RS2.matrix()))
    fail->Add("the slave's pose drifted from its command's", "end of soak");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rmslab rms_stress: numerical stability under stress (docs/performance.md)"};
  long pairs = 10000000, poses = 1000000, frames = 1000000;
  std::uint64_t seed = 19721122;
  std::string md_path, config_path = rms::DefaultConfigPath();
  app.add_option("--pairs", pairs, "Collision configurations")->capture_default_str();
  app.add_option("--poses", poses, "Arm poses")->capture_default_str();
  app.add_option("--frames", frames, "Soak frames of random operator input")->capture_default_str();
  app.add_option("--seed", seed, "Seed")->capture_default_str();
  app.add_option("--config", config_path, "Configuration file")->capture_default_str();
  app.add_option("--md", md_path, "Write the results as markdown to this file");
  if (const auto rc = rms::ParseCommandLine(app, argc, argv)) return *rc;
  spdlog::set_level(spdlog::level::err);
  std::printf("rms_stress: seed %llu, %ld pairs, %ld poses, %ld soak frames\n",
              static_cast<unsigned long long>(seed), pairs, poses, frames);
  const rms::LabConfig config = rms::LoadConfig(config_path);
  Failures fail;
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  PairStats ps;
  StressPairs(pairs, seed, &ps, &fail);
  const auto t1 = Clock::now();
  StressPoses(config, poses, seed + 2, &fail);
  const auto t2 = Clock::now();
  SoakStats ss;
  Soak(config, frames, seed + 3, &ss, &fail);
  const auto t3 = Clock::now();
  auto sec = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
  std::ostringstream md;
  md << "## Numerical stability under stress\n\n"
     << Sprintf(
            "`rms_stress --pairs %ld --poses %ld --frames %ld --seed %llu` (%.1f s + %.1f s + %.1f "
            "s):\n\n",
            pairs, poses, frames, static_cast<unsigned long long>(seed), sec(t0, t1), sec(t1, t2),
            sec(t2, t3))
     << Sprintf(
            "- **Collision configurations**: %ld pairs at scales 1e-6..1e6 ft (%ld colliding; %ld "
            "box pairs also "
            "against the long double separating-axis test); %ld pairs needed the band to excuse a "
            "difference "
            "(swapped roles, bounding spheres and boxes off, a 1e-12 x scale move) and lay inside "
            "it. Families:",
            ps.pairs, ps.collide, ps.sat_checked, ps.in_band);
  for (const auto& [k, v] : ps.by_kind) md << Sprintf(" %s %ld;", k.c_str(), v);
  md << "\n"
     << Sprintf(
            "- **Arm poses**: %ld (random; wrist yaw +-90 deg, the singular wrist; every angle at "
            "+-180; shoulder "
            "height at its limits and far outside them, clamped by the words).\n",
            poses)
     << Sprintf(
            "- **Soak**: %ld frames of random operator input through the input words and the DCP "
            "(Mode 1 %ld, "
            "Mode 2 %ld, Mode 3 %ld frames; %ld restores of Mode 2 / 3 checkpoints, %ld resets, "
            "%ld frames held, "
            "%ld planes sent); worst rotation orthonormality error %.1e, worst change of a held "
            "payload's edge "
            "%.1e ft.\n",
            ss.frames, ss.frames_in_mode[1], ss.frames_in_mode[2], ss.frames_in_mode[3],
            ss.restores, ss.resets, ss.held, ss.planes, ss.worst_orthonormal, ss.worst_rigid_ft);
  if (fail.total() == 0) {
    md << "- **Failures**: none (no NaN, no invalid verdict, no plane that fails to separate, no "
          "verdict flip outside "
          "the band, no drift).\n\n";
  } else {
    md << Sprintf("- **Failures**: %ld\n", fail.total());
    for (const auto& [k, v] : fail.count)
      md << Sprintf("  - %s: %ld (first: %s)\n", k.c_str(), v, fail.first[k].c_str());
    md << "\n";
  }
  std::fputs(md.str().c_str(), stdout);
  if (!md_path.empty()) std::ofstream(md_path) << md.str();
  std::printf("%s\n", fail.total() == 0 ? "PASS" : "FAIL");
  return fail.total() == 0 ? 0 : 1;
}
