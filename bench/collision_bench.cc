// rms_collision_bench: the report's collision algorithm (the DCP's) against
// its peers on the same pairs, one run, as ratios; and every method's verdict
// agreement with the exact reference (docs/performance.md).
//
//   rms_collision_bench [--md FILE] [--agreement N] [Google Benchmark flags]
//
// Timing: 4096 random box pairs (and 4096 random general hexahedra), 4096
// dense pairs of each (bounding spheres overlapping, half colliding), and
// 4096 of each kind the DCP tests in an autopilot mission's Mode 1 frames,
// each method given the pairs in its own form, prepared before timing, cycled
// through in the same order. Agreement: N pairs of each family of the test
// generator (random, touching to 1e-6..1e-12, parallel edges, nested, rods
// through slabs, near contact), against the exact reference (CGAL, exact
// arithmetic).
#include <algorithm>
#include <benchmark/benchmark.h>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "rms/base/config.h"
#include "rms/dcp_model/collision.h"
#include "rms/dcp_model/dcp_models.h"
#include "rms/dcp_model/dynamic_collision_program.h"
#include "rms/reference/exact_hull.h"
#include "rms/reference/generators.h"
#include "rms/sim/closed_loop.h"
#include "rms/wire/dcp_mode.h"

#include "peers.h"

namespace {

using rms::reference::Pair;
using Hull = std::array<Eigen::Vector3d, 8>;

rms::bench::BoxShape Shape(const rms::reference::Solid& s) {
  rms::bench::BoxShape b;
  b.centre = s.box.centre.cast<double>();
  for (int k = 0; k < 3; ++k) {
    b.R.col(k) = s.box.axis[k].cast<double>();
    b.half[k] = static_cast<double>(s.box.half[k]);
  }
  return b;
}

rms::dcp_model::CollideOptions VerdictOnly() {
  rms::dcp_model::CollideOptions o;
  o.want_plane = false;
  return o;
}

struct Sets {
  std::vector<std::pair<rms::dcp_model::Hexahedron, rms::dcp_model::Hexahedron>> hex_boxes,
      hex_general;
  std::vector<std::pair<rms::bench::BoxShape, rms::bench::BoxShape>> boxes;
  std::vector<std::pair<Hull, Hull>> hulls_boxes, hulls_general;
  std::vector<std::unique_ptr<rms::bench::FclPair>> fcl_boxes, fcl_general;
  // Dense: pairs whose bounding spheres overlap (what Mode 1 sees with the
  // end effector at the receptacle), half of them colliding.
  std::vector<std::pair<rms::dcp_model::Hexahedron, rms::dcp_model::Hexahedron>> hex_dense_boxes,
      hex_dense_general;
  // Those of the dense boxes no face separates and no edge pierces (the
  // report's step 4: separate, the plane from the edges).
  std::vector<std::pair<rms::dcp_model::Hexahedron, rms::dcp_model::Hexahedron>>
      hex_dense_boxes_no_edge_pierces;
  std::vector<std::pair<rms::bench::BoxShape, rms::bench::BoxShape>> dense_boxes;
  std::vector<std::unique_ptr<rms::bench::FclPair>> fcl_dense_boxes, fcl_dense_general;
  int dense_boxes_colliding = 0, dense_general_colliding = 0;  // of the 4096
  // The pairs the DCP tests in the Mode 1 frames of an autopilot mission
  // (EFF HEX 1-3 against the BAR and its posts: boxes; against the payload's
  // strips: general hexahedra), 4096 of each taken evenly in flight order.
  std::vector<std::pair<rms::dcp_model::Hexahedron, rms::dcp_model::Hexahedron>> hex_mission_boxes,
      hex_mission_general;
  std::vector<std::pair<rms::bench::BoxShape, rms::bench::BoxShape>> mission_boxes;
  std::vector<std::unique_ptr<rms::bench::FclPair>> fcl_mission_boxes, fcl_mission_general;
  int mission_frames = 0, mission_boxes_colliding = 0, mission_general_colliding = 0;
};

// The solids' bounding spheres (about their vertices' mean) overlap.
bool SpheresOverlap(const Hull& a, const Hull& b) {
  auto sphere = [](const Hull& h) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (const auto& v : h) c += v / 8.0;
    double r = 0.0;
    for (const auto& v : h) r = std::max(r, (v - c).norm());
    return std::pair{c, r};
  };
  const auto [ca, ra] = sphere(a);
  const auto [cb, rb] = sphere(b);
  return (ca - cb).norm() < ra + rb;
}

