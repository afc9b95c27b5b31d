#include "rms/dcp_model/hexahedron.h"

#include <algorithm>
#include <cmath>

#include "simd.h"

namespace rms::dcp_model {

char FaceLetter(int f) { return static_cast<char>('a' + f); }

const char* HexProblemName(HexProblem p) {
  switch (p) {
    case HexProblem::kNone:
      return "valid";
    case HexProblem::kNonFinite:
      return "a coordinate is not finite";
    case HexProblem::kOverflow:
      return "a coordinate beyond 1e75 ft (its products would overflow)";
    case HexProblem::kTooSmall:
      return "smaller than 1e-75 ft (its products would underflow)";
    case HexProblem::kBadDimension:
      return "a length or half-width not positive";
    case HexProblem::kSkewedAxes:
      return "its axes U, V, W are not orthonormal";
    case HexProblem::kDegenerateFace:
      return "a face has no area";
    case HexProblem::kFlat:
      return "flat: thinner than the rounding tolerance at its coordinates";
    case HexProblem::kTwisted:
      return "twisted: its faces disagree on the outward side";
    case HexProblem::kNonConvex:
      return "not convex: a vertex beyond a face's plane";
  }
  return "?";
}

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

// The face masks, the fast way: all six masks at once, branch-free, four
// vertices at a time in AVX registers where the processor has them (checked
// once), else two at a time in SSE2 (every x86-64), else the plain loop. All
// three compute each projection as (nx x + ny y) + nz z in double, without
// fused multiply-adds, so they give the same bits on every machine (a
// session re-simulates identically anywhere).
namespace {

#if defined(RMS_DCP_X86)
// (Helpers, not lambdas: a lambda would not inherit the target.)
__attribute__((target("avx"))) inline __m256d ProjectAvx(const Hexahedron& h, int f, __m256d X,
                                                         __m256d Y, __m256d Z) {
  return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(h.nx[f]), X),
                                     _mm256_mul_pd(_mm256_set1_pd(h.ny[f]), Y)),
                       _mm256_mul_pd(_mm256_set1_pd(h.nz[f]), Z));
}
__attribute__((target("avx"))) inline std::uint8_t AboveAvx(__m256d s0, __m256d s1, double lim) {
  const __m256d l = _mm256_set1_pd(lim);
  return static_cast<std::uint8_t>(_mm256_movemask_pd(_mm256_cmp_pd(s0, l, _CMP_GT_OQ)) |
                                   (_mm256_movemask_pd(_mm256_cmp_pd(s1, l, _CMP_GT_OQ)) << 4));
}
__attribute__((target("avx"))) inline std::uint8_t BelowAvx(__m256d s0, __m256d s1, double lim) {
  const __m256d l = _mm256_set1_pd(lim);
  return static_cast<std::uint8_t>(_mm256_movemask_pd(_mm256_cmp_pd(s0, l, _CMP_LT_OQ)) |
                                   (_mm256_movemask_pd(_mm256_cmp_pd(s1, l, _CMP_LT_OQ)) << 4));
}

__attribute__((target("avx"))) void MasksAvx(const Hexahedron& h, const Hexahedron& o, double tau,
                                             std::array<std::uint8_t, 6>* masks) {
  const __m256d X0 = _mm256_loadu_pd(&o.x[0]), X1 = _mm256_loadu_pd(&o.x[4]);
  const __m256d Y0 = _mm256_loadu_pd(&o.y[0]), Y1 = _mm256_loadu_pd(&o.y[4]);
  const __m256d Z0 = _mm256_loadu_pd(&o.z[0]), Z1 = _mm256_loadu_pd(&o.z[4]);
  if (h.parallel_opposites) {
    // A box: faces f and f + 3 share an axis; one projection serves both
    // (beyond face f + 3: n_f . p < -d_{f+3}).
    for (int f = 0; f < 3; ++f) {
      const __m256d s0 = ProjectAvx(h, f, X0, Y0, Z0), s1 = ProjectAvx(h, f, X1, Y1, Z1);
      (*masks)[f] = AboveAvx(s0, s1, h.d[f] + tau);
      (*masks)[f + 3] = BelowAvx(s0, s1, -(h.d[f + 3] + tau));
    }
  } else {
    for (int f = 0; f < kNumFaces; ++f) {
      (*masks)[f] =
          AboveAvx(ProjectAvx(h, f, X0, Y0, Z0), ProjectAvx(h, f, X1, Y1, Z1), h.d[f] + tau);
    }
  }
}
#endif

}  // namespace

