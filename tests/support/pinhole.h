#pragma once
// The pinhole of docs/esg.md "Projection", written independently of the
// renderer's GL matrices: eye frame X forward, Y right, Z down; vertical field
// of view; square pixels; pixel (0, 0) at the top left.
#include <Eigen/Core>
#include <cmath>

#include "rms/wire/word_blocks.h"

namespace rms::testing {

// The pixel of point p_R for the frame's view in a w x h image; false when the
// point is behind the eye (or within 1 ft of it) or outside the image.
inline bool Project(const wire::EsgFrameData& f, const Eigen::Vector3d& p_R, int w, int h, int* px,
                    int* py) {
  const Eigen::Vector3d e = f.R_RE.transpose() * (p_R - f.p_RoEye_R_ft);
  if (e.x() < 1.0) return false;
  const double focal = 0.5 * h / std::tan(0.5 * f.fov_deg * M_PI / 180.0);
  *px = static_cast<int>(std::floor(0.5 * w + focal * e.y() / e.x()));
  *py = static_cast<int>(std::floor(0.5 * h + focal * e.z() / e.x()));
  return *px >= 0 && *px < w && *py >= 0 && *py < h;
}

}  // namespace rms::testing
