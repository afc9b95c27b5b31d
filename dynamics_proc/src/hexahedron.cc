#include "hexahedron.h"

#include <algorithm>
#include <cmath>

namespace rms::dcp {

char FaceLetter(int f) { return static_cast<char>('a' + f); }

LocationWord Hexahedron::Word(double px, double py, double pz, double tau) const {
  LocationWord w = 0;
  for (int f = 0; f < kNumFaces; ++f) {
    if (Beyond(f, px, py, pz) > tau) w |= FaceBit(f);
  }
  return w;
}

std::array<LocationWord, 8> Hexahedron::Words(const Hexahedron& o, double tau) const {
  std::array<LocationWord, 8> w{};
  for (int f = 0; f < kNumFaces; ++f) {
    const double a = nx[f], b = ny[f], c = nz[f], off = d[f] + tau;
    for (int i = 0; i < kNumVertices; ++i) {
      const double s = a * o.x[i] + b * o.y[i] + c * o.z[i];
      w[i] |= static_cast<LocationWord>((s > off) << f);
    }
  }
  return w;
}

namespace {

void SetVertex(Hexahedron* h, int i, const Eigen::Vector3d& p) {
  h->x[i] = p.x();
  h->y[i] = p.y();
  h->z[i] = p.z();
}

void SetFace(Hexahedron* h, int f, const Eigen::Vector3d& n, double d) {
  h->nx[f] = n.x();
  h->ny[f] = n.y();
  h->nz[f] = n.z();
  h->d[f] = d;
}

// Edge lengths, scale and the finiteness check, common to both builders.
bool Finish(Hexahedron* h) {
  double lo[3] = {h->x[0], h->y[0], h->z[0]}, hi[3] = {h->x[0], h->y[0], h->z[0]};
  bool finite = true;
  for (int i = 0; i < kNumVertices; ++i) {
    const double c[3] = {h->x[i], h->y[i], h->z[i]};
    for (int k = 0; k < 3; ++k) {
      finite = finite && std::isfinite(c[k]);
      lo[k] = std::min(lo[k], c[k]);
      hi[k] = std::max(hi[k], c[k]);
    }
  }
  for (int f = 0; f < kNumFaces; ++f) {
    finite = finite && std::isfinite(h->nx[f]) && std::isfinite(h->ny[f]) &&
             std::isfinite(h->nz[f]) && std::isfinite(h->d[f]);
    for (int j = 0; j < 4; ++j) {
      const int a = kFaceVertices[f][j], b = kFaceVertices[f][(j + 1) % 4];
      h->edge_len[f][j] = (h->vertex(b) - h->vertex(a)).norm();
    }
  }
  h->scale = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                       (hi[2] - lo[2]) * (hi[2] - lo[2]));
  return finite && std::isfinite(h->scale) && h->scale > 0.0;
}

}  // namespace

Hexahedron MakeBox(const Eigen::Vector3d& p_A, const Eigen::Vector3d& U, const Eigen::Vector3d& V,
                   const Eigen::Vector3d& W, double length, double half_v, double half_w) {
  Hexahedron h;
  // Section IV.A.2: only the three unit vectors are transformed; the two
  // symmetric combinations serve all eight vertices.
  const Eigen::Vector3d p = half_v * V + half_w * W;
  const Eigen::Vector3d q = half_v * V - half_w * W;
  const Eigen::Vector3d l = length * U;
  SetVertex(&h, 0, p_A - p);      // v1 = A - W UY2 - H UZ2
  SetVertex(&h, 1, p_A - q);      // v2 = A - W UY2 + H UZ2
  SetVertex(&h, 3, p_A + p);      // v4 = A + W UY2 + H UZ2
  SetVertex(&h, 4, p_A + q);      // v5 = A + W UY2 - H UZ2
  SetVertex(&h, 2, p_A - p + l);  // v3 = v1 + L UX2
  SetVertex(&h, 5, p_A - q + l);  // v6
  SetVertex(&h, 6, p_A + p + l);  // v7
  SetVertex(&h, 7, p_A + q + l);  // v8
  const double ua = U.dot(p_A), va = V.dot(p_A), wa = W.dot(p_A);
  SetFace(&h, kFaceA, -U, -ua);
  SetFace(&h, kFaceD, U, ua + length);
  SetFace(&h, kFaceB, -V, -va + half_v);
  SetFace(&h, kFaceE, V, va + half_v);
  SetFace(&h, kFaceC, -W, -wa + half_w);
  SetFace(&h, kFaceF, W, wa + half_w);
  h.handedness = U.dot(V.cross(W)) >= 0 ? 1.0 : -1.0;
  h.valid = Finish(&h) && length > 0 && half_v > 0 && half_w > 0;
  return h;
}

Hexahedron FromVertices(const std::array<Eigen::Vector3d, 8>& v) {
  Hexahedron h;
  for (int i = 0; i < kNumVertices; ++i) SetVertex(&h, i, v[i]);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : v) centroid += p;
  centroid /= 8.0;
  int inward = 0;
  bool ok = true;
  for (int f = 0; f < kNumFaces; ++f) {
    const auto& fv = kFaceVertices[f];
    Eigen::Vector3d n = (v[fv[2]] - v[fv[0]]).cross(v[fv[3]] - v[fv[1]]);
    const double len = n.norm();
    if (!(len > 0) || !std::isfinite(len)) {
      ok = false;
      n = Eigen::Vector3d::UnitZ();
    } else {
      n /= len;
    }
    const Eigen::Vector3d mid = 0.25 * (v[fv[0]] + v[fv[1]] + v[fv[2]] + v[fv[3]]);
    if (n.dot(mid - centroid) < 0) {
      n = -n;
      ++inward;
    }
    SetFace(&h, f, n, n.dot(mid));
  }
  // Every face's diagonal normal points inward for a mirrored hexahedron,
  // none for a right-handed one; a mixture is a twisted, invalid solid.
  if (inward != 0 && inward != kNumFaces) ok = false;
  h.handedness = inward == kNumFaces ? -1.0 : 1.0;
  ok = Finish(&h) && ok;
  // Convex: every vertex on the FALSE side of (or on) every face's plane,
  // within the rounding of non-planar faces.
  if (ok) {
    const double tol = 1e-9 * h.scale;
    for (int f = 0; f < kNumFaces && ok; ++f) {
      for (int i = 0; i < kNumVertices; ++i) {
        if (h.Beyond(f, h.x[i], h.y[i], h.z[i]) > tol) {
          ok = false;
          break;
        }
      }
    }
  }
  h.valid = ok;
  return h;
}

}  // namespace rms::dcp