// 4096 pairs of the generator's (boxes only, or general hexahedra only)
// whose spheres overlap, 2048 colliding and 2048 not by the exact reference
// -- or, if one kind is still short after 400,000 draws, the rest of either
// kind. Returns how many collide.
template <typename Take>
int MakeDenseSet(rms::reference::PairGenerator& gen, bool boxes, Take take) {
  int colliding = 0, apart = 0;
  long draws = 0;
  while (colliding + apart < 4096) {
    const Pair p = gen.Next(1.0, boxes);
    ++draws;
    const bool right_kind = boxes ? (p.a.is_box && p.b.is_box) : !(p.a.is_box || p.b.is_box);
    if (!right_kind || !SpheresOverlap(p.a.v, p.b.v)) continue;
    const bool hit = rms::reference::ExactHullsIntersect(p.a.v, p.b.v);
    int& n = hit ? colliding : apart;
    if (n >= 2048 && draws < 400000) continue;
    ++n;
    take(p);
  }
  return colliding;
}

Hull HullOf(const rms::dcp_model::Hexahedron& h) {
  Hull v;
  for (int i = 0; i < 8; ++i) v[i] = h.vertex(i);
  return v;
}

// A box hexahedron (MakeBox's numbering) as centre, axes and half extents.
rms::bench::BoxShape BoxOf(const rms::dcp_model::Hexahedron& h) {
  rms::bench::BoxShape b;
  b.centre = Eigen::Vector3d::Zero();
  for (int i = 0; i < 8; ++i) b.centre += h.vertex(i) / 8.0;
  const Eigen::Vector3d edges[3] = {h.vertex(2) - h.vertex(0), h.vertex(4) - h.vertex(0),
                                    h.vertex(1) - h.vertex(0)};  // U: v3-v1, V: v5-v1, W: v2-v1
  for (int k = 0; k < 3; ++k) {
    b.R.col(k) = edges[k].normalized();
    b.half[k] = 0.5 * edges[k].norm();
  }
  return b;
}

// The mission's Mode 1 pairs: the planned autopilot's flight replayed
// through the DCP, each Mode 1 frame's models rebuilt from its status.
void MakeMissionSets(Sets* s) {
  using namespace rms::dcp_model;
  const rms::LabConfig config = rms::LoadConfig(rms::DefaultConfigPath());
  std::vector<rms::wire::OperatorInputs> inputs;
  rms::sim::FlyAutopilot(config, {}, 20000, 1, &inputs);
  DynamicCollisionProgram dcp(config);
  std::vector<std::pair<Hexahedron, Hexahedron>> boxes, general;
  for (const auto& in : inputs) {
    const bool mode1 = dcp.mode() == rms::wire::DcpMode::kAcquisition;
    dcp.Step(in);
    if (!mode1 || dcp.mode() != rms::wire::DcpMode::kAcquisition) continue;
    ++s->mission_frames;
    const DcpStatus& st = dcp.status();
    const EndEffectorModel ee = MakeEndEffector(config.end_effector, st.X_RS2, st.finger_gap_ft);
    const Hexahedron bar = MakeBar(config.payload, st.X_RP);
    std::array<Hexahedron, 2> posts;
    const int n_posts = MakeBarPosts(config.payload, st.X_RP, &posts);
    const PayloadModel payload = MakePayload(config.payload, st.X_RP);
    for (const Hexahedron& h : ee.hex) {
      boxes.emplace_back(h, bar);
      for (int j = 0; j < n_posts; ++j) boxes.emplace_back(h, posts[j]);
      for (const Hexahedron& strip : payload.body) general.emplace_back(h, strip);
    }
  }
  auto take = [](const auto& all, auto* out) {
    for (std::size_t i = 0; i < 4096 && !all.empty(); ++i)
      out->push_back(all[i * all.size() / 4096]);
  };
  take(boxes, &s->hex_mission_boxes);
  take(general, &s->hex_mission_general);
  for (const auto& [a, b] : s->hex_mission_boxes) {
    s->mission_boxes.emplace_back(BoxOf(a), BoxOf(b));
    s->fcl_mission_boxes.push_back(rms::bench::FclPair::Boxes(BoxOf(a), BoxOf(b)));
    s->mission_boxes_colliding += rms::reference::ExactHullsIntersect(HullOf(a), HullOf(b));
  }
  for (const auto& [a, b] : s->hex_mission_general) {
    s->fcl_mission_general.push_back(rms::bench::FclPair::Hulls(HullOf(a), HullOf(b)));
    s->mission_general_colliding += rms::reference::ExactHullsIntersect(HullOf(a), HullOf(b));
  }
}

