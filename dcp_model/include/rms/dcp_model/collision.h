#pragma once
// The collision algorithm of the report's Section IV.A.1 (docs/collision.md):
//
//  1. The location words of Hex A's eight vertices against Hex B's six faces.
//     A word of six zeros: that vertex is inside (or on) Hex B: collision.
//     A face with a 1 in all eight words: a separating plane.
//  2. The same with the roles swapped.
//     Either test ends the algorithm as soon as it decides.
//  3. Otherwise, potential edge collisions: an edge whose two vertex words'
//     exclusive-or has two or more ones is tested against the faces named by
//     those ones, by the sequence of scalar triple products of the report's
//     Figure 4; all of one face's products non-positive: the edge pierces that
//     face: collision. Hex A's edges against Hex B's faces, then Hex B's
//     against Hex A's (one direction alone misses a rod through a slab).
//  4. No collision: a separating plane, the report's non-negative-product
//     plane when it really separates, else one found from the edge directions.
//
// Before step 1, when enabled: bounding spheres apart (by more than tau)
// means separate, with the plane midway between the spheres; so do
// axis-aligned bounding boxes apart, with the plane midway between them
// normal to that axis; then, when a
// hint is given, the previous frame's plane if it still separates.
//
// Touching counts as collision: a vertex within tau of a face's plane is on
// the FALSE side, and an edge within tau of a face's boundary pierces it
// (ToleranceFt: tau = relative_tolerance x scale + kRoundingPerFt x
// magnitude, scale the larger bounding-box diagonal of the pair, magnitude
// its largest coordinate; docs/collision.md "Tolerance rule"). Invalid or
// non-finite input is an error (kInvalid), never a verdict.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <limits>

#include "rms/dcp_model/hexahedron.h"
#include "rms/scene_model/separating_plane.h"

namespace rms::dcp_model {

enum class Verdict : std::uint8_t { kSeparate, kCollide, kInvalid };

// What decided the verdict.
enum class Decider : std::uint8_t {
  kVertexOfAInB,      // index: the vertex of A (0-7) whose word was all zeros
  kVertexOfBInA,      // index: the vertex of B
  kFaceOfBSeparates,  // index: the face of B (0-5) with a 1 in all of A's words
  kFaceOfASeparates,  // index: the face of A
  kEdgeOfAPiercesB,   // index: the edge of A (0-11); face: the face of B it pierces
  kEdgeOfBPiercesA,   // index: the edge of B; face: the face of A
  kNoEdgePierces,     // every edge test negative: separate
  kNonFinite,         // invalid input
  kSpheresApart,      // the bounding spheres are apart (before the report's test, when enabled)
  kHintPlane,         // the hint plane (the previous frame's) still separates (when given)
  kBoxesApart,        // the axis-aligned bounding boxes are apart (before the report's test, when
                      // enabled)
};

struct CollideOptions {
  double relative_tolerance = 1e-12;  // tau = relative_tolerance x scale (docs/collision.md)
  bool want_plane = true;             // find a separating plane when separate
  // Reject pairs whose bounding spheres are apart before the report's test
  // (a real-time saving; the verdict is the same). Off: the report's
  // algorithm alone, every decision by its own steps.
  bool sphere_reject = true;
  // Reject pairs whose axis-aligned bounding boxes are apart (after the
  // spheres; the same verdict, a plane normal to the axis that parts them).
  bool aabb_reject = true;
  // Frame coherence: a plane to try first (the pair's separating plane of
  // the previous frame); when it still separates the pair with more than
  // tau to spare on each side, the verdict is separate with this plane (it
  // cannot change a verdict: a pair within tau of it goes to the report's
  // test). Null: none.
  const scene_model::SeparatingPlane* hint = nullptr;
};

struct CollisionResult {
  Verdict verdict = Verdict::kInvalid;
  Decider decider = Decider::kNonFinite;
  int index = -1;
  int face = -1;
  // Separating plane (when verdict is kSeparate and want_plane), n_R from
  // A's side toward B's.
  bool plane_valid = false;
  scene_model::SeparatingPlane plane;
  // Location words: A's vertices against B's faces and B's against A's,
  // when the vertex phases did not decide (words_valid; the edge phase uses
  // them).
  std::array<LocationWord, 8> words_a{};
  std::array<LocationWord, 8> words_b{};
  bool words_valid = false;
  // Work done, for benchmarks: triple products evaluated.
  int triple_products = 0;
};

CollisionResult Collide(const Hexahedron& a, const Hexahedron& b,
                        const CollideOptions& options = {});

// The pair's tolerance tau, ft: a distance (docs/collision.md "Tolerance rule").
double ToleranceFt(const Hexahedron& a, const Hexahedron& b, double relative_tolerance = 1e-12);

// Does every vertex of A lie at or below the plane (n . p <= d + tol) and
// every vertex of B at or above it (n . p >= d - tol)?
bool PlaneSeparates(const Hexahedron& a, const Hexahedron& b, const Eigen::Vector3d& n, double d,
                    double tol);

// The gap between A (below) and B (above) along the unit normal n: min over
// B of n . p less max over A: a lower bound on the distance between the
// solids when positive (docs/collision.md "Nothing passes through").
double GapAlong(const Hexahedron& a, const Hexahedron& b, const Eigen::Vector3d& n);

// The offset d that puts the plane n . p = d midway in the gap between A
// (below) and B (above) along n: (max over A + min over B) / 2. The DCP
// sends its planes centred so that rounding to the 24-bit plane words
// (docs/performance.md, word precision) leaves them separating unless the
// gap is within a word's LSB.
double MidGapOffset(const Hexahedron& a, const Hexahedron& b, const Eigen::Vector3d& n);

// The faces (bits) of a 6-bit mask, in order: the compiled list for each
// combination of TRUE faces. kFacesOfMask[m] holds the count and the faces.
struct FaceList {
  std::uint8_t count;
  std::array<std::uint8_t, 6> faces;
};
extern const std::array<FaceList, 64> kFacesOfMask;

namespace internal {

// Step 4's last resort for a plane (docs/collision.md "The widest edge
// axis"): among the unit cross products n of an edge direction of A and
// one of B (12 x 12; a pair with |da x db| <= 1e-12 |da| |db|, near
// parallel, skipped), the widest gap from A to B along n or -n. Of equal
// gaps the first wins, in the order A's edge, B's edge, then B above A
// before A above B. gap_ft is -infinity when no axis was tried.
struct EdgeAxisPlane {
  Eigen::Vector3d n_R = Eigen::Vector3d::UnitZ();  // from A toward B, Reference frame
  double d_ft = 0.0;                               // the plane n . p = d, midway in the gap, ft
  double gap_ft = -std::numeric_limits<double>::infinity();  // the gap, ft (negative: overlap)
  int axes_computed = 0;  // of the 144, how many were computed (work done, for benchmarks)
};
// Skips each pair of edge directions whose axes are all bounded below an
// axis already computed; the same answer, bit for bit, as
// WidestEdgeAxisExhaustive (docs/collision.md "The widest edge axis").
EdgeAxisPlane WidestEdgeAxis(const Hexahedron& a, const Hexahedron& b);
// Every one of the 144 axes: the reference, for tests and the benchmark.
EdgeAxisPlane WidestEdgeAxisExhaustive(const Hexahedron& a, const Hexahedron& b);

}  // namespace internal

}  // namespace rms::dcp_model