bool UseAvx(bool on) {
#if defined(RMS_DCP_X86)
  avx_enabled = on && __builtin_cpu_supports("avx");
  return avx_enabled;
#else
  (void)on;
  return false;
#endif
}

int Hexahedron::FaceMasks(const Hexahedron& o, double tau,
                          std::array<std::uint8_t, 6>* masks) const {
#if defined(RMS_DCP_X86)
  if (avx_enabled) {
    MasksAvx(*this, o, tau, masks);
    for (int f = 0; f < kNumFaces; ++f) {
      if ((*masks)[f] == 0xFF) return f;
    }
    return -1;
  }
#endif
#if defined(__SSE2__)
  __m128d X[4], Y[4], Z[4];
  for (int k = 0; k < 4; ++k) {
    X[k] = _mm_loadu_pd(&o.x[2 * k]);
    Y[k] = _mm_loadu_pd(&o.y[2 * k]);
    Z[k] = _mm_loadu_pd(&o.z[2 * k]);
  }
  auto project = [&](int f, int k) {
    return _mm_add_pd(
        _mm_add_pd(_mm_mul_pd(_mm_set1_pd(nx[f]), X[k]), _mm_mul_pd(_mm_set1_pd(ny[f]), Y[k])),
        _mm_mul_pd(_mm_set1_pd(nz[f]), Z[k]));
  };
  if (parallel_opposites) {
    for (int f = 0; f < 3; ++f) {
      const __m128d off = _mm_set1_pd(d[f] + tau), lim = _mm_set1_pd(-(d[f + 3] + tau));
      unsigned m1 = 0, m2 = 0;
      for (int k = 0; k < 4; ++k) {
        const __m128d sp = project(f, k);
        m1 |= static_cast<unsigned>(_mm_movemask_pd(_mm_cmpgt_pd(sp, off))) << (2 * k);
        m2 |= static_cast<unsigned>(_mm_movemask_pd(_mm_cmplt_pd(sp, lim))) << (2 * k);
      }
      (*masks)[f] = static_cast<std::uint8_t>(m1);
      (*masks)[f + 3] = static_cast<std::uint8_t>(m2);
    }
  } else {
    for (int f = 0; f < kNumFaces; ++f) {
      const __m128d off = _mm_set1_pd(d[f] + tau);
      unsigned m = 0;
      for (int k = 0; k < 4; ++k)
        m |= static_cast<unsigned>(_mm_movemask_pd(_mm_cmpgt_pd(project(f, k), off))) << (2 * k);
      (*masks)[f] = static_cast<std::uint8_t>(m);
    }
  }
#else
  for (int f = 0; f < kNumFaces; ++f) {
    const double a = nx[f], b = ny[f], c = nz[f], off = d[f] + tau;
    unsigned m = 0;
    for (int i = 0; i < kNumVertices; ++i)
      m |= static_cast<unsigned>((a * o.x[i] + b * o.y[i]) + c * o.z[i] > off) << i;
    (*masks)[f] = static_cast<std::uint8_t>(m);
  }
#endif
  for (int f = 0; f < kNumFaces; ++f) {
    if ((*masks)[f] == 0xFF) return f;
  }
  return -1;
}

