#pragma once
// The collision peers the DCP's algorithm is measured against (docs/
// performance.md), each given the pair in its own natural form, prepared
// before timing:
//  - a 15-axis separating-axis test in double (boxes): the floor;
//  - ODE's dBoxTouchesBox (boxes);
//  - FCL's collide() on boxes (it computes a contact: more work than a yes/no);
//  - libccd's MPR (boxes and general hexahedra, through support functions);
//  - FCL's collide() on convex polyhedra (general hexahedra, GJK/EPA inside).
#include <Eigen/Geometry>
#include <array>
#include <memory>
#include <vector>

namespace rms::bench {

struct BoxShape {
  Eigen::Vector3d centre;
  Eigen::Matrix3d R;     // columns: unit axes
  Eigen::Vector3d half;  // half extents along them
};

// The 15-axis separating-axis test in double: true when the closed boxes
// intersect (touching counts), as the DCP's verdict.
bool SatBoxesIntersect(const BoxShape& a, const BoxShape& b);

// ODE: dBoxTouchesBox.
void InitOde();
bool OdeBoxesTouch(const BoxShape& a, const BoxShape& b);

// libccd MPR on boxes and on hexahedra given by their eight vertices.
bool CcdMprBoxes(const BoxShape& a, const BoxShape& b);
bool CcdMprHulls(const std::array<Eigen::Vector3d, 8>& a, const std::array<Eigen::Vector3d, 8>& b);

// FCL: objects built once, collide() timed.
class FclPair {
 public:
  static std::unique_ptr<FclPair> Boxes(const BoxShape& a, const BoxShape& b);
  // General hexahedra as fcl::Convex (the standard vertex numbering's faces).
  static std::unique_ptr<FclPair> Hulls(const std::array<Eigen::Vector3d, 8>& a,
                                        const std::array<Eigen::Vector3d, 8>& b);
  ~FclPair();
  bool Collide() const;

 private:
  FclPair();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rms::bench
