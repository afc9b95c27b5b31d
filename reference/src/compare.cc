#include "rms/reference/compare.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "rms/dcp_model/collision.h"
#include "rms/reference/exact_hull.h"
#include "rms/reference/generators.h"

namespace rms::reference {

namespace {
const char* DeciderName(dcp_model::Decider d) {
  switch (d) {
    case dcp_model::Decider::kVertexOfAInB:
      return "vertex of A in B";
    case dcp_model::Decider::kVertexOfBInA:
      return "vertex of B in A";
    case dcp_model::Decider::kFaceOfBSeparates:
      return "face of B separates";
    case dcp_model::Decider::kFaceOfASeparates:
      return "face of A separates";
    case dcp_model::Decider::kEdgeOfAPiercesB:
      return "edge of A pierces B";
    case dcp_model::Decider::kEdgeOfBPiercesA:
      return "edge of B pierces A";
    case dcp_model::Decider::kNoEdgePierces:
      return "no edge pierces";
    case dcp_model::Decider::kNonFinite:
      return "invalid";
    case dcp_model::Decider::kSpheresApart:
      return "bounding spheres apart";
    case dcp_model::Decider::kHintPlane:
      return "previous plane separates";
    case dcp_model::Decider::kBoxesApart:
      return "bounding boxes apart";
  }
  return "?";
}

// Pair n of the comparison at this scale. Every third block of 8 draws from
// all ten kinds (three of them general hexahedra), the rest from the seven
// box kinds: 10% general in all. Every 7th pair: two boxes with nearly
// parallel edges, gap or overlap from just outside the band to 100x it (or
// inside it, one in 8). Every 5th pair of scale <= 1 ft is moved 1 to 1e4 ft
// from the origin.
Pair DrawPair(PairGenerator& gen, long n, double scale, double band_rel) {
  const bool boxes_only = (n / 8) % 3 != 2;
  Pair p;
  if (n % 7 == 3) {
    std::uniform_real_distribution<double> lg(0.0, 2.0);
    std::uniform_int_distribution<int> sg(0, 15);
    const int k = sg(gen.rng());
    const double mag =
        (k < 2 ? 0.5 : 1.01) * band_rel * std::pow(10.0, k < 2 ? -lg(gen.rng()) : lg(gen.rng()));
    p = gen.NearParallelEdges(scale, k % 2 ? mag : -mag);
  } else {
    p = gen.Next(scale, boxes_only);
  }
  if (n % 5 == 1 && scale <= 1.0) {
    std::uniform_real_distribution<double> lg(0.0, 4.0);
    const Eigen::Vector3d dir = RandomRotation(gen.rng()).col(0);
    p = Translated(p, std::pow(10.0, lg(gen.rng())) * dir);
  }
  return p;
}

// The reference's verdict: boxes by the long double separating-axis test
// (exactly, every exact_every-th pair and every near-parallel one: exact
// wins), general hexahedra exactly.
bool ReferenceHit(const Pair& p, long n, int exact_every, CompareStats* st) {
  if (!(p.a.is_box && p.b.is_box)) {
    ++st->exact_checked;
    return ExactHullsIntersect(p.a.v, p.b.v);
  }
  bool hit = BoxesIntersect(p.a.box, p.b.box);
  if ((exact_every > 0 && n % exact_every == 0) || p.kind.rfind("near-parallel", 0) == 0) {
    ++st->exact_checked;
    hit = ExactHullsIntersect(p.a.v,
                              p.b.v);  // near contact the long double test may differ; exact wins
  }
  return hit;
}

// The DCP's verdict and plane against the reference's, within the band
// (docs/collision.md "Tolerance rule": 1000 x tau).
void Judge(const Pair& p, const dcp_model::CollisionResult& r, bool ref_hit, long n, double scale,
           double band_rel, const Topology& topo, CompareStats* st) {
  const double band = 1000.0 * dcp_model::ToleranceFt(p.a.hex, p.b.hex, band_rel / 1000.0);
  const double s = std::max(p.a.hex.scale, p.b.hex.scale);
  if (r.verdict == dcp_model::Verdict::kInvalid) {
    ++st->invalid;
    if (st->examples.size() < 10) {
      st->examples.push_back(
          "pair " + std::to_string(n) + " (" + p.kind + ", scale " + std::to_string(scale) +
          "): invalid: " +
          dcp_model::HexProblemName(p.a.hex.valid ? p.b.hex.problem : p.a.hex.problem));
    }
    return;
  }
  const bool dcp_hit = r.verdict == dcp_model::Verdict::kCollide;
  // The pair's separation, only when needed: distance if disjoint, minus
  // the penetration depth if overlapping.
  auto separation = [&] {
    return ref_hit ? -static_cast<double>(PenetrationDepth(p.a.v, p.b.v, topo))
                   : static_cast<double>(HullDistance(p.a.v, p.b.v, topo));
  };
  if (dcp_hit != ref_hit) {
    const double sep = separation();
    if (std::abs(sep) <= band) {
      ++st->disagree_in_band;
      ++st->in_band_by_kind[p.kind];
      return;
    }
    ++st->disagree_outside;
    if (st->examples.size() < 10) {
      std::ostringstream os;
      os.precision(17);
      os << "pair " << n << " (" << p.kind << ", scale " << scale << "): dcp "
         << (dcp_hit ? "collide" : "separate") << " by '" << DeciderName(r.decider)
         << "', reference " << (ref_hit ? "intersect" : "disjoint") << ", separation " << sep
         << " = " << sep / s << " x scale (band " << band / s << " x scale)";
      st->examples.push_back(os.str());
    }
  } else if (!dcp_hit) {
    // Separate: the plane must separate the solids (within the band).
    if (!r.plane_valid) {
      if (separation() > band) ++st->plane_missing;
    } else if (!dcp_model::PlaneSeparates(p.a.hex, p.b.hex, r.plane.n_R, r.plane.d_ft, band)) {
      ++st->plane_wrong;
    }
  }
}

}  // namespace

CompareStats Compare(std::uint64_t seed, long count, double band_rel, int exact_every) {
  static const double kScales[] = {1e-3, 1e-2, 1e-1, 1.0, 10.0, 100.0, 1e3, 1e4};
  const Topology topo = StandardTopology();
  PairGenerator gen(seed);
  CompareStats st;
  using Clock = std::chrono::steady_clock;
  for (long n = 0; n < count; ++n) {
    const double scale = kScales[n % 8];
    const Pair p = DrawPair(gen, n, scale, band_rel);
    ++st.pairs;
    ++st.pairs_by_kind[p.kind];
    const auto t0 = Clock::now();
    const dcp_model::CollisionResult r = dcp_model::Collide(p.a.hex, p.b.hex);
    const auto t1 = Clock::now();
    const bool ref_hit = ReferenceHit(p, n, exact_every, &st);
    const auto t2 = Clock::now();
    st.dcp_seconds += std::chrono::duration<double>(t1 - t0).count();
    st.ref_seconds += std::chrono::duration<double>(t2 - t1).count();
    ++st.deciders[DeciderName(r.decider)];
    st.collide += ref_hit;
    Judge(p, r, ref_hit, n, scale, band_rel, topo, &st);
  }
  return st;
}

std::string Describe(const CompareStats& s) {
  std::ostringstream os;
  os << s.pairs << " pairs (" << s.collide << " intersecting by the reference, " << s.exact_checked
     << " checked exactly): " << s.disagree_outside << " disagreements outside the band, "
     << s.disagree_in_band << " inside it; " << s.invalid << " invalid; separating planes missing "
     << s.plane_missing << ", wrong " << s.plane_wrong << "\n";
  os << "  DCP " << 1e9 * s.dcp_seconds / s.pairs << " ns/pair, reference "
     << 1e9 * s.ref_seconds / s.pairs << " ns/pair (timed inside the test loop)\n";
  os << "  kinds:";
  for (const auto& [k, n] : s.pairs_by_kind) os << " " << k << " " << n << ";";
  os << "\n  disagreements inside the band, by kind:";
  for (const auto& [k, n] : s.in_band_by_kind) os << " " << k << " " << n << ";";
  os << "\n  deciders:";
  for (const auto& [k, n] : s.deciders) os << " " << k << " " << n << ";";
  os << "\n";
  for (const auto& e : s.examples) os << "  " << e << "\n";
  return os.str();
}

}  // namespace rms::reference