namespace {
// Bit i of m spread to bit 8 i: a face's mask as one bit in each vertex's byte.
constexpr std::array<std::uint64_t, 256> MakeSpread() {
  std::array<std::uint64_t, 256> t{};
  for (unsigned m = 0; m < 256; ++m)
    for (int i = 0; i < 8; ++i)
      if (m & (1u << i)) t[m] |= std::uint64_t{1} << (8 * i);
  return t;
}
constexpr std::array<std::uint64_t, 256> kSpread = MakeSpread();
}  // namespace

std::array<LocationWord, 8> WordsFromMasks(const std::array<std::uint8_t, 6>& masks) {
  // The transpose, eight words at once: byte i of `all` is vertex i's word.
  std::uint64_t all = 0;
  for (int f = 0; f < kNumFaces; ++f) all |= kSpread[masks[f]] << f;
  std::array<LocationWord, 8> w{};
  for (int i = 0; i < kNumVertices; ++i) w[i] = static_cast<LocationWord>(all >> (8 * i));
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

// Scale, bounds, magnitude and the finiteness and range checks, common to
// both builders.
HexProblem Finish(Hexahedron* h) {
  double lo[3] = {h->x[0], h->y[0], h->z[0]}, hi[3] = {h->x[0], h->y[0], h->z[0]};
  // Finite: x * 0 is 0 for a finite x and NaN otherwise; one sum, no branch.
  double zero = 0.0;
  for (int i = 0; i < kNumVertices; ++i) {
    const double c[3] = {h->x[i], h->y[i], h->z[i]};
    for (int k = 0; k < 3; ++k) {
      zero += c[k] * 0.0;
      lo[k] = std::min(lo[k], c[k]);
      hi[k] = std::max(hi[k], c[k]);
    }
  }
  for (int f = 0; f < kNumFaces; ++f) zero += (h->nx[f] + h->ny[f] + h->nz[f] + h->d[f]) * 0.0;
  const bool finite = zero == 0.0;
  h->magnitude = 0.0;
  for (int k = 0; k < 3; ++k)
    h->magnitude = std::max({h->magnitude, std::abs(lo[k]), std::abs(hi[k])});
  h->scale = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                       (hi[2] - lo[2]) * (hi[2] - lo[2]));
  h->cx = 0.5 * (lo[0] + hi[0]);
  h->cy = 0.5 * (lo[1] + hi[1]);
  h->cz = 0.5 * (lo[2] + hi[2]);
  double r2 = 0.0;
  for (int i = 0; i < kNumVertices; ++i) {
    r2 =
        std::max(r2, (h->x[i] - h->cx) * (h->x[i] - h->cx) + (h->y[i] - h->cy) * (h->y[i] - h->cy) +
                         (h->z[i] - h->cz) * (h->z[i] - h->cz));
  }
  h->radius = std::sqrt(r2);
  h->hx = 0.5 * (hi[0] - lo[0]);
  h->hy = 0.5 * (hi[1] - lo[1]);
  h->hz = 0.5 * (hi[2] - lo[2]);
  if (!finite) return HexProblem::kNonFinite;
  if (!(h->magnitude <= kMaxCoordinateFt) || !std::isfinite(h->scale)) return HexProblem::kOverflow;
  if (!(h->scale >= kMinScaleFt)) return HexProblem::kTooSmall;
  return HexProblem::kNone;
}

// The rounding tolerance of the builders' checks, ft (docs/collision.md).
double ShapeTolerance(const Hexahedron& h) { return 1e-9 * h.scale + kRoundingPerFt * h.magnitude; }