Sets MakeSets() {
  Sets s;
  rms::reference::PairGenerator gen(12345);
  while (s.boxes.size() < 4096) {
    const Pair p = gen.Next(1.0, true);
    if (p.kind != "random boxes") continue;
    s.hex_boxes.emplace_back(p.a.hex, p.b.hex);
    s.boxes.emplace_back(Shape(p.a), Shape(p.b));
    s.hulls_boxes.emplace_back(p.a.v, p.b.v);
    s.fcl_boxes.push_back(rms::bench::FclPair::Boxes(Shape(p.a), Shape(p.b)));
  }
  while (s.hex_general.size() < 4096) {
    const Pair p = gen.Next(1.0, false);
    if (p.a.is_box || p.b.is_box) continue;
    s.hex_general.emplace_back(p.a.hex, p.b.hex);
    s.hulls_general.emplace_back(p.a.v, p.b.v);
    s.fcl_general.push_back(rms::bench::FclPair::Hulls(p.a.v, p.b.v));
  }
  rms::reference::PairGenerator dense(271828);
  s.dense_boxes_colliding = MakeDenseSet(dense, true, [&s](const Pair& p) {
    s.hex_dense_boxes.emplace_back(p.a.hex, p.b.hex);
    if (rms::dcp_model::Collide(p.a.hex, p.b.hex, VerdictOnly()).decider ==
        rms::dcp_model::Decider::kNoEdgePierces)
      s.hex_dense_boxes_no_edge_pierces.emplace_back(p.a.hex, p.b.hex);
    s.dense_boxes.emplace_back(Shape(p.a), Shape(p.b));
    s.fcl_dense_boxes.push_back(rms::bench::FclPair::Boxes(Shape(p.a), Shape(p.b)));
  });
  s.dense_general_colliding = MakeDenseSet(dense, false, [&s](const Pair& p) {
    s.hex_dense_general.emplace_back(p.a.hex, p.b.hex);
    s.fcl_dense_general.push_back(rms::bench::FclPair::Hulls(p.a.v, p.b.v));
  });
  MakeMissionSets(&s);
  return s;
}

// Collects every run's time for the tables.
class Collector : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs) {
      if (r.run_type != Run::RT_Iteration) continue;
      // The name without "/repeats:N"; with repetitions, the median.
      std::string name = r.benchmark_name();
      if (const auto k = name.find("/repeats:"); k != std::string::npos) name.resize(k);
      auto& v = all[name];
      v.push_back(r.GetAdjustedCPUTime());
      std::vector<double> sorted = v;
      std::sort(sorted.begin(), sorted.end());
      ns[name] = sorted[sorted.size() / 2];
    }
    ConsoleReporter::ReportRuns(runs);
  }
  std::map<std::string, double> ns;                // median over repetitions
  std::map<std::string, std::vector<double>> all;  // every repetition
};

struct Agreement {
  long pairs = 0;
  std::map<std::string, long> wrong;  // by method
  std::map<std::string, std::map<std::string, long>> wrong_by_kind;
  std::map<std::string, long> pairs_by_kind;
};

// What a method says of a pair: collide or not.
using Verdicts = std::map<std::string, bool>;

void Tally(const Pair& p, bool exact, const Verdicts& says, Agreement* ag) {
  ++ag->pairs;
  ++ag->pairs_by_kind[p.kind];
  for (const auto& [m, v] : says) {
    if (v != exact) {
      ++ag->wrong[m];
      ++ag->wrong_by_kind[m][p.kind];
    }
  }
}

bool DcpSaysCollide(const Pair& p) {
  return rms::dcp_model::Collide(p.a.hex, p.b.hex, VerdictOnly()).verdict ==
         rms::dcp_model::Verdict::kCollide;
}

