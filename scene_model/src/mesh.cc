#include "rms/scene_model/mesh.h"

#include <Eigen/Geometry>
#include <cmath>

namespace rms::scene_model {

void Mesh::AddTri(const Eigen::Vector3f& a, Eigen::Vector3f b, Eigen::Vector3f c,
                  const Eigen::Vector3f& outward, const Rgb& rgb) {
  Eigen::Vector3f n = (b - a).cross(c - a);
  if (n.dot(outward) < 0) {
    std::swap(b, c);
    n = -n;
  }
  const float len = n.norm();
  if (len <= 0) return;  // degenerate: nothing to draw
  tris_.push_back({a, b, c, n / len, rgb, decal_});
}

void Mesh::AddQuad(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c,
                   const Eigen::Vector3f& d, const Eigen::Vector3f& outward, const Rgb& rgb) {
  AddTri(a, b, c, outward, rgb);
  AddTri(a, c, d, outward, rgb);
}

void Mesh::AddPanel(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c,
                    const Eigen::Vector3f& d, const Rgb& front, const Rgb& back) {
  const Eigen::Vector3f n = (b - a).cross(c - a);
  AddQuad(a, b, c, d, n, front);
  AddQuad(a, b, c, d, -n, back);
}

void Mesh::AddBox(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, const Rgb& rgb) {
  const auto P = [&](int i, int j, int k) {
    return Eigen::Vector3f(i ? hi.x() : lo.x(), j ? hi.y() : lo.y(), k ? hi.z() : lo.z());
  };
  AddQuad(P(0, 0, 0), P(0, 1, 0), P(0, 1, 1), P(0, 0, 1), -Eigen::Vector3f::UnitX(), rgb);
  AddQuad(P(1, 0, 0), P(1, 1, 0), P(1, 1, 1), P(1, 0, 1), Eigen::Vector3f::UnitX(), rgb);
  AddQuad(P(0, 0, 0), P(1, 0, 0), P(1, 0, 1), P(0, 0, 1), -Eigen::Vector3f::UnitY(), rgb);
  AddQuad(P(0, 1, 0), P(1, 1, 0), P(1, 1, 1), P(0, 1, 1), Eigen::Vector3f::UnitY(), rgb);
  AddQuad(P(0, 0, 0), P(1, 0, 0), P(1, 1, 0), P(0, 1, 0), -Eigen::Vector3f::UnitZ(), rgb);
  AddQuad(P(0, 0, 1), P(1, 0, 1), P(1, 1, 1), P(0, 1, 1), Eigen::Vector3f::UnitZ(), rgb);
}

void Mesh::AddBoxInterior(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi,
                          const std::array<Rgb, 6>& rgb, unsigned skip) {
  const auto P = [&](int i, int j, int k) {
    return Eigen::Vector3f(i ? hi.x() : lo.x(), j ? hi.y() : lo.y(), k ? hi.z() : lo.z());
  };
  if (!(skip & 1))
    AddQuad(P(0, 0, 0), P(0, 1, 0), P(0, 1, 1), P(0, 0, 1), Eigen::Vector3f::UnitX(), rgb[0]);
  if (!(skip & 2))
    AddQuad(P(1, 0, 0), P(1, 1, 0), P(1, 1, 1), P(1, 0, 1), -Eigen::Vector3f::UnitX(), rgb[1]);
  if (!(skip & 4))
    AddQuad(P(0, 0, 0), P(1, 0, 0), P(1, 0, 1), P(0, 0, 1), Eigen::Vector3f::UnitY(), rgb[2]);
  if (!(skip & 8))
    AddQuad(P(0, 1, 0), P(1, 1, 0), P(1, 1, 1), P(0, 1, 1), -Eigen::Vector3f::UnitY(), rgb[3]);
  if (!(skip & 16))
    AddQuad(P(0, 0, 0), P(1, 0, 0), P(1, 1, 0), P(0, 1, 0), Eigen::Vector3f::UnitZ(), rgb[4]);
  if (!(skip & 32))
    AddQuad(P(0, 0, 1), P(1, 0, 1), P(1, 1, 1), P(0, 1, 1), -Eigen::Vector3f::UnitZ(), rgb[5]);
}

void Mesh::AddCylinder(const Eigen::Vector3f& p0, const Eigen::Vector3f& p1, float radius,
                       int sides, const Rgb& rgb, bool caps, float phase) {
  const Eigen::Vector3f axis = p1 - p0;
  const Eigen::Vector3f w = axis.normalized();
  const Eigen::Vector3f helper =
      std::abs(w.x()) < 0.9f ? Eigen::Vector3f::UnitX() : Eigen::Vector3f::UnitY();
  const Eigen::Vector3f u = w.cross(helper).normalized();
  const Eigen::Vector3f v = w.cross(u);
  std::vector<Eigen::Vector3f> ring;
  for (int i = 0; i < sides; ++i) {
    const float t = phase + 2.0f * static_cast<float>(M_PI) * i / sides;
    ring.push_back(radius * (std::cos(t) * u + std::sin(t) * v));
  }
  for (int i = 0; i < sides; ++i) {
    const Eigen::Vector3f& r0 = ring[i];
    const Eigen::Vector3f& r1 = ring[(i + 1) % sides];
    AddQuad(p0 + r0, p0 + r1, p1 + r1, p1 + r0, r0 + r1, rgb);
    if (caps) {
      AddTri(p0, p0 + r0, p0 + r1, -w, rgb);
      AddTri(p1, p1 + r0, p1 + r1, w, rgb);
    }
  }
}

void Mesh::AddFrustum(const Eigen::Vector3f& p0, const Eigen::Vector3f& p1, float r0, float r1,
                      int sides, const Rgb& rgb) {
  const Eigen::Vector3f w = (p1 - p0).normalized();
  const Eigen::Vector3f helper =
      std::abs(w.x()) < 0.9f ? Eigen::Vector3f::UnitX() : Eigen::Vector3f::UnitY();
  const Eigen::Vector3f u = w.cross(helper).normalized();
  const Eigen::Vector3f v = w.cross(u);
  for (int i = 0; i < sides; ++i) {
    const float t0 = 2.0f * static_cast<float>(M_PI) * i / sides;
    const float t1 = 2.0f * static_cast<float>(M_PI) * (i + 1) / sides;
    const Eigen::Vector3f d0 = std::cos(t0) * u + std::sin(t0) * v,
                          d1 = std::cos(t1) * u + std::sin(t1) * v;
    const Eigen::Vector3f out = (d0 + d1) * (r0 + r1) * 0.5f + (r0 - r1) * w;
    AddQuad(p0 + r0 * d0, p0 + r0 * d1, p1 + r1 * d1, p1 + r1 * d0, out, rgb);
    AddTri(p0, p0 + r0 * d0, p0 + r0 * d1, -w, rgb);
    AddTri(p1, p1 + r1 * d0, p1 + r1 * d1, w, rgb);
  }
}

void Mesh::AddExtrusion(const std::vector<Eigen::Vector3f>& outline, const Eigen::Vector3f& axis,
                        const Rgb& rgb) {
  const std::size_t n = outline.size();
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();
  for (const auto& p : outline) centre += p;
  centre /= static_cast<float>(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3f& a = outline[i];
    const Eigen::Vector3f& b = outline[(i + 1) % n];
    const Eigen::Vector3f out = (a + b) * 0.5f - centre;
    AddQuad(a, b, b + axis, a + axis, out - out.dot(axis.normalized()) * axis.normalized(), rgb);
    AddTri(centre, a, b, -axis, rgb);
    AddTri(centre + axis, a + axis, b + axis, axis, rgb);
  }
}

}  // namespace rms::scene_model