void SetValidity(Hexahedron* h, HexProblem p) {
  h->problem = p;
  h->valid = p == HexProblem::kNone;
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
  h.parallel_opposites = true;  // the normals above are exact negatives
  HexProblem problem = Finish(&h);
  if (problem == HexProblem::kNone) {
    const double skew = std::max({std::abs(U.squaredNorm() - 1), std::abs(V.squaredNorm() - 1),
                                  std::abs(W.squaredNorm() - 1), std::abs(U.dot(V)),
                                  std::abs(V.dot(W)), std::abs(W.dot(U))});
    if (!(length > 0 && half_v > 0 && half_w > 0))
      problem = HexProblem::kBadDimension;
    else if (!(skew <= 1e-9))
      problem = HexProblem::kSkewedAxes;
    else if (std::min({length, 2 * half_v, 2 * half_w}) <= ShapeTolerance(h))
      problem = HexProblem::kFlat;
  }
  SetValidity(&h, problem);
  return h;
}

Hexahedron FromVertices(const std::array<Eigen::Vector3d, 8>& v) {
  Hexahedron h;
  for (int i = 0; i < kNumVertices; ++i) SetVertex(&h, i, v[i]);
  HexProblem problem = Finish(&h);
  if (problem != HexProblem::kNone) {
    SetValidity(&h, problem);
    return h;
  }
  // Faces from differences of vertices (accurate at any distance from the
  // origin), about the first vertex.
  const Eigen::Vector3d& o = v[0];
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : v) centroid += p - o;
  centroid /= 8.0;
  int inward = 0;
  double volume6 = 0.0, largest_area2 = 0.0;  // six times the volume; twice the largest face's area
  std::array<double, 6> d_o{};                // each face's offset about o
  for (int f = 0; f < kNumFaces; ++f) {
    const auto& fv = kFaceVertices[f];
    Eigen::Vector3d n = (v[fv[2]] - v[fv[0]]).cross(v[fv[3]] - v[fv[1]]);
    const double len = n.norm();
    if (!(len > 0) || !std::isfinite(len)) {
      SetValidity(&h, HexProblem::kDegenerateFace);
      return h;
    }
    n /= len;
    const Eigen::Vector3d mid =
        0.25 * ((v[fv[0]] - o) + (v[fv[1]] - o) + (v[fv[2]] - o) + (v[fv[3]] - o));
    if (n.dot(mid - centroid) < 0) {
      n = -n;
      ++inward;
    }
    // The pyramid from the centroid over the face: its height times twice
    // the face's area (a quadrilateral's area is half its diagonals' cross
    // product); the six summed are six times the volume.
    volume6 += n.dot(mid - centroid) * len;
    d_o[f] = n.dot(mid);
    largest_area2 = std::max(largest_area2, len);
    SetFace(&h, f, n, n.dot(mid) + n.dot(o));
  }
  // Every face's diagonal normal points inward for a mirrored hexahedron,
  // none for a right-handed one; a mixture is a twisted, invalid solid.
  if (inward != 0 && inward != kNumFaces) {
    SetValidity(&h, HexProblem::kTwisted);
    return h;
  }
  h.handedness = inward == kNumFaces ? -1.0 : 1.0;
  const double tol = ShapeTolerance(h);
  // Flat: the volume over the largest face's area is the solid's thickness
  // (exactly, for a box), = volume6 / (3 largest_area2).
  if (!(volume6 / (3.0 * largest_area2) > tol)) {
    SetValidity(&h, HexProblem::kFlat);
    return h;
  }
  // Convex: every vertex on the FALSE side of (or on) every face's plane,
  // within the rounding of non-planar faces and of the coordinates.
  for (int f = 0; f < kNumFaces; ++f) {
    for (int i = 0; i < kNumVertices; ++i) {
      const double beyond = h.nx[f] * (h.x[i] - o.x()) + h.ny[f] * (h.y[i] - o.y()) +
                            h.nz[f] * (h.z[i] - o.z()) - d_o[f];
      if (beyond > tol) {
        SetValidity(&h, HexProblem::kNonConvex);
        return h;
      }
    }
  }
  SetValidity(&h, HexProblem::kNone);
  return h;
}

}  // namespace rms::dcp_model