// Every method's verdict against the exact reference on the generator's box
// families, then on general hexahedra: the same pairs for every method.
std::pair<Agreement, Agreement> MeasureAgreement(long agreement_pairs, std::uint64_t seed) {
  Agreement boxes, general;
  rms::reference::PairGenerator gen(seed);
  for (long n = 0; n < 7 * (agreement_pairs / 7); ++n) {
    const Pair p = gen.Next(1.0, true);
    const auto a = Shape(p.a), b = Shape(p.b);
    Tally(p, rms::reference::ExactHullsIntersect(p.a.v, p.b.v),
          {{"DCP", DcpSaysCollide(p)},
           {"separating axes, 15", rms::bench::SatBoxesIntersect(a, b)},
           {"ODE dBoxTouchesBox", rms::bench::OdeBoxesTouch(a, b)},
           {"FCL boxes", rms::bench::FclPair::Boxes(a, b)->Collide()},
           {"libccd MPR", rms::bench::CcdMprBoxes(a, b)}},
          &boxes);
  }
  while (general.pairs < agreement_pairs / 2) {
    const Pair p = gen.Next(1.0, false);
    if (p.a.is_box || p.b.is_box) continue;
    Tally(p, rms::reference::ExactHullsIntersect(p.a.v, p.b.v),
          {{"DCP", DcpSaysCollide(p)},
           {"libccd MPR", rms::bench::CcdMprHulls(p.a.v, p.b.v)},
           {"FCL convex", rms::bench::FclPair::Hulls(p.a.v, p.b.v)->Collide()}},
          &general);
  }
  // Every method appears, with 0 when it never disagreed.
  for (const char* m :
       {"DCP", "separating axes, 15", "ODE dBoxTouchesBox", "FCL boxes", "libccd MPR"})
    boxes.wrong[m] += 0;
  for (const char* m : {"DCP", "libccd MPR", "FCL convex"}) general.wrong[m] += 0;
  return {boxes, general};
}

// A method timed on 4096 pairs, cycled: f(i) for i = 0..4095, again and again.
template <class F>
void Cycle(benchmark::State& st, F&& f) {
  std::size_t i = 0;
  for (auto _ : st) benchmark::DoNotOptimize(f(i++ & 4095));
}

// The DCP's Collide on a set's pairs with these options.
template <class Pairs>
void RegisterDcp(const char* name, const Pairs& pairs, rms::dcp_model::CollideOptions o) {
  benchmark::RegisterBenchmark(name, [&pairs, o](benchmark::State& st) {
    Cycle(st, [&](std::size_t i) {
      return rms::dcp_model::Collide(pairs[i].first, pairs[i].second, o).verdict;
    });
  });
}

// Boxes: the DCP with and without its rejections, and every peer.
void RegisterBoxTimings(const Sets& sets) {
  const rms::dcp_model::CollideOptions verdict_only = VerdictOnly();
  rms::dcp_model::CollideOptions report_only = verdict_only;
  report_only.sphere_reject = false;
  report_only.aabb_reject = false;
  rms::dcp_model::CollideOptions spheres_only = verdict_only;
  spheres_only.aabb_reject = false;
  RegisterDcp("boxes/DCP, verdict", sets.hex_boxes, verdict_only);
  RegisterDcp("boxes/DCP, verdict, no bounding-volume rejection", sets.hex_boxes, report_only);
  RegisterDcp("boxes/DCP, verdict, spheres but no box rejection", sets.hex_boxes, spheres_only);
  RegisterDcp("boxes/DCP, verdict and separating plane", sets.hex_boxes, {});
  benchmark::RegisterBenchmark("boxes/separating axes, 15 (double)", [&sets](benchmark::State& st) {
    Cycle(st, [&](std::size_t i) {
      return rms::bench::SatBoxesIntersect(sets.boxes[i].first, sets.boxes[i].second);
    });
  });
  benchmark::RegisterBenchmark("boxes/ODE dBoxTouchesBox", [&sets](benchmark::State& st) {
    Cycle(st, [&](std::size_t i) {
      return rms::bench::OdeBoxesTouch(sets.boxes[i].first, sets.boxes[i].second);
    });
  });
  benchmark::RegisterBenchmark(
      "boxes/FCL collide() on boxes (computes a contact)", [&sets](benchmark::State& st) {
        Cycle(st, [&](std::size_t i) { return sets.fcl_boxes[i]->Collide(); });
      });
  benchmark::RegisterBenchmark("boxes/libccd MPR", [&sets](benchmark::State& st) {
    Cycle(st, [&](std::size_t i) {
      return rms::bench::CcdMprBoxes(sets.boxes[i].first, sets.boxes[i].second);
    });
  });
  benchmark::RegisterBenchmark("boxes/exact (CGAL)", [&sets](benchmark::State& st) {
    Cycle(st, [&](std::size_t i) {
      return rms::reference::ExactHullsIntersect(sets.hulls_boxes[i].first,
                                                 sets.hulls_boxes[i].second);
    });
  });
}

