#pragma once
// The hexahedron of the DYNAMIC COLLISION PROGRAM in the report's standard
// notation (Section IV.A.1, Figure 2, reconstructed in docs/collision.md).
//
// Faces a-f; opposite faces are three letters apart: (a, d), (b, e), (c, f).
// Vertex v1..v8 (index 0..7 here) is where three faces meet:
//   v1 a b c   v2 a b f   v3 d b c   v4 a e f
//   v5 a e c   v6 d b f   v7 d e f   v8 d e c
// For EFF HEX 1 this is the report's numbering: v1 = A - W UY2 - H UZ2,
// v2 = A - W UY2 + H UZ2, v3 = v1 + L UX2, v4 = A + W UY2 + H UZ2.
//
// A point's location word has bit f set when the point is on the TRUE side of
// face f: outside, beyond the face's plane by more than the tolerance. A point
// on a face's plane, or within the tolerance of it, is on the FALSE side
// (touching counts as collision).
//
// Storage is structure-of-arrays so the per-face loops over eight vertices
// vectorise, and small (the hot data in seven cache lines).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>

namespace rms::dcp_model {

enum Face : int { kFaceA = 0, kFaceB, kFaceC, kFaceD, kFaceE, kFaceF };
inline constexpr int kNumFaces = 6;
inline constexpr int kNumVertices = 8;
inline constexpr int kNumEdges = 12;

// Why a hexahedron is refused (docs/collision.md "Tolerance rule"): a test on
// it is an error, never a verdict. kNone: valid.
enum class HexProblem : std::uint8_t {
  kNone,
  kNonFinite,       // a coordinate is NaN or infinite
  kOverflow,        // a coordinate beyond kMaxCoordinateFt: its products would overflow
  kTooSmall,        // smaller than kMinScaleFt: its products would underflow
  kBadDimension,    // MakeBox: a length or half-width not positive
  kSkewedAxes,      // MakeBox: U, V, W not orthonormal (to 1e-9)
  kDegenerateFace,  // a face with no area (its diagonals parallel)
  kFlat,            // thinner than the rounding tolerance at its coordinates
  kTwisted,         // the faces disagree on which side is outward
  kNonConvex,       // a vertex beyond a face's plane by more than the rounding tolerance
};
const char* HexProblemName(HexProblem p);
// Face normals come from cross products of edges (fourth powers of length
// in their norms): beyond these the products would overflow or underflow.
inline constexpr double kMaxCoordinateFt = 1e75;
inline constexpr double kMinScaleFt = 1e-75;
// The rounding tolerance of a solid at coordinates of magnitude M ft is
// kRoundingPerFt x M: what double rounding of the vertices, the face planes
// and one projection can do there (32 units of 2^-52; docs/collision.md).
inline constexpr double kRoundingPerFt = 32.0 * 2.220446049250313e-16;

// Six bits, bit f for face f (bit 0 = a ... bit 5 = f).
using LocationWord = std::uint8_t;
// The eight location words from six face masks (bit i of masks[f]: vertex i
// beyond face f): the transpose.
std::array<LocationWord, 8> WordsFromMasks(const std::array<std::uint8_t, 6>& masks);
inline constexpr LocationWord FaceBit(int f) { return static_cast<LocationWord>(1u << f); }
inline constexpr LocationWord kAllFaces = 0x3F;
char FaceLetter(int f);
inline constexpr int OppositeFace(int f) { return (f + 3) % 6; }

// The three faces meeting at each vertex.
inline constexpr std::array<std::array<int, 3>, 8> kVertexFaces = {{
    {kFaceA, kFaceB, kFaceC},
    {kFaceA, kFaceB, kFaceF},
    {kFaceD, kFaceB, kFaceC},
    {kFaceA, kFaceE, kFaceF},
    {kFaceA, kFaceE, kFaceC},
    {kFaceD, kFaceB, kFaceF},
    {kFaceD, kFaceE, kFaceF},
    {kFaceD, kFaceE, kFaceC},
}};

// Each face's four vertices in order round it: counter-clockwise seen from
// the TRUE side for a right-handed hexahedron (docs/collision.md).
inline constexpr std::array<std::array<int, 4>, 6> kFaceVertices = {{
    {0, 1, 3, 4},  // a: v1 v2 v4 v5
    {0, 2, 5, 1},  // b: v1 v3 v6 v2
    {0, 4, 7, 2},  // c: v1 v5 v8 v3
    {2, 7, 6, 5},  // d: v3 v8 v7 v6
    {4, 3, 6, 7},  // e: v5 v4 v7 v8
    {1, 5, 6, 3},  // f: v2 v6 v7 v4
}};

// The twelve edges, each the meeting of two faces.
inline constexpr std::array<std::array<int, 2>, 12> kEdges = {{
    {0, 1},
    {4, 3},
    {0, 4},
    {1, 3},  // a-b, a-e, a-c, a-f
    {2, 5},
    {7, 6},
    {2, 7},
    {5, 6},  // d-b, d-e, d-c, d-f
    {0, 2},
    {1, 5},
    {4, 7},
    {3, 6},  // b-c, b-f, e-c, e-f
}};

struct Hexahedron {
  // Vertices v1..v8, Reference coordinates, ft.
  std::array<double, 8> x{}, y{}, z{};
  // Faces a..f: outward unit normal and offset (n . p = d on the face).
  std::array<double, 6> nx{}, ny{}, nz{}, d{};
  // The bounding box's diagonal, ft: the hexahedron's scale for tolerances.
  double scale = 0.0;
  // The largest absolute coordinate of a vertex, ft: the magnitude at which
  // its numbers are rounded (tolerances, docs/collision.md).
  double magnitude = 0.0;
  // A bounding sphere (centre of the bounding box, radius to the farthest
  // vertex), ft: for rejecting pairs far apart before the report's test.
  double cx = 0.0, cy = 0.0, cz = 0.0, radius = 0.0;
  // The axis-aligned bounding box's half extents about (cx, cy, cz), ft.
  double hx = 0.0, hy = 0.0, hz = 0.0;
  // +1 when kFaceVertices runs counter-clockwise seen from outside, -1 when
  // the hexahedron is mirrored (left-handed axes).
  double handedness = 1.0;
  // Opposite faces parallel (a box: n_d = -n_a, n_e = -n_b, n_f = -n_c
  // exactly): one dot product a vertex serves both faces of a pair.
  bool parallel_opposites = false;
  // Every number above finite, the solid well-formed. A collision test on an
  // invalid hexahedron is an error, never a verdict; `problem` says why.
  bool valid = false;
  HexProblem problem = HexProblem::kNonFinite;

