// The DCP's collision algorithm (report IV.A.1): hand-made cases, then
// agreement with the independent references on generated pairs.
#include "rms/dcp_model/collision.h"

#include <bit>
#include <cmath>
#include <cstdio>
#include <gtest/gtest.h>
#include <limits>
#include <random>

#include "rms/reference/compare.h"
#include "rms/reference/generators.h"

namespace rms::dcp_model {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

Hexahedron AxisBox(const Vector3d& lo, const Vector3d& hi) {
  // Face a at x = lo.x (U = +X), b at y = lo.y, c at z = lo.z.
  const Vector3d c = 0.5 * (lo + hi), h = 0.5 * (hi - lo);
  return MakeBox(Vector3d(lo.x(), c.y(), c.z()), Vector3d::UnitX(), Vector3d::UnitY(),
                 Vector3d::UnitZ(), 2 * h.x(), h.y(), h.z());
}

TEST(Hexahedron, TheReportsVertexNumberingAndFaceLetters) {
  // EFF HEX 1 at A = 0 with UX2, UY2, UZ2 = X, Y, Z: the report's v1..v4.
  const Hexahedron h = MakeBox(Vector3d::Zero(), Vector3d::UnitX(), Vector3d::UnitY(),
                               Vector3d::UnitZ(), 3.0, 1.0, 2.0);
  EXPECT_EQ(h.vertex(0), Vector3d(0, -1, -2));  // v1 = A - W UY2 - H UZ2
  EXPECT_EQ(h.vertex(1), Vector3d(0, -1, 2));   // v2 = A - W UY2 + H UZ2
  EXPECT_EQ(h.vertex(2), Vector3d(3, -1, -2));  // v3 = A - W UY2 - H UZ2 + L UX2
  EXPECT_EQ(h.vertex(3), Vector3d(0, 1, 2));    // v4 = A + W UY2 + H UZ2
  // Face d is the far ("bottom") face along UX2; b and e the -Y and +Y faces.
  EXPECT_EQ(h.normal(kFaceD), Vector3d::UnitX());
  EXPECT_EQ(h.normal(kFaceB), -Vector3d::UnitY());
  EXPECT_EQ(h.normal(kFaceE), Vector3d::UnitY());
  EXPECT_EQ(h.normal(kFaceC), -Vector3d::UnitZ());
  EXPECT_EQ(FaceLetter(kFaceD), 'd');
  // Every vertex lies on its three faces.
  for (int i = 0; i < 8; ++i)
    for (int f : kVertexFaces[i])
      EXPECT_NEAR(h.Beyond(f, h.x[i], h.y[i], h.z[i]), 0.0, 1e-12) << i << f;
  // A general hexahedron from the same vertices has the same planes.
  std::array<Vector3d, 8> v;
  for (int i = 0; i < 8; ++i) v[i] = h.vertex(i);
  const Hexahedron g = FromVertices(v);
  ASSERT_TRUE(g.valid);
  for (int f = 0; f < 6; ++f) {
    EXPECT_LT((g.normal(f) - h.normal(f)).norm(), 1e-12);
    EXPECT_NEAR(g.d[f], h.d[f], 1e-12);
  }
}

TEST(Hexahedron, LocationWordsSayWhichFacesAPointIsBeyond) {
  const Hexahedron h = AxisBox(Vector3d(0, 0, 0), Vector3d(1, 1, 1));
  EXPECT_EQ(h.Word(Vector3d(0.5, 0.5, 0.5), 1e-12), 0);              // inside: six zeros
  EXPECT_EQ(h.Word(Vector3d(2, 0.5, 0.5), 1e-12), FaceBit(kFaceD));  // beyond x = 1
  EXPECT_EQ(h.Word(Vector3d(-1, -1, 2), 1e-12),
            FaceBit(kFaceA) | FaceBit(kFaceB) | FaceBit(kFaceF));
  EXPECT_EQ(h.Word(Vector3d(1, 0.5, 0.5), 1e-12), 0);  // on a face: FALSE side
}

TEST(Collide, VertexInsideAndFaceSeparation) {
  const Hexahedron a = AxisBox(Vector3d(0, 0, 0), Vector3d(1, 1, 1));
  const Hexahedron b = AxisBox(Vector3d(0.5, 0.5, 0.5), Vector3d(2, 2, 2));
  const CollisionResult r = Collide(a, b);
  EXPECT_EQ(r.verdict, Verdict::kCollide);
  EXPECT_EQ(r.decider, Decider::kVertexOfAInB);
  EXPECT_EQ(r.index, 6);  // v7 = (1, 1, 1) is inside b

  const Hexahedron c = AxisBox(Vector3d(3, 0, 0), Vector3d(4, 1, 1));
  // With bounding-sphere rejection (the default) the spheres decide first,
  // with a plane that still separates.
  const CollisionResult fast = Collide(a, c);
  EXPECT_EQ(fast.verdict, Verdict::kSeparate);
  EXPECT_EQ(fast.decider, Decider::kSpheresApart);
  ASSERT_TRUE(fast.plane_valid);
  EXPECT_TRUE(PlaneSeparates(a, c, fast.plane.n_R, fast.plane.d_ft, 0.0));
  // The report's algorithm alone names c's face a.
  CollideOptions report_only;
  report_only.sphere_reject = false;
  report_only.aabb_reject = false;
  const CollisionResult s = Collide(a, c, report_only);
  EXPECT_EQ(s.verdict, Verdict::kSeparate);
  EXPECT_EQ(s.decider, Decider::kFaceOfBSeparates);
  EXPECT_EQ(s.face, kFaceA);  // all of a lies beyond c's face a (x = 3)
  ASSERT_TRUE(s.plane_valid);
  EXPECT_LT((s.plane.n_R - Vector3d::UnitX()).norm(), 1e-15);  // from a toward c
  EXPECT_DOUBLE_EQ(s.plane.d_ft, 3.0);
}

TEST(Collide, BoundingBoxesApartDecideWhereTheSpheresOverlap) {
  // Two long bars side by side: their spheres overlap, their boxes do not.
  const Hexahedron a = AxisBox(Vector3d(0, 0, 0), Vector3d(10, 1, 1));
  const Hexahedron b = AxisBox(Vector3d(0, 1.5, 0), Vector3d(10, 2.5, 1));
  const CollisionResult r = Collide(a, b);
  EXPECT_EQ(r.verdict, Verdict::kSeparate);
  EXPECT_EQ(r.decider, Decider::kBoxesApart);
  ASSERT_TRUE(r.plane_valid);
  EXPECT_LT((r.plane.n_R - Vector3d::UnitY()).norm(), 1e-15);
  EXPECT_DOUBLE_EQ(r.plane.d_ft, 1.25);  // midway in the gap
  const CollisionResult back = Collide(b, a);
  EXPECT_EQ(back.decider, Decider::kBoxesApart);
  EXPECT_TRUE(PlaneSeparates(b, a, back.plane.n_R, back.plane.d_ft, 0.0));
  // Without the box test the report's algorithm decides the same.
  CollideOptions report_only;
  report_only.sphere_reject = report_only.aabb_reject = false;
  EXPECT_EQ(Collide(a, b, report_only).verdict, Verdict::kSeparate);
  EXPECT_NE(Collide(a, b, report_only).decider, Decider::kBoxesApart);
}

TEST(Collide, TouchingCountsAsCollision) {
  const Hexahedron a = AxisBox(Vector3d(0, 0, 0), Vector3d(1, 1, 1));
  EXPECT_EQ(Collide(a, AxisBox(Vector3d(1, 0, 0), Vector3d(2, 1, 1))).verdict, Verdict::kCollide);
  EXPECT_EQ(Collide(a, AxisBox(Vector3d(1, 1, 1), Vector3d(2, 2, 2))).verdict,
            Verdict::kCollide);  // a corner
  EXPECT_EQ(Collide(a, AxisBox(Vector3d(1 + 1e-9, 0, 0), Vector3d(2, 1, 1))).verdict,
            Verdict::kSeparate);
}

TEST(Collide, ARodThroughASlabNeedsTheEdgeTestInBothDirections) {
  // No vertex of either lies in the other.
  const Hexahedron rod = AxisBox(Vector3d(-0.1, -0.1, -5), Vector3d(0.1, 0.1, 5));
  const Hexahedron slab = AxisBox(Vector3d(-3, -3, -0.2), Vector3d(3, 3, 0.2));
  const CollisionResult r1 = Collide(rod, slab);
  EXPECT_EQ(r1.verdict, Verdict::kCollide);
  EXPECT_EQ(r1.decider, Decider::kEdgeOfAPiercesB);  // the rod's long edges pierce the slab's faces
  const CollisionResult r2 = Collide(slab, rod);
  EXPECT_EQ(r2.verdict, Verdict::kCollide);
  EXPECT_EQ(r2.decider, Decider::kEdgeOfBPiercesA);  // found only in the second direction
  // Crossed beams.
  const Hexahedron beam1 = AxisBox(Vector3d(-5, -0.2, -0.2), Vector3d(5, 0.2, 0.2));
  const Hexahedron beam2 = AxisBox(Vector3d(-0.2, -5, -0.2), Vector3d(0.2, 5, 0.2));
  EXPECT_EQ(Collide(beam1, beam2).verdict, Verdict::kCollide);
}

TEST(Collide, AnEdgeThatStopsShortOfTheSolidIsNotACollision) {
  // docs/collision.md's counter-example to a ray-only test: the edge from
  // (2, 2, 2) heads into the corner region of the unit cube and its ray
  // would enter through face x = 1, but the edge ends at (1.12, 0.8, 0.8),
  // 0.12 ft short. Its vertices' words differ in two bits.
  const Hexahedron cube = AxisBox(Vector3d(0, 0, 0), Vector3d(1, 1, 1));
  std::array<Vector3d, 8> v;
  // A thin hexahedron along that edge: every vertex within 0.01 of it.
  const Vector3d p0(2, 2, 2), p1(1.12, 0.8, 0.8);
  const Vector3d u = (p1 - p0).normalized(), side = u.cross(Vector3d::UnitZ()).normalized(),
                 up = u.cross(side);
  const Hexahedron needle = MakeBox(p0, u, side, up, (p1 - p0).norm(), 0.005, 0.005);
  const CollisionResult r = Collide(needle, cube);
  EXPECT_EQ(r.verdict, Verdict::kSeparate) << static_cast<int>(r.decider);
  EXPECT_TRUE(r.plane_valid);
  // Longer, it reaches the cube.
  const Hexahedron longer = MakeBox(p0, u, side, up, 1.2 * (p1 - p0).norm(), 0.005, 0.005);
  EXPECT_EQ(Collide(longer, cube).verdict, Verdict::kCollide);
}

TEST(Collide, NonFiniteInputIsAnErrorNotAVerdict) {
  const Hexahedron a = AxisBox(Vector3d(0, 0, 0), Vector3d(1, 1, 1));
  for (double bad : {std::nan(""), std::numeric_limits<double>::infinity()}) {
    const Hexahedron b = AxisBox(Vector3d(bad, 0, 0), Vector3d(2, 1, 1));
    EXPECT_FALSE(b.valid);
    const CollisionResult r = Collide(a, b);
    EXPECT_EQ(r.verdict, Verdict::kInvalid);
    EXPECT_EQ(r.decider, Decider::kNonFinite);
    EXPECT_EQ(Collide(b, a).verdict, Verdict::kInvalid);
  }
}

TEST(Collide, NearParallelEdgesJustOutsideTheBandGetTheExactVerdict) {
  // Edges at 1e-7 .. 1e-2 rad, 1.5 to 3 band widths apart or overlapping.
  // The old tolerance (T_j against tau |e| |V|) grew as 1/sin(angle) and
  // called about 5% of the apart ones collisions.
  const std::uint64_t seed = 20261202;
  std::printf("seed %llu\n", static_cast<unsigned long long>(seed));
  reference::PairGenerator gen(seed);
  std::uniform_real_distribution<double> k(1.5, 3.0);
  int wrong = 0, pairs = 0;
  for (double scale : {1e-3, 1.0, 1e4}) {
    for (int i = 0; i < 2000; ++i) {
      const bool apart = i % 2 == 0;
      const reference::Pair p =
          gen.NearParallelEdges(scale, (apart ? 1 : -1) * k(gen.rng()) * 1e-9);
      const CollisionResult r = Collide(p.a.hex, p.b.hex);
      ASSERT_NE(r.verdict, Verdict::kInvalid);
      ++pairs;
      if ((r.verdict == Verdict::kCollide) == apart) {
        if (++wrong < 5)
          ADD_FAILURE() << "scale " << scale << " pair " << i
                        << (apart ? " apart" : " overlapping");
      }
    }
  }
  EXPECT_EQ(wrong, 0) << "of " << pairs;
}

TEST(Hexahedron, SmallSolidsFarFromTheOriginAreAnsweredAndDegenerateOnesRefusedWithTheReason) {
  // 0.001 ft solids at 1e4 ft: a bolt far out in the Reference frame.
  const std::uint64_t seed = 977;
  std::printf("seed %llu\n", static_cast<unsigned long long>(seed));
  std::mt19937_64 rng(seed);
  for (int i = 0; i < 500; ++i) {
    const Vector3d at = 1e4 * reference::RandomRotation(rng).col(0);
    const reference::Solid g =
        reference::General(at, reference::RandomShear(rng, 0.5), Vector3d(5e-4, 3e-4, 4e-4), 0.7);
    ASSERT_TRUE(g.hex.valid) << i << ": " << HexProblemName(g.hex.problem);
    const reference::Solid b =
        reference::Box(at, reference::RandomRotation(rng), Vector3d(5e-4, 2e-4, 3e-4));
    ASSERT_TRUE(b.hex.valid) << i << ": " << HexProblemName(b.hex.problem);
    // A copy moved by 2 x its size is separate; by a tenth of it, collides.
    const reference::Solid far = reference::Box(
        at + Vector3d(2e-3, 0, 0), reference::RandomRotation(rng), Vector3d(5e-4, 2e-4, 3e-4));
    const reference::Solid near = reference::Box(
        at + Vector3d(1e-4, 0, 0), reference::RandomRotation(rng), Vector3d(5e-4, 2e-4, 3e-4));
    EXPECT_EQ(Collide(b.hex, far.hex).verdict, Verdict::kSeparate);
    EXPECT_EQ(Collide(b.hex, near.hex).verdict, Verdict::kCollide);
  }
  // Degenerate solids, near and far, each refused with its reason.
  for (const Vector3d& at : {Vector3d(0, 0, 0), Vector3d(1e4, -1e4, 1e4)}) {
    std::array<Vector3d, 8> cube;
    for (int i = 0; i < 8; ++i)
      cube[i] = at + 1e-3 * Vector3d(reference::kVertexSigns[i][0], reference::kVertexSigns[i][1],
                                     reference::kVertexSigns[i][2]);
    EXPECT_EQ(FromVertices(cube).problem, HexProblem::kNone);
    auto flat = cube;
    for (auto& v : flat) v.z() = at.z();
    EXPECT_EQ(FromVertices(flat).problem, HexProblem::kDegenerateFace);
    auto thin =
        cube;  // 1e-18 thick: below what rounding resolves at 1e4 ft (and 1e-9 x scale at 0)
    for (int i = 0; i < 8; ++i)
      thin[i].z() =
          at.z() + (reference::kVertexSigns[i][2] > 0 ? 1e-18 * std::max(1.0, at.norm()) : 0.0);
    const HexProblem tp = FromVertices(thin).problem;
    EXPECT_TRUE(tp == HexProblem::kFlat || tp == HexProblem::kDegenerateFace) << HexProblemName(tp);
    auto twisted = cube;
    std::swap(twisted[0], twisted[2]);
    EXPECT_NE(FromVertices(twisted).problem, HexProblem::kNone);
    auto dented = cube;  // v1 pushed in along the diagonal: faces a, b, c bend inward
    dented[0] = at + 0.2e-3 * Vector3d(-1, -1, -1);
    EXPECT_EQ(FromVertices(dented).problem, HexProblem::kNonConvex);
    auto nan = cube;
    nan[3].y() = std::nan("");
    EXPECT_EQ(FromVertices(nan).problem, HexProblem::kNonFinite);
    auto huge = cube;
    huge[5] = Vector3d(1e200, 0, 0);
    EXPECT_EQ(FromVertices(huge).problem, HexProblem::kOverflow);
  }
  EXPECT_STREQ(HexProblemName(HexProblem::kNonConvex),
               "not convex: a vertex beyond a face's plane");
  EXPECT_EQ(
      MakeBox(Vector3d::Zero(), Vector3d::UnitX(), Vector3d::UnitY(), Vector3d::UnitZ(), 0.0, 1, 1)
          .problem,
      HexProblem::kBadDimension);
  EXPECT_EQ(MakeBox(Vector3d(1e4, 0, 0), Vector3d::UnitX(), Vector3d::UnitY(), Vector3d::UnitZ(),
                    1e-14, 1, 1)
                .problem,
            HexProblem::kFlat);
}

TEST(Collide, TheHintCannotChangeAVerdict) {
  // Exactly touching faces collide; their common plane as the hint must not
  // call them separate.
  const Hexahedron a = AxisBox(Vector3d(0, 0, 0), Vector3d(1, 1, 1));
  const Hexahedron b = AxisBox(Vector3d(1, 0, 0), Vector3d(2, 1, 1));
  scene_model::SeparatingPlane hint{Vector3d::UnitX(), 1.0};
  CollideOptions o;
  o.hint = &hint;
  o.sphere_reject = o.aabb_reject = false;  // the hint first
  const CollisionResult r = Collide(a, b, o);
  EXPECT_EQ(r.verdict, Verdict::kCollide);
  EXPECT_NE(r.decider, Decider::kHintPlane);
  // Apart by 1e-6, the hint decides.
  const Hexahedron c = AxisBox(Vector3d(1 + 1e-6, 0, 0), Vector3d(2, 1, 1));
  hint.d_ft = 1 + 5e-7;
  EXPECT_EQ(Collide(a, c, o).decider, Decider::kHintPlane);
}

TEST(Collide, TheCompiledFaceListsCoverEveryCombination) {
  for (int m = 0; m < 64; ++m) {
    int bits = 0;
    for (int i = 0; i < kFacesOfMask[m].count; ++i) bits |= 1 << kFacesOfMask[m].faces[i];
    EXPECT_EQ(bits, m);
  }
}

TEST(CollideVsReference, AgreesOutsideTheBandOnGeneratedPairs) {
  // Fixed seed; the long target (rms_long_tests) runs 10^6 pairs.
  const std::uint64_t seed = 20261122;
  const long count = 40000;
  std::printf("seed %llu, %ld pairs\n", static_cast<unsigned long long>(seed), count);
  const reference::CompareStats st = reference::Compare(seed, count, 1e-9, /*exact_every=*/20);
  std::printf("%s", reference::Describe(st).c_str());
  EXPECT_EQ(st.disagree_outside, 0);
  EXPECT_EQ(st.invalid, 0);
  EXPECT_EQ(st.plane_wrong, 0);
  EXPECT_EQ(st.plane_missing, 0);
  // Exactly touching faces (representable coordinates) are always collisions.
  EXPECT_EQ(st.in_band_by_kind.count("touching faces, exact"), 0u);
  // The mix really exercises every path.
  EXPECT_GT(st.deciders.at("edge of A pierces B") + st.deciders.at("edge of B pierces A"), 100);
  EXPECT_GT(st.deciders.at("no edge pierces"), 100);
  EXPECT_GT(st.collide, count / 5);
  EXPECT_LT(st.collide, 4 * count / 5);
}

std::uint64_t Bits(double v) { return std::bit_cast<std::uint64_t>(v); }

TEST(Collide, TheAvxPathsGiveTheScalarCodesResultsBitForBit) {
  // Every field of the result (verdict, decider, index, face, plane bits,
  // words, triple products) with the AVX paths and with the portable scalar
  // code, on every family of the generator at three scales, with and
  // without planes and bounding-volume rejection (docs/performance.md).
  const std::uint64_t seed = 4242;
  std::printf("seed %llu\n", static_cast<unsigned long long>(seed));
  const bool avx = UseAvx(true);
  std::printf("AVX on this processor: %s\n", avx ? "yes" : "no (scalar against scalar)");
#if defined(__x86_64__) || defined(__i386__)
  ASSERT_EQ(avx, __builtin_cpu_supports("avx") != 0) << "the AVX paths are not built in";
#endif
  CollideOptions opts[3];
  opts[1].want_plane = false;
  opts[2].sphere_reject = opts[2].aabb_reject = false;
  auto same = [](const CollisionResult& x, const CollisionResult& y) {
    return x.verdict == y.verdict && x.decider == y.decider && x.index == y.index &&
           x.face == y.face && x.plane_valid == y.plane_valid &&
           Bits(x.plane.n_R.x()) == Bits(y.plane.n_R.x()) &&
           Bits(x.plane.n_R.y()) == Bits(y.plane.n_R.y()) &&
           Bits(x.plane.n_R.z()) == Bits(y.plane.n_R.z()) &&
           Bits(x.plane.d_ft) == Bits(y.plane.d_ft) && x.words_a == y.words_a &&
           x.words_b == y.words_b && x.words_valid == y.words_valid &&
           x.triple_products == y.triple_products;
  };
  reference::PairGenerator gen(seed);
  int differ = 0, edge_phase = 0;
  for (int i = 0; i < 60000; ++i) {
    const double scale = i % 3 == 0 ? 1e-3 : (i % 3 == 1 ? 1.0 : 1e4);
    const reference::Pair p = gen.Next(scale, i % 2 == 0);
    for (const CollideOptions& o : opts) {
      UseAvx(true);
      const CollisionResult fast = Collide(p.a.hex, p.b.hex, o);
      UseAvx(false);
      const CollisionResult plain = Collide(p.a.hex, p.b.hex, o);
      edge_phase += plain.words_valid;
      // The DCP's clearance: the gap along each plane (the same value; an
      // exactly zero gap may differ in sign, which the DCP's max(0, gap) hides).
      if (plain.plane_valid) {
        UseAvx(true);
        const double gap_fast = GapAlong(p.a.hex, p.b.hex, plain.plane.n_R);
        UseAvx(false);
        const double gap_plain = GapAlong(p.a.hex, p.b.hex, plain.plane.n_R);
        if (!(gap_fast == gap_plain) && ++differ < 5) ADD_FAILURE() << p.kind << " gap " << i;
      }
      if (!same(fast, plain) && ++differ < 5) ADD_FAILURE() << p.kind << " pair " << i;
    }
  }
  UseAvx(true);
  EXPECT_EQ(differ, 0);
  EXPECT_GT(edge_phase, 10000);  // the edge phase was exercised
}

bool SameBits(const internal::EdgeAxisPlane& x, const internal::EdgeAxisPlane& y) {
  return Bits(x.n_R.x()) == Bits(y.n_R.x()) && Bits(x.n_R.y()) == Bits(y.n_R.y()) &&
         Bits(x.n_R.z()) == Bits(y.n_R.z()) && Bits(x.d_ft) == Bits(y.d_ft) &&
         Bits(x.gap_ft) == Bits(y.gap_ft);
}

TEST(WidestEdgeAxis, SkippingAxesGivesTheExhaustiveSearchsAnswerBitForBit) {
  // Every family of the generator, boxes and general hexahedra, at five
  // scales, near the origin and 10^5 of their sizes from it; then mirror-
  // image pairs, whose pairs of edge directions tie. The search step 4
  // falls back on (docs/collision.md "The widest edge axis").
  const std::uint64_t seed = 777;
  std::printf("seed %llu\n", static_cast<unsigned long long>(seed));
  reference::PairGenerator gen(seed);
  std::mt19937_64 rng(seed);
  int differ = 0;
  long boxes = 0, box_axes = 0;
  // With the AVX paths (where the processor has them) and without.
  auto check = [&](const Hexahedron& a, const Hexahedron& b, const char* what, int i) {
    const internal::EdgeAxisPlane all = internal::WidestEdgeAxisExhaustive(a, b);
    EXPECT_EQ(all.axes_computed, kNumEdges * kNumEdges);
    int axes = 0;
    for (bool avx : {true, false}) {
      UseAvx(avx);
      const internal::EdgeAxisPlane fast = internal::WidestEdgeAxis(a, b);
      if (!SameBits(fast, all) && ++differ < 5)
        ADD_FAILURE() << what << " pair " << i << (avx ? " (AVX)" : "") << ": gap " << fast.gap_ft
                      << " against " << all.gap_ft;
      axes = fast.axes_computed;
    }
    UseAvx(true);
    return axes;
  };
  // Five scales: the three of the lab and two near the ends of the valid
  // range (products near underflow and far from overflow).
  const double scales[] = {1e-3, 1.0, 1e4, 1e-72, 1e60};
  for (int i = 0; i < 30000; ++i) {
    const double scale = scales[i % 5];
    const bool boxes_only = i % 2 == 0;
    reference::Pair p = gen.Next(scale, boxes_only);
    if (i % 11 == 0) p = reference::Translated(p, Vector3d(1e5, -2e5, 3e5) * scale);
    const int axes = check(p.a.hex, p.b.hex, p.kind.c_str(), i);
    if (boxes_only && p.kind == "random boxes") ++boxes, box_axes += axes;
  }
  // Mirror images: B is A reflected through the plane x = y and moved along
  // (1, 1, h), so directions swap between the two solids and gaps tie.
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 3000; ++i) {
    const Matrix3d R = Eigen::AngleAxisd(u(rng) * M_PI, Vector3d::UnitZ()).toRotationMatrix();
    const reference::Solid s = reference::Box(Vector3d::Zero(), R, Vector3d(1.0, 0.5, 0.25));
    std::array<Vector3d, 8> mirrored;
    const Vector3d shift(1.5 + u(rng), 1.5 + u(rng), 0.1 * u(rng));
    for (int k = 0; k < 8; ++k) mirrored[k] = Vector3d(s.v[k].y(), s.v[k].x(), s.v[k].z()) + shift;
    check(s.hex, FromVertices(mirrored), "mirror image", i);
  }
  // Solids of about 1e-73 ft whose cross products' squares are subnormal
  // (so a "unit" axis is off by tens of percent): found by a review, where
  // an unguarded bound skipped the widest axis.
  const std::array<Vector3d, 8> tiny_a = {{
      {-0x1p-247, -0x1p-242, 0x1p-242},
      {-0x1p-247, -0x1.ffffff62b601ep-243, 0x1.0000004ea4ff1p-242},
      {0x1p-247, -0x1p-242, 0x1p-242},
      {-0x1p-247, -0x1.efffff61ac390p-243, 0x1.f000009c3e710p-243},
      {-0x1p-247, -0x1.fp-243, 0x1.fp-243},
      {0x1p-247, -0x1.ffffff62b601ep-243, 0x1.0000004ea4ff1p-242},
      {0x1p-247, -0x1.efffff61ac390p-243, 0x1.f000009c3e710p-243},
      {0x1p-247, -0x1.fp-243, 0x1.fp-243},
  }};
  const std::array<Vector3d, 8> tiny_b = {{
      {-0x1p-247, 0x1p-242, -0x1p-242},
      {-0x1.fffff8p-248, 0x1p-242, -0x1p-242},
      {-0x1p-247, 0x1.08p-242, -0x1.fp-243},
      {-0x1.fffff8p-248, 0x1.fp-243, -0x1.fp-243},
      {-0x1p-247, 0x1.fp-243, -0x1.fp-243},
      {-0x1.fffff8p-248, 0x1.08p-242, -0x1.fp-243},
      {-0x1.fffff8p-248, 0x1p-242, -0x1.ep-243},
      {-0x1p-247, 0x1p-242, -0x1.ep-243},
  }};
  const Hexahedron ta = FromVertices(tiny_a), tb = FromVertices(tiny_b);
  ASSERT_TRUE(ta.valid && tb.valid) << HexProblemName(ta.problem) << HexProblemName(tb.problem);
  check(ta, tb, "subnormal cross products", 0);
  EXPECT_EQ(differ, 0);
  // Random box pairs need far fewer than the 144 axes.
  ASSERT_GT(boxes, 100);
  std::printf("random box pairs: %.1f axes of 144 on average\n",
              static_cast<double>(box_axes) / static_cast<double>(boxes));
  EXPECT_LT(box_axes, 60 * boxes);
}

}  // namespace
}  // namespace rms::dcp_model