// Dense pairs: bounding spheres overlapping, half colliding; the widest
// edge axis; the mission's own pairs.
void RegisterDenseTimings(const Sets& sets) {
  const rms::dcp_model::CollideOptions verdict_only = VerdictOnly();
  RegisterDcp("dense boxes/DCP, verdict", sets.hex_dense_boxes, verdict_only);
  RegisterDcp("dense boxes/DCP, verdict and separating plane", sets.hex_dense_boxes, {});
  benchmark::RegisterBenchmark("dense boxes/separating axes, 15 (double)",
                               [&sets](benchmark::State& st) {
                                 Cycle(st, [&](std::size_t i) {
                                   return rms::bench::SatBoxesIntersect(sets.dense_boxes[i].first,
                                                                        sets.dense_boxes[i].second);
                                 });
                               });
  benchmark::RegisterBenchmark(
      "dense boxes/FCL collide() on boxes (computes a contact)", [&sets](benchmark::State& st) {
        Cycle(st, [&](std::size_t i) { return sets.fcl_dense_boxes[i]->Collide(); });
      });
  // Step 4's last resort on the dense box pairs no face separates and no
  // edge pierces: the widest edge axis, skipping axes and all 144 (their
  // own table: another set of pairs).
  for (bool all : {false, true}) {
    benchmark::RegisterBenchmark(
        all ? "widest edge axis/all 144 axes" : "widest edge axis/skipping axes",
        [&sets, all](benchmark::State& st) {
          const auto search = all ? rms::dcp_model::internal::WidestEdgeAxisExhaustive
                                  : rms::dcp_model::internal::WidestEdgeAxis;
          const auto& pairs = sets.hex_dense_boxes_no_edge_pierces;
          std::size_t i = 0;
          for (auto _ : st) {
            const auto& [a, b] = pairs[i++ % pairs.size()];
            benchmark::DoNotOptimize(search(a, b).gap_ft);
          }
        });
  }
  RegisterDcp("dense general/DCP, verdict", sets.hex_dense_general, verdict_only);
  RegisterDcp("dense general/DCP, verdict and separating plane", sets.hex_dense_general, {});
  benchmark::RegisterBenchmark(
      "dense general/FCL collide() on convex (GJK/EPA)", [&sets](benchmark::State& st) {
        Cycle(st, [&](std::size_t i) { return sets.fcl_dense_general[i]->Collide(); });
      });
  // The mission's Mode 1 pairs.
  if (sets.hex_mission_boxes.size() == 4096 && sets.hex_mission_general.size() == 4096) {
    RegisterDcp("mission boxes/DCP, verdict", sets.hex_mission_boxes, verdict_only);
    RegisterDcp("mission boxes/DCP, verdict and separating plane", sets.hex_mission_boxes, {});
    benchmark::RegisterBenchmark("mission boxes/separating axes, 15 (double)",
                                 [&sets](benchmark::State& st) {
                                   Cycle(st, [&](std::size_t i) {
                                     return rms::bench::SatBoxesIntersect(
                                         sets.mission_boxes[i].first, sets.mission_boxes[i].second);
                                   });
                                 });
    benchmark::RegisterBenchmark(
        "mission boxes/FCL collide() on boxes (computes a contact)", [&sets](benchmark::State& st) {
          Cycle(st, [&](std::size_t i) { return sets.fcl_mission_boxes[i]->Collide(); });
        });
    RegisterDcp("mission general/DCP, verdict", sets.hex_mission_general, verdict_only);
    RegisterDcp("mission general/DCP, verdict and separating plane", sets.hex_mission_general, {});
    benchmark::RegisterBenchmark(
        "mission general/FCL collide() on convex (GJK/EPA)", [&sets](benchmark::State& st) {
          Cycle(st, [&](std::size_t i) { return sets.fcl_mission_general[i]->Collide(); });
        });
  }
}

// General hexahedra.
void RegisterGeneralTimings(const Sets& sets) {
  const rms::dcp_model::CollideOptions verdict_only = VerdictOnly();
  RegisterDcp("general/DCP, verdict", sets.hex_general, verdict_only);
  RegisterDcp("general/DCP, verdict and separating plane", sets.hex_general, {});
  benchmark::RegisterBenchmark("general/libccd MPR", [&sets](benchmark::State& st) {
    Cycle(st, [&](std::size_t i) {
      return rms::bench::CcdMprHulls(sets.hulls_general[i].first, sets.hulls_general[i].second);
    });
  });
  benchmark::RegisterBenchmark(
      "general/FCL collide() on convex (GJK/EPA)", [&sets](benchmark::State& st) {
        Cycle(st, [&](std::size_t i) { return sets.fcl_general[i]->Collide(); });
      });
  benchmark::RegisterBenchmark("general/exact (CGAL)", [&sets](benchmark::State& st) {
    Cycle(st, [&](std::size_t i) {
      return rms::reference::ExactHullsIntersect(sets.hulls_general[i].first,
                                                 sets.hulls_general[i].second);
    });
  });
}

