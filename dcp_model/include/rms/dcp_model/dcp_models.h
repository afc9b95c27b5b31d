#pragma once
// The models of the DYNAMIC COLLISION PROGRAM, generated every frame in
// Reference coordinates the report's way (Section IV.A.2): the three
// System-Two unit vectors (or the payload's, the bay's, the CAE's) scaled by
// the dimensions of the configuration. docs/collision.md has the figures.
#include <Eigen/Geometry>
#include <array>
#include <string>

#include "rms/base/config.h"
#include "rms/dcp_model/hexahedron.h"

namespace rms::dcp_model {

// EFF HEX 1 (palm), EFF HEX 2 (fixed finger), EFF HEX 3 (movable finger).
// System Two: X2 = UX2 along the approach (a -> d: face d is the palm's
// "bottom"), Y2 = UY2 (b -> e), Z2 = UZ2 (c -> f). Face b of EFF HEX 2 and
// face e of EFF HEX 3 are the fingers' interior faces, `finger_gap_ft` apart.
struct EndEffectorModel {
  std::array<Hexahedron, 3> hex;
};
EndEffectorModel MakeEndEffector(const EndEffectorConfig& ee, const Eigen::Isometry3d& X_RS2,
                                 double finger_gap_ft);

// The bar receptacle (BAR, RECPT) on the payload: u = x_P along the bar
// (faces a and d are its ends), v = -y_P, w = -z_P (face c its top).
Hexahedron MakeBar(const PayloadConfig& p, const Eigen::Isometry3d& X_RP);

// The BAR's two posts in Reference coordinates: rms::BarPosts_P (the boxes
// the scene draws), x_P, y_P, z_P as u, v, w. Returns how many (0 or 2).
int MakeBarPosts(const PayloadConfig& p, const Eigen::Isometry3d& X_RP,
                 std::array<Hexahedron, 2>* posts);

// The payload model (the report's Figure 8, reconstructed; docs/collision.md
// "The payload"): the body is the drawn 16-sided prism round the cylinder
// (a flat on top, r cos(pi/16) above the axis, as the scene draws it), so
// contact shows where it is drawn. Its 32 vertices take the place of the
// report's V11-V18; Mode 1 tests it as seven hexahedra, horizontal strips of
// the 16-gon (each a trapezoid prism). V21-V24 the probe's root, V31-V36 the
// probe's tip.
inline constexpr int kBodySides = 16;
inline constexpr int kBodyStrips = 7;
inline constexpr int kBodyVertices = 2 * kBodySides;
inline constexpr int kProbeFirst = kBodyVertices;       // V21
inline constexpr int kProbeTipFirst = kProbeFirst + 4;  // V31
inline constexpr int kPayloadVertices = kProbeTipFirst + 6;
struct PayloadModel {
  // Strip j between the 16-gon's vertex levels j and j + 1 from the top:
  // u = y_P (face d at the probe end), v = x_P, w = -z_P (c the strip's top).
  std::array<Hexahedron, kBodyStrips> body;
  // The strips were made (MakePayload with_body). Modes 2 and 3 test only
  // the vertices and usually leave them out (HeldPayload).
  bool has_body = true;
  std::array<Eigen::Vector3d, kPayloadVertices>
      v;                             // body (aft ring, then fore ring), V21..V24, V31..V36
  Eigen::Vector3d probe_tip_centre;  // centre of V31-V36
  Eigen::Vector3d probe_axis;        // y_P, the probe's y-axis
};
// What of the payload's model depends on its configuration alone (its
// coordinates in its own frame P, ft; the angles' sines and cosines), made
// once: a frame then only places it.
struct PayloadShape {
  double half_len = 0, probe_length = 0, probe_radius = 0;
  std::array<double, 9> level_z{}, level_hx{};        // the 16-gon's levels from the top
  std::array<double, kBodySides> ring_x{}, ring_z{};  // each ring's vertices about y_P
  std::array<double, 6> tip_cos{}, tip_sin{};         // V31..V36 round the probe's tip
};
PayloadShape MakePayloadShape(const PayloadConfig& p);
// The payload placed at X_RP (the same numbers whichever form is called);
// without its strips when !with_body.
PayloadModel MakePayload(const PayloadShape& s, const Eigen::Isometry3d& X_RP,
                         bool with_body = true);
PayloadModel MakePayload(const PayloadConfig& p, const Eigen::Isometry3d& X_RP);
// The payload vertex names: "B1" .. "B32" (the body), "V21" .. "V36".
std::string PayloadVertexName(int i);

// The cargo bay (Figure 8): u = X_R (a forward bulkhead, d aft bulkhead),
// v = -Y_R (b starboard wall, e port wall), w = -Z_R (c the top, the bay's
// opening; f the bottom).
Hexahedron MakeCargoBay(const ShuttleConfig& s);

// The CAE's front half (Figure 9): the octahedron (a hexagonal prism: six
// sides and two ends) cut through its axis parallel to the port's face. u =
// z_C (a, d the ends), v = x_C (b, e the slanted sides), w = y_C (c the face
// with the docking port, f the cut). Face c's neighbours a, b, d, e bound
// the docking envelope.
Hexahedron MakeCaeFrontHalf(const CaeConfig& c);

}  // namespace rms::dcp_model
