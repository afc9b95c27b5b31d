// A program that links rms::dcp_model and nothing else of the product
// (docs/architecture.md "Libraries": the model links without LCM). It
// tests two pairs of hexahedra with the report's algorithm and exits 1 if
// a verdict is wrong; ctest also reads its dynamic section for LCM
// (tests/unit/CMakeLists.txt, unit.dcp_model_links_no_lcm).
#include <Eigen/Core>
#include <cstdio>
#include <string>

#include "rms/dcp_model/collision.h"
#include "rms/dcp_model/hexahedron.h"

int main() {
  using rms::dcp_model::Collide;
  using rms::dcp_model::MakeBox;
  using rms::dcp_model::Verdict;
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY(),
                        z = Eigen::Vector3d::UnitZ();
  // A 2 ft box along x from the origin; one overlapping it, one 1 ft past its end.
  const auto a = MakeBox(Eigen::Vector3d::Zero(), x, y, z, 2.0, 0.5, 0.5);
  const auto overlapping = MakeBox(Eigen::Vector3d(1.5, 0.2, 0.0), x, y, z, 2.0, 0.5, 0.5);
  const auto apart = MakeBox(Eigen::Vector3d(3.0, 0.0, 0.0), x, y, z, 2.0, 0.5, 0.5);
  const bool hit = Collide(a, overlapping).verdict == Verdict::kCollide;
  const auto miss = Collide(a, apart);
  const bool clear = miss.verdict == Verdict::kSeparate && miss.plane_valid;
  std::printf("overlapping: %s; 1 ft apart: %s%s\n", hit ? "collide" : "NOT collide",
              clear ? "separate, with a plane at d = " : "NOT separate with a plane",
              clear ? std::to_string(miss.plane.d_ft).c_str() : "");
  return hit && clear ? 0 : 1;
}