// Every method on the same 4096 pairs of each set, cycled.
void RegisterTimings(const Sets& sets) {
  RegisterBoxTimings(sets);
  RegisterDenseTimings(sets);
  RegisterGeneralTimings(sets);
}

// A set's rows (names under `prefix`), each against the set's DCP verdict
// and, when given (> 0), its separating-axis test.
void SetRows(const Collector& collector, const std::string& prefix, double dcp, double sat,
             std::ostringstream& md) {
  char line[600];
  for (const auto& [name, ns] : collector.ns) {
    if (name.rfind(prefix, 0) != 0) continue;
    if (sat > 0)
      std::snprintf(line, sizeof line, "| %s | %.1f | %.2f | %.2f |\n",
                    name.substr(prefix.size()).c_str(), ns, ns / dcp, ns / sat);
    else
      std::snprintf(line, sizeof line, "| %s | %.1f | %.2f |\n", name.substr(prefix.size()).c_str(),
                    ns, ns / dcp);
    md << line;
  }
}

double Figure(const Collector& collector, const std::string& name) {
  const auto it = collector.ns.find(name);
  return it == collector.ns.end() ? 0.0 : it->second;
}

// "**Target** what: figure (met | MISSED by ...)", or "not measured".
std::string TargetLine(const std::string& what, double value, double limit, bool at_most,
                       const char* unit) {
  if (!(value > 0)) return "- **Target** " + what + ": not measured.\n";
  const bool met = at_most ? value <= limit : value >= limit;
  char verdict[48] = "met";
  if (!met)
    std::snprintf(verdict, sizeof verdict, "MISSED by %.2fx",
                  at_most ? value / limit : limit / value);
  char b[300];
  std::snprintf(b, sizeof b, "- **Target** %s: %.2f%s (%s).\n", what.c_str(), value, unit, verdict);
  return b;
}

// Step 4's last resort (docs/collision.md "The widest edge axis") on the
// dense box pairs that reach it: skipping axes against all 144, and how
// many axes the skipping search computes on them (counted here, outside the
// timed loop).
void WidestEdgeAxisTable(const Collector& collector, const Sets& sets, std::ostringstream& md) {
  const double skip = Figure(collector, "widest edge axis/skipping axes");
  const double all = Figure(collector, "widest edge axis/all 144 axes");
  const auto& pairs = sets.hex_dense_boxes_no_edge_pierces;
  if (skip <= 0 || all <= 0 || pairs.empty()) return;
  long axes = 0;
  for (const auto& [a, b] : pairs)
    axes += rms::dcp_model::internal::WidestEdgeAxis(a, b).axes_computed;
  char line[400];
  std::snprintf(
      line, sizeof line,
      "\n| The widest edge axis, on the %zu dense box pairs no face separates and no edge "
      "pierces (step 4) | ns / pair | axes computed, mean | vs all 144 |\n"
      "|---|---|---|---|\n"
      "| skipping the pairs of edge directions bounded below (the DCP's) | %.1f | %.1f | "
      "%.2f |\n"
      "| all 144 axes (the reference: the same answer, bit for bit) | %.1f | 144 | 1.00 |\n",
      pairs.size(), skip, static_cast<double>(axes) / static_cast<double>(pairs.size()), skip / all,
      all);
  md << line;
}

