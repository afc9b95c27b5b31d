#include "peers.h"

#include <ccd/ccd.h>
#include <ccd/vec3.h>
#include <cmath>
#include <fcl/fcl.h>
#include <ode/ode.h>

namespace rms::bench {

bool SatBoxesIntersect(const BoxShape& a, const BoxShape& b) {
  // Gottschalk's form: B's axes in A's frame, the 15 axes from A's three,
  // B's three and their nine cross products; |R| + eps guards parallel edges.
  const Eigen::Matrix3d R = a.R.transpose() * b.R;
  const Eigen::Vector3d t = a.R.transpose() * (b.centre - a.centre);
  Eigen::Matrix3d AbsR;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) AbsR(i, j) = std::fabs(R(i, j)) + 1e-12;
  const Eigen::Vector3d& ea = a.half;
  const Eigen::Vector3d& eb = b.half;
  for (int i = 0; i < 3; ++i) {
    if (std::fabs(t[i]) > ea[i] + eb.dot(AbsR.row(i))) return false;
  }
  for (int j = 0; j < 3; ++j) {
    if (std::fabs(t.dot(R.col(j))) > ea.dot(AbsR.col(j)) + eb[j]) return false;
  }
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      const double ra = ea[i1] * AbsR(i2, j) + ea[i2] * AbsR(i1, j);
      const double rb = eb[j1] * AbsR(i, j2) + eb[j2] * AbsR(i, j1);
      if (std::fabs(t[i2] * R(i1, j) - t[i1] * R(i2, j)) > ra + rb) return false;
    }
  }
  return true;
}

void InitOde() { dInitODE2(0); }

namespace {
void ToOde(const BoxShape& s, dVector3 p, dMatrix3 R, dVector3 side) {
  for (int i = 0; i < 3; ++i) {
    p[i] = s.centre[i];
    side[i] = 2 * s.half[i];
    for (int j = 0; j < 3; ++j) R[4 * i + j] = s.R(i, j);
    R[4 * i + 3] = 0;
  }
  p[3] = side[3] = 0;
}
}  // namespace

bool OdeBoxesTouch(const BoxShape& a, const BoxShape& b) {
  dVector3 pa, pb, sa, sb;
  dMatrix3 Ra, Rb;
  ToOde(a, pa, Ra, sa);
  ToOde(b, pb, Rb, sb);
  return dBoxTouchesBox(pa, Ra, sa, pb, Rb, sb) != 0;
}

namespace {
void BoxSupport(const void* obj, const ccd_vec3_t* dir, ccd_vec3_t* out) {
  const auto* s = static_cast<const BoxShape*>(obj);
  const Eigen::Vector3d d(dir->v[0], dir->v[1], dir->v[2]);
  Eigen::Vector3d p = s->centre;
  for (int k = 0; k < 3; ++k)
    p += (s->R.col(k).dot(d) >= 0 ? 1.0 : -1.0) * s->half[k] * s->R.col(k);
  ccdVec3Set(out, p.x(), p.y(), p.z());
}
void BoxCenter(const void* obj, ccd_vec3_t* c) {
  const auto* s = static_cast<const BoxShape*>(obj);
  ccdVec3Set(c, s->centre.x(), s->centre.y(), s->centre.z());
}
using Hull = std::array<Eigen::Vector3d, 8>;
void HullSupport(const void* obj, const ccd_vec3_t* dir, ccd_vec3_t* out) {
  const auto* h = static_cast<const Hull*>(obj);
  const Eigen::Vector3d d(dir->v[0], dir->v[1], dir->v[2]);
  int best = 0;
  double bd = (*h)[0].dot(d);
  for (int i = 1; i < 8; ++i) {
    const double v = (*h)[i].dot(d);
    if (v > bd) {
      bd = v;
      best = i;
    }
  }
  ccdVec3Set(out, (*h)[best].x(), (*h)[best].y(), (*h)[best].z());
}
void HullCenter(const void* obj, ccd_vec3_t* c) {
  const auto* h = static_cast<const Hull*>(obj);
  Eigen::Vector3d m = Eigen::Vector3d::Zero();
  for (const auto& p : *h) m += p;
  m /= 8.0;
  ccdVec3Set(c, m.x(), m.y(), m.z());
}
}  // namespace