  Eigen::Vector3d vertex(int i) const { return {x[i], y[i], z[i]}; }
  Eigen::Vector3d normal(int f) const { return {nx[f], ny[f], nz[f]}; }
  // Signed distance of p beyond face f's plane (positive on the TRUE side).
  double Beyond(int f, double px, double py, double pz) const {
    return nx[f] * px + ny[f] * py + nz[f] * pz - d[f];
  }
  // The location word of point p: bit f set when p is beyond face f by more than tau.
  LocationWord Word(double px, double py, double pz, double tau) const;
  LocationWord Word(const Eigen::Vector3d& p, double tau) const {
    return Word(p.x(), p.y(), p.z(), tau);
  }
  // The location words of all eight vertices of `other` against this one's faces.
  std::array<LocationWord, 8> Words(const Hexahedron& other, double tau) const;
  // The same information face by face, the fast way: masks[f] has bit i set
  // when `other`'s vertex i is on face f's TRUE side. Returns the lowest face
  // with all eight vertices beyond it (a separating face), or -1.
  int FaceMasks(const Hexahedron& other, double tau, std::array<std::uint8_t, 6>* masks) const;
};

// The AVX paths (FaceMasks, the edge test's triple products) run where the
// processor has them and give the same bits as the portable scalar code.
// UseAvx(false) forces the scalar code, for a test that checks the two
// agree; UseAvx(true) restores AVX if the processor has it. Returns whether
// AVX is now used. Not to be called while another thread tests pairs.
bool UseAvx(bool on);

// The report's way (Section IV.A.2): from point A at the centre of face a and
// the Reference coordinates of three unit vectors U (a to d), V (b to e) and
// W (c to f) -- for EFF HEX 1 these are UX2, UY2, UZ2 -- scaled by the length
// L along U and the half-widths hv along V and hw along W. The symmetry is
// used: W hv V + hw W and hv V - hw W are formed once and added or subtracted.
// Face normals are +-U, +-V, +-W directly. U, V, W must be orthonormal.
Hexahedron MakeBox(const Eigen::Vector3d& p_A, const Eigen::Vector3d& U, const Eigen::Vector3d& V,
                   const Eigen::Vector3d& W, double length, double half_v, double half_w);

// A general convex hexahedron from its eight vertices in the standard
// numbering (frusta, skewed boxes, the CAE's front half). Each face's normal
// comes from its diagonals; the result is invalid (valid == false, problem
// says why) when a coordinate is not finite or too large, a face is
// degenerate, the solid is flat, twisted or not convex. Flatness and
// convexity are judged against the rounding tolerance at the solid's
// coordinates (1e-9 x scale + kRoundingPerFt x magnitude), so a small solid
// far from the origin is answered like the same solid at the origin.
Hexahedron FromVertices(const std::array<Eigen::Vector3d, 8>& v);

}  // namespace rms::dcp_model