// Issue 18's sets: pairs whose bounding spheres overlap, half colliding, and
// its targets (docs/performance.md "Collision against its peers").
void DenseTables(const Collector& collector, const Sets& sets_made, std::ostringstream& md) {
  const double dcp = Figure(collector, "dense boxes/DCP, verdict");
  const double plane = Figure(collector, "dense boxes/DCP, verdict and separating plane");
  const double sat = Figure(collector, "dense boxes/separating axes, 15 (double)");
  const double dcp_g = Figure(collector, "dense general/DCP, verdict");
  md << "\n| Method (4096 dense box pairs: bounding spheres overlap, "
     << sets_made.dense_boxes_colliding
     << " colliding) | ns / pair | vs the DCP | vs separating axes |\n|---|---|---|---|\n";
  if (dcp > 0 && sat > 0) SetRows(collector, "dense boxes/", dcp, sat, md);
  md << "\n| Method (4096 dense general hexahedra: spheres overlap, "
     << sets_made.dense_general_colliding
     << " colliding) | ns / pair | vs the DCP |\n|---|---|---|\n";
  if (dcp_g > 0) SetRows(collector, "dense general/", dcp_g, 0.0, md);
  WidestEdgeAxisTable(collector, sets_made, md);
  const double dcp_mb = Figure(collector, "mission boxes/DCP, verdict");
  const double sat_mb = Figure(collector, "mission boxes/separating axes, 15 (double)");
  const double dcp_mg = Figure(collector, "mission general/DCP, verdict");
  md << "\n| Method (4096 box pairs of an autopilot mission's " << sets_made.mission_frames
     << " Mode 1 frames: EFF HEX 1-3 against the BAR and its posts; "
     << sets_made.mission_boxes_colliding
     << " colliding) | ns / pair | vs the DCP | vs separating axes |\n|---|---|---|---|\n";
  if (dcp_mb > 0 && sat_mb > 0) SetRows(collector, "mission boxes/", dcp_mb, sat_mb, md);
  md << "\n| Method (4096 general pairs of the same frames: EFF HEX 1-3 against the payload's "
        "strips; "
     << sets_made.mission_general_colliding
     << " colliding) | ns / pair | vs the DCP |\n|---|---|---|\n";
  if (dcp_mg > 0) SetRows(collector, "mission general/", dcp_mg, 0.0, md);
  md << "\n"
     << TargetLine("on dense box pairs the verdict at most 2x separating axes",
                   sat > 0 ? dcp / sat : 0.0, 2.0, true, "x")
     << TargetLine("on dense box pairs the verdict with its plane at most 3x separating axes",
                   sat > 0 ? plane / sat : 0.0, 3.0, true, "x");
  // At least 10x faster than FCL on every set.
  const struct {
    const char* set;
    const char* dcp;
    const char* fcl;
  } sets[] = {
      {"random boxes", "boxes/DCP, verdict", "boxes/FCL collide() on boxes (computes a contact)"},
      {"random general hexahedra", "general/DCP, verdict",
       "general/FCL collide() on convex (GJK/EPA)"},
      {"dense boxes", "dense boxes/DCP, verdict",
       "dense boxes/FCL collide() on boxes (computes a contact)"},
      {"dense general hexahedra", "dense general/DCP, verdict",
       "dense general/FCL collide() on convex (GJK/EPA)"},
      {"the mission's box pairs", "mission boxes/DCP, verdict",
       "mission boxes/FCL collide() on boxes (computes a contact)"},
      {"the mission's general pairs", "mission general/DCP, verdict",
       "mission general/FCL collide() on convex (GJK/EPA)"},
  };
  for (const auto& x : sets) {
    const double d = Figure(collector, x.dcp), f = Figure(collector, x.fcl);
    md << TargetLine(std::string("at least 10x faster than FCL on ") + x.set,
                     d > 0 && f > 0 ? f / d : 0.0, 10.0, false, "x");
  }
}

// The timing tables and their targets (docs/performance.md).
void TimingTables(Collector& collector, const Sets& sets_made, std::ostringstream& md) {
  const double dcp = Figure(collector, "boxes/DCP, verdict");
  const double sat = Figure(collector, "boxes/separating axes, 15 (double)");
  const double fcl = Figure(collector, "boxes/FCL collide() on boxes (computes a contact)");
  char line[600];
  // The FCL ratio repetition by repetition (the same pairs, run after run).
  double ratio_lo = 1e30, ratio_hi = 0;
  const auto& d = collector.all["boxes/DCP, verdict"];
  const auto& f = collector.all["boxes/FCL collide() on boxes (computes a contact)"];
  for (std::size_t i = 0; i < std::min(d.size(), f.size()); ++i) {
    ratio_lo = std::min(ratio_lo, f[i] / d[i]);
    ratio_hi = std::max(ratio_hi, f[i] / d[i]);
  }
  const std::size_t reps = collector.all["boxes/DCP, verdict"].size();
  md << "## Collision against its peers\n\n"
     << "`rms_collision_bench` (Google Benchmark): the same 4096 random pairs for every method, "
        "cycled, time per "
        "pair (CPU), the median of "
     << reps << " repetition" << (reps == 1 ? "" : "s")
     << ". The DCP is the "
        "report's algorithm (Section IV.A.1; `docs/collision.md`), verdict only unless said; FCL's "
        "`collide()` on "
        "boxes computes a contact (point, normal, depth) as it decides; ODE's `dBoxTouchesBox` and "
        "the 15-axis "
        "separating-axis test (double) give a verdict only; for general hexahedra FCL works on "
        "convex meshes "
        "(GJK/EPA) and libccd with MPR.\n\n";
  md << "| Method (4096 random box pairs, cycled) | ns / pair | vs the DCP | vs separating axes "
        "|\n|---|---|---|---|\n";
  for (const auto& [name, ns] : collector.ns) {
    if (name.rfind("boxes/", 0) != 0) continue;
    std::snprintf(line, sizeof line, "| %s | %.1f | %.2f | %.2f |\n", name.substr(6).c_str(), ns,
                  ns / dcp, ns / sat);
    md << line;
  }
  const double dcp_g = Figure(collector, "general/DCP, verdict");
  md << "\n| Method (4096 random general hexahedra: frusta, skewed) | ns / pair | vs the DCP "
        "|\n|---|---|---|\n";
  for (const auto& [name, ns] : collector.ns) {
    if (name.rfind("general/", 0) != 0) continue;
    std::snprintf(line, sizeof line, "| %s | %.1f | %.2f |\n", name.substr(8).c_str(), ns,
                  ns / dcp_g);
    md << line;
  }
  // A target whose figures were not measured (a --benchmark_filter left
  // them out) says so, never "met".
  if (dcp > 0 && sat > 0) {
    std::snprintf(line, sizeof line,
                  "\n- **Target** collision at most 40 ns a random box pair: %.1f ns (%s; twice "
                  "the separating-axis floor here is %.1f ns).\n",
                  dcp, dcp <= 40.0 ? "met" : "MISSED", 2 * sat);
    md << line;
  } else {
    md << "\n- **Target** collision at most 40 ns a random box pair: not measured.\n";
  }
  if (dcp > 0 && fcl > 0) {
    std::snprintf(line, sizeof line,
                  "- **Target** collision at least 8x faster than FCL on the same pairs: %.1fx "
                  "(%s; over the repetitions %.1fx to %.1fx).\n",
                  fcl / dcp, fcl / dcp >= 8.0 ? "met" : "MISSED", ratio_lo, ratio_hi);
    md << line;
  } else {
    md << "- **Target** collision at least 8x faster than FCL on the same pairs: not measured.\n";
  }
  DenseTables(collector, sets_made, md);
}