bool CcdMprBoxes(const BoxShape& a, const BoxShape& b) {
  ccd_t ccd;
  CCD_INIT(&ccd);
  ccd.support1 = ccd.support2 = BoxSupport;
  ccd.center1 = ccd.center2 = BoxCenter;
  ccd.mpr_tolerance = 1e-12;
  return ccdMPRIntersect(&a, &b, &ccd) != 0;
}

bool CcdMprHulls(const std::array<Eigen::Vector3d, 8>& a, const std::array<Eigen::Vector3d, 8>& b) {
  ccd_t ccd;
  CCD_INIT(&ccd);
  ccd.support1 = ccd.support2 = HullSupport;
  ccd.center1 = ccd.center2 = HullCenter;
  ccd.mpr_tolerance = 1e-12;
  return ccdMPRIntersect(&a, &b, &ccd) != 0;
}

struct FclPair::Impl {
  std::shared_ptr<fcl::CollisionGeometryd> ga, gb;
  std::unique_ptr<fcl::CollisionObjectd> a, b;
};

FclPair::FclPair() : impl_(std::make_unique<Impl>()) {}
FclPair::~FclPair() = default;

std::unique_ptr<FclPair> FclPair::Boxes(const BoxShape& a, const BoxShape& b) {
  std::unique_ptr<FclPair> p(new FclPair);
  auto make = [](const BoxShape& s, std::shared_ptr<fcl::CollisionGeometryd>* g) {
    *g = std::make_shared<fcl::Boxd>(2 * s.half.x(), 2 * s.half.y(), 2 * s.half.z());
    fcl::Transform3d X = fcl::Transform3d::Identity();
    X.linear() = s.R;
    X.translation() = s.centre;
    return std::make_unique<fcl::CollisionObjectd>(*g, X);
  };
  p->impl_->a = make(a, &p->impl_->ga);
  p->impl_->b = make(b, &p->impl_->gb);
  return p;
}

std::unique_ptr<FclPair> FclPair::Hulls(const std::array<Eigen::Vector3d, 8>& a,
                                        const std::array<Eigen::Vector3d, 8>& b) {
  std::unique_ptr<FclPair> p(new FclPair);
  // The standard notation's faces (docs/collision.md), outward.
  static const int kFaces[6][4] = {{0, 1, 3, 4}, {0, 2, 5, 1}, {0, 4, 7, 2},
                                   {2, 7, 6, 5}, {4, 3, 6, 7}, {1, 5, 6, 3}};
  auto make = [](const std::array<Eigen::Vector3d, 8>& v,
                 std::shared_ptr<fcl::CollisionGeometryd>* g) {
    auto verts = std::make_shared<std::vector<fcl::Vector3d>>(v.begin(), v.end());
    auto faces = std::make_shared<std::vector<int>>();
    for (const auto& f : kFaces) {
      faces->push_back(4);
      for (int k = 0; k < 4; ++k)
        faces->push_back(f[k]);  // counter-clockwise seen from outside, as FCL wants
    }
    *g = std::make_shared<fcl::Convexd>(verts, 6, faces);
    return std::make_unique<fcl::CollisionObjectd>(*g, fcl::Transform3d::Identity());
  };
  p->impl_->a = make(a, &p->impl_->ga);
  p->impl_->b = make(b, &p->impl_->gb);
  return p;
}

bool FclPair::Collide() const {
  fcl::CollisionRequestd request;  // one contact at most; FCL computes it
  fcl::CollisionResultd result;
  return fcl::collide(impl_->a.get(), impl_->b.get(), request, result) > 0;
}

}  // namespace rms::bench
