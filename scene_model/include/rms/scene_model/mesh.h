#pragma once
// Flat-shaded triangle meshes for the ESG's static models. Each triangle has
// one colour and one outward normal (the period's look: flat shading, no
// textures). Builders take the outward direction and wind triangles to match,
// so back-face culling and lighting are right by construction.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

namespace rms::scene_model {

using Rgb = std::array<std::uint8_t, 3>;

struct Triangle {
  Eigen::Vector3f a, b, c;
  Eigen::Vector3f n;  // unit, outward: (b - a) x (c - a) direction
  Rgb rgb;
  bool decal = false;  // lies on another face of its cluster; drawn after the others
};

class Mesh {
 public:
  // Adds triangle a, b, c wound so that its normal points along `outward`.
  void AddTri(const Eigen::Vector3f& a, Eigen::Vector3f b, Eigen::Vector3f c,
              const Eigen::Vector3f& outward, const Rgb& rgb);
  // Adds the planar quad a, b, c, d (in order around it) facing `outward`.
  void AddQuad(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c,
               const Eigen::Vector3f& d, const Eigen::Vector3f& outward, const Rgb& rgb);
  // Both sides of a thin panel (two quads back to back).
  void AddPanel(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c,
                const Eigen::Vector3f& d, const Rgb& front, const Rgb& back);
  // An axis-aligned box, faces outward.
  void AddBox(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, const Rgb& rgb);
  // The inside of an axis-aligned box (faces inward), for the cargo bay; the
  // faces whose bit is set in `skip_mask` (bit 0 -x, 1 +x, 2 -y, 3 +y, 4 -z,
  // 5 +z) are left out.
  void AddBoxInterior(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi,
                      const std::array<Rgb, 6>& rgb, unsigned skip_mask);
  // A prism of `sides` sides (a cylinder's flat-shaded stand-in) from p0 to p1.
  void AddCylinder(const Eigen::Vector3f& p0, const Eigen::Vector3f& p1, float radius, int sides,
                   const Rgb& rgb, bool caps = true, float phase_rad = 0.0f);
  // A truncated cone of `sides` sides from p0 (radius r0) to p1 (radius r1).
  void AddFrustum(const Eigen::Vector3f& p0, const Eigen::Vector3f& p1, float r0, float r1,
                  int sides, const Rgb& rgb);
  // A convex polygon prism: `outline` (counter-clockwise about +axis, in the
  // plane through p0) extruded by `axis`.
  void AddExtrusion(const std::vector<Eigen::Vector3f>& outline, const Eigen::Vector3f& axis,
                    const Rgb& rgb);

  // Triangles added from now on are decals (markings on a face, drawn after
  // the faces they lie on).
  void SetDecal(bool decal) { decal_ = decal; }

  const std::vector<Triangle>& triangles() const { return tris_; }
  std::size_t size() const { return tris_.size(); }

 private:
  std::vector<Triangle> tris_;
  bool decal_ = false;
};

}  // namespace rms::scene_model
