// FindSeparatingPlane (rms/scene_model/separating_plane.h) on its own:
// random box pairs against the classic 15-axis separating-axis test, the
// hint tried first, touching within eps.
#include "rms/scene_model/separating_plane.h"

#include <Eigen/Geometry>
#include <cstdio>
#include <gtest/gtest.h>
#include <random>

namespace rms::scene_model {
namespace {

struct Box {
  Eigen::Vector3d c;
  Eigen::Matrix3d R;  // columns: the box's axes
  Eigen::Vector3d h;  // half-extents
};

PosedHull HullOf(const Box& b) {
  PosedHull p;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d s(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1);
    p.points_R.push_back(b.c + b.R * s.cwiseProduct(b.h));
  }
  for (int k = 0; k < 3; ++k) {
    p.normals_R.push_back(b.R.col(k));
    p.edges_R.push_back(b.R.col(k));
  }
  p.centroid_R = b.c;
  p.scale_ft = b.h.norm();
  return p;
}

// The largest gap between the two boxes' projections over the 15 axes
// (> 0: separated by that much along some axis; < 0: they overlap).
double SatGap(const Box& a, const Box& b, bool* only_by_an_edge_pair) {
  auto gap = [&](Eigen::Vector3d n) {
    if (n.norm() < 1e-9) return -1e9;
    n.normalize();
    const double ra = (a.R.transpose() * n).cwiseAbs().dot(a.h);
    const double rb = (b.R.transpose() * n).cwiseAbs().dot(b.h);
    return std::abs(n.dot(b.c - a.c)) - ra - rb;
  };
  double faces = -1e9, edges = -1e9;
  for (int k = 0; k < 3; ++k) faces = std::max({faces, gap(a.R.col(k)), gap(b.R.col(k))});
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) edges = std::max(edges, gap(a.R.col(i).cross(b.R.col(j))));
  *only_by_an_edge_pair = faces < 0 && edges > 0;
  return std::max(faces, edges);
}

Box RandomBox(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), size(0.05, 1.5);
  const Eigen::Quaterniond q = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized();
  return {Eigen::Vector3d(u(rng), u(rng), u(rng)) * 1.5, q.toRotationMatrix(),
          Eigen::Vector3d(size(rng), size(rng), size(rng))};
}

TEST(SeparatingPlane, AgreesWithTheSeparatingAxisTestOnRandomBoxes) {
  const std::uint64_t seed = 20261207;
  std::printf("seed %llu\n", static_cast<unsigned long long>(seed));
  std::mt19937_64 rng(seed);
  const double eps = 1e-9;
  int separated = 0, overlapping = 0, by_edges = 0;
  for (int i = 0; i < 20000; ++i) {
    const Box a = RandomBox(rng), b = RandomBox(rng);
    bool edge_only = false;
    const double gap = SatGap(a, b, &edge_only);
    if (std::abs(gap) < 1e-6) continue;  // too near to call either way
    const PosedHull ha = HullOf(a), hb = HullOf(b);
    const std::optional<SeparatingPlane> plane = FindSeparatingPlane(ha, hb, eps, nullptr);
    if (gap < 0) {
      ++overlapping;
      EXPECT_FALSE(plane.has_value()) << "pair " << i << ": overlapping by " << -gap;
      continue;
    }
    ++separated;
    by_edges += edge_only;
    ASSERT_TRUE(plane.has_value()) << "pair " << i << ": separated by " << gap;
    EXPECT_NEAR(plane->n_R.norm(), 1.0, 1e-12);
    for (const auto& p : ha.points_R) EXPECT_LE(plane->SignedDistanceFt(p), eps) << "pair " << i;
    for (const auto& p : hb.points_R) EXPECT_GE(plane->SignedDistanceFt(p), -eps) << "pair " << i;
  }
  std::printf("%d separated (%d only by an edge pair), %d overlapping\n", separated, by_edges,
              overlapping);
  EXPECT_GT(separated, 1000);
  EXPECT_GT(overlapping, 1000);
  EXPECT_GT(by_edges, 20) << "the cross products of edges are exercised";
}

TEST(SeparatingPlane, TheHintIsTriedFirstAndAStaleOneIsNotReturned) {
  const Box a{Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity(), Eigen::Vector3d::Ones()};
  const Box b{Eigen::Vector3d(3, 0, 0), Eigen::Matrix3d::Identity(), Eigen::Vector3d::Ones()};
  const PosedHull ha = HullOf(a), hb = HullOf(b);
  // A tilted plane that still separates is kept, found with one try.
  const SeparatingPlane hint{Eigen::Vector3d(1, 0.1, 0).normalized(), 1.5};
  int tried = 0;
  const auto kept = FindSeparatingPlane(ha, hb, 1e-9, &hint, &tried);
  ASSERT_TRUE(kept.has_value());
  EXPECT_EQ(tried, 1);
  EXPECT_EQ(kept->n_R, hint.n_R);
  EXPECT_EQ(kept->d_ft, hint.d_ft);
  // A hint that cuts B is not returned: a plane is searched for afresh.
  const SeparatingPlane stale{Eigen::Vector3d::UnitX(), 2.5};
  const auto fresh = FindSeparatingPlane(ha, hb, 1e-9, &stale, &tried);
  ASSERT_TRUE(fresh.has_value());
  EXPECT_GT(tried, 1);
  EXPECT_NEAR(fresh->n_R.x(), 1.0, 1e-12) << "A's face normal, toward B";
  EXPECT_NEAR(fresh->d_ft, 1.5, 1e-12) << "midway across the 1 ft gap";
}

TEST(SeparatingPlane, TouchingWithinEpsHasAPlaneAndDeeperDoesNot) {
  const Box a{Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity(), Eigen::Vector3d::Ones()};
  const double eps = 1e-3;
  for (const double overlap : {0.0, 0.5e-3, 0.99e-3}) {
    const Box b{Eigen::Vector3d(2 - overlap, 0.3, -0.2), Eigen::Matrix3d::Identity(),
                Eigen::Vector3d::Ones()};
    EXPECT_TRUE(FindSeparatingPlane(HullOf(a), HullOf(b), eps, nullptr).has_value()) << overlap;
  }
  const Box deep{Eigen::Vector3d(2 - 2e-3, 0.3, -0.2), Eigen::Matrix3d::Identity(),
                 Eigen::Vector3d::Ones()};
  EXPECT_FALSE(FindSeparatingPlane(HullOf(a), HullOf(deep), eps, nullptr).has_value());
}

}  // namespace
}  // namespace rms::scene_model