// Disagreements with the exact reference, by family of pairs, every method.
void AgreementTable(const Agreement& ag, const char* title, std::ostringstream& md) {
  md << "\n| " << title << " | pairs |";
  for (const auto& [m, n] : ag.wrong) md << " " << m << " |";
  std::vector<std::string> methods;
  for (const auto& [m, n] : ag.wrong) methods.push_back(m);
  md << "\n|---|---|";
  for (std::size_t i = 0; i < methods.size(); ++i) md << "---|";
  md << "\n";
  for (const auto& [kind, n] : ag.pairs_by_kind) {
    md << "| " << kind << " | " << n << " |";
    for (const auto& m : methods) {
      const auto it = ag.wrong_by_kind.find(m);
      const long w =
          it == ag.wrong_by_kind.end() ? 0 : (it->second.count(kind) ? it->second.at(kind) : 0);
      md << " " << w << " |";
    }
    md << "\n";
  }
  md << "| **all** | " << ag.pairs << " |";
  for (const auto& m : methods) md << " **" << ag.wrong.at(m) << "** |";
  md << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  std::string md_path;
  long agreement_pairs = 14000;
  // Our own flags first; the rest go to Google Benchmark.
  std::vector<char*> rest = {argv[0]};
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--md") && i + 1 < argc)
      md_path = argv[++i];
    else if (!std::strcmp(argv[i], "--agreement") && i + 1 < argc)
      agreement_pairs = std::atol(argv[++i]);
    else
      rest.push_back(argv[i]);
  }
  int bargc = static_cast<int>(rest.size());
  benchmark::Initialize(&bargc, rest.data());
  rms::bench::InitOde();

  static const Sets sets = MakeSets();
  RegisterTimings(sets);
  Collector collector;
  benchmark::RunSpecifiedBenchmarks(&collector);
  benchmark::Shutdown();

  const std::uint64_t seed = 19721122;
  std::fprintf(stderr, "agreement: %ld pairs a family, seed %llu\n", agreement_pairs,
               static_cast<unsigned long long>(seed));
  const auto [box_agree, gen_agree] = MeasureAgreement(agreement_pairs, seed);

  std::ostringstream md;
  TimingTables(collector, sets, md);
  md << "\nVerdicts that disagree with the exact reference (CGAL, exact arithmetic; touching "
        "counts as intersecting), "
        "by family of pairs (seed 19721122):\n";
  AgreementTable(box_agree, "Boxes: family", md);
  AgreementTable(gen_agree, "General hexahedra: family", md);
  std::fputs(md.str().c_str(), stdout);
  if (!md_path.empty()) std::ofstream(md_path) << md.str();
  return 0;
}
