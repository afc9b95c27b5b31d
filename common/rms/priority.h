#pragma once
// Visual priority by separating planes, as General Electric's ESG did it
// after Schumacker et al. (1969); docs/scene.md "Visual priority" is the
// design, this implements it.
//
// Every pair of the scene's 34 convex clusters has a separating plane. Each
// frame the Visual Scene Program (scene_proc) sets one bit a plane: 1 when the
// viewpoint is on the side of the pair's first cluster (the lower id), which
// can then hide the second but not be hidden by it. The ESG turns the bits
// into the order it draws clusters in, farther before nearer, with no depth
// buffer. The planes of the three pairs EFF HEX 1, 2, 3 / BAR are the DCP's
// dynamic separating planes (report IV.A.1); the others are fixed (pairs of
// fixed or rigidly joined clusters) or found by scene_proc every frame
// (pairs that move relative to each other).
#include <array>
#include <bitset>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "rms/control_word.h"
#include "rms/counters.h"
#include "rms/scene_model.h"
#include "rms/word_blocks.h"

namespace rms {

inline constexpr int kNumPairs = kNumClusters * (kNumClusters - 1) / 2;  // 561
static_assert(kNumPairs == esg_words::kScenePairs && kNumClusters <= 64);
// Index of the pair (a, b), a < b, in lexicographic order.
constexpr int PairIndex(int a, int b) { return a * (2 * kNumClusters - a - 1) / 2 + (b - a - 1); }
std::pair<int, int> PairOf(int index);

// The three pairs whose planes the DCP computes: control word bits 14-16.
inline constexpr std::array<std::pair<int, int>, 3> kDcpPairs = {
    {{kEffHex1, kBar}, {kEffHex2, kBar}, {kEffHex3, kBar}}};

// bit[pair] = 1: the viewpoint is on the pair's first cluster's side.
using PriorityBits = std::bitset<kNumPairs>;

// The bits on the wire (docs/protocol.md): the DCP pairs in the control
// word's PRIORITY_DYNAMIC bits, then the other 558 pairs in pair order: the
// first 7 in PRIORITY_FIXED, the rest in the ESG frame's priority words,
// bit 0 of word 0 first, 24 to a word.
void PackPriority(const PriorityBits& bits, ControlWord* cw,
                  std::array<std::int32_t, esg_words::kPriorityCount>* words);
PriorityBits UnpackPriority(const ControlWord& cw, std::span<const std::int32_t> priority_words);
// Where a pair's bit travels, for the priority table: "control word bit 14",
// "ESG word 41 bit 0" (ESG frame word numbering, docs/protocol.md).
std::string PriorityBitPlace(int pair);

// How a pair's plane is set: the priority table of docs/scene.md.
enum class PlaneSource : std::uint8_t {
  kFixed,    // both clusters fixed (orbiter, CAE): computed once
  kRigid,    // rigidly joined (the payload's parts; wrist, palm, fixed finger; elbow, lower boom)
  kDcp,      // the DCP's dynamic plane (falls back to kDynamic when the DCP has none)
  kDynamic,  // found every frame by scene_proc, last frame's plane tried first
};
const char* PlaneSourceName(PlaneSource s);

struct Plane {
  Eigen::Vector3d n = Eigen::Vector3d::UnitZ();  // unit, from the first cluster toward the second
  double d = 0.0;                                // n . p = d on the plane
};

// A cluster's separating-plane data, posed in R.
struct PosedHull {
  std::vector<Eigen::Vector3d> points, normals, edges;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  double scale = 0.0;
};
PosedHull PoseHull(const Cluster& c, const Eigen::Affine3d& X_RC);

// A plane with A at or below it and B at or above it (touching allowed
// within eps), or nothing when they interpenetrate. `hint` (last frame's
// plane) is tried first. Candidate axes: the hint, the centroids' difference,
// the face normals (and a flat cluster's in-plane edge normals), then the
// cross products of the edge directions.
std::optional<Plane> FindSeparatingPlane(const PosedHull& a, const PosedHull& b, double eps,
                                         const Plane* hint, int* axes_tried = nullptr);

// The Visual Scene Program's side: the bits for a frame.
class PriorityPlanner {
 public:
  explicit PriorityPlanner(const SceneModel& model);
  // dcp_planes / dcp_valid: the DCP's three planes (valid bits 0-2).
  // Counters: "priority.dynamic_searches" (planes searched afresh),
  // "priority.unresolved" (pairs no plane separates: decided by distance).
  PriorityBits Compute(const ClusterPoses& poses, const Eigen::Vector3d& p_RoEye_R,
                       const std::array<SeparatingPlane, 3>& dcp_planes, std::uint32_t dcp_valid,
                       Counters* counters);
  PlaneSource source(int pair) const { return source_[pair]; }
  // A fixed or rigid pair's plane in its first cluster's frame.
  const Plane& fixed_plane(int pair) const { return local_[pair]; }

 private:
  const SceneModel& model_;
  std::array<PlaneSource, kNumPairs> source_{};
  std::array<Plane, kNumPairs> local_{};       // kFixed / kRigid: in the first cluster's frame
  std::array<Plane, kNumPairs> last_{};        // kDynamic: last frame's plane, in R
  std::array<bool, kNumPairs> have_last_{};
};

// The ESG's side: the clusters to draw, back to front. A pair's bit orders
// its clusters only when their silhouettes overlap; a cycle (which a
// well-formed scene does not have) is broken at the cluster with the fewest
// clusters still to be drawn behind it, and counted.
struct ScreenBox {
  bool visible = false;  // anything of it inside the view volume
  bool everywhere = false;  // it reaches behind the eye: it may cover any part of the screen
  float x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // its screen rectangle, normalised device coordinates
  // Its silhouette: the convex hull of its projected points, counter-clockwise.
  std::vector<Eigen::Vector2f> outline;
};
// The convex hull of 2D points (Andrew's monotone chain), counter-clockwise.
std::vector<Eigen::Vector2f> ConvexHull2d(std::vector<Eigen::Vector2f> points);
// Do two silhouettes overlap by more than `tol` (a separating-axis test on
// their outlines' edge normals)?
bool OutlinesOverlap(const ScreenBox& a, const ScreenBox& b, float tol);
// overlap_tol: how far (NDC) silhouettes must overlap to be ordered.
std::vector<int> DrawOrder(const PriorityBits& bits, const std::array<ScreenBox, kNumClusters>& boxes,
                           int* cycles_broken, float overlap_tol = 1e-3f);

}  // namespace rms
