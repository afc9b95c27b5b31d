#pragma once
// Pairs of hexahedra for checking the DCP's collision algorithm against the
// references (fixed seeds; the tests print them). Each pair comes as the
// DCP's Hexahedron and as the vertex arrays (and, for boxes, the exact box
// parameters) the references take.
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <random>
#include <string>

#include "rms/dcp_model/hexahedron.h"
#include "rms/reference/box_sat.h"
#include "rms/reference/hull_distance.h"

namespace rms::reference {

struct Solid {
  dcp_model::Hexahedron hex;
  std::array<Eigen::Vector3d, 8> v;
  bool is_box = false;
  RefBox box;  // when is_box
};

struct Pair {
  Solid a, b;
  std::string kind;
};

inline Topology StandardTopology() {
  Topology t;
  for (int f = 0; f < 6; ++f)
    for (int j = 0; j < 4; ++j) t.faces[f][j] = dcp_model::kFaceVertices[f][j];
  for (int e = 0; e < 12; ++e) t.edges[e] = {dcp_model::kEdges[e][0], dcp_model::kEdges[e][1]};
  return t;
}

// Sign pattern (u, v, w) of each vertex in the standard notation, u from
// face a to d, v from b to e, w from c to f.
inline constexpr std::array<std::array<int, 3>, 8> kVertexSigns = {{
    {-1, -1, -1},
    {-1, -1, 1},
    {1, -1, -1},
    {-1, 1, 1},
    {-1, 1, -1},
    {1, -1, 1},
    {1, 1, 1},
    {1, 1, -1},
}};

inline Eigen::Matrix3d RandomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
}

// A box the report's way (MakeBox from the centre of face a), and its exact
// description for the long double reference.
inline Solid Box(const Eigen::Vector3d& centre, const Eigen::Matrix3d& R,
                 const Eigen::Vector3d& half) {
  Solid s;
  const Eigen::Vector3d U = R.col(0), V = R.col(1), W = R.col(2);
  s.hex = dcp_model::MakeBox(centre - half.x() * U, U, V, W, 2 * half.x(), half.y(), half.z());
  for (int i = 0; i < 8; ++i) s.v[i] = s.hex.vertex(i);
  s.is_box = true;
  s.box.centre = centre.cast<long double>();
  for (int k = 0; k < 3; ++k) {
    s.box.axis[k] = R.col(k).cast<long double>();
    s.box.half[k] = half[k];
  }
  return s;
}

// A general hexahedron: the box's vertices, face f shrunk toward its centre
// by `taper` (a frustum; 1 keeps the box), then the linear map M (a shear
// makes a skewed solid), then placed at `centre`.
inline Solid General(const Eigen::Vector3d& centre, const Eigen::Matrix3d& M,
                     const Eigen::Vector3d& half, double taper) {
  Solid s;
  for (int i = 0; i < 8; ++i) {
    Eigen::Vector3d p(kVertexSigns[i][0] * half.x(), kVertexSigns[i][1] * half.y(),
                      kVertexSigns[i][2] * half.z());
    if (kVertexSigns[i][2] > 0) {  // on face f (w+): toward its centre
      p.x() *= taper;
      p.y() *= taper;
    }
    s.v[i] = centre + M * p;
  }
  s.hex = dcp_model::FromVertices(s.v);
  return s;
}

inline Eigen::Matrix3d RandomShear(std::mt19937_64& rng, double amount) {
  std::uniform_real_distribution<double> u(-amount, amount);
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  S(0, 1) = u(rng);
  S(0, 2) = u(rng);
  S(1, 2) = u(rng);
  return RandomRotation(rng) * S;
}

// The same pair moved by `offset` ft (a small solid far from the origin:
// its coordinates rounded at the offset's magnitude). Boxes are rebuilt the
// report's way at the new centre; general hexahedra from the moved vertices.
inline Pair Translated(const Pair& p, const Eigen::Vector3d& offset) {
  auto move = [&](const Solid& s) {
    if (s.is_box) {
      Eigen::Matrix3d R;
      Eigen::Vector3d half;
      for (int k = 0; k < 3; ++k) {
        R.col(k) = s.box.axis[k].cast<double>();
        half[k] = static_cast<double>(s.box.half[k]);
      }
      Solid t = Box(s.box.centre.cast<double>() + offset, R, half);
      return t;
    }
    Solid t = s;
    for (auto& v : t.v) v += offset;
    t.hex = dcp_model::FromVertices(t.v);
    return t;
  };
  return {move(p.a), move(p.b), p.kind + ", far out"};
}

// The mix of cases, at `scale` ft. kind selects the family; the generator
// picks one of them per call in a fixed rotation.
class PairGenerator {
 public:
  explicit PairGenerator(std::uint64_t seed) : rng_(seed) {}

  Pair Next(double scale, bool boxes_only) {
    const int kinds = boxes_only ? 7 : 10;
    const int k = static_cast<int>(counter_++ % kinds);
    switch (k) {
      case 0:
        return RandomBoxes(scale);
      case 1:
        return TouchingFaces(scale, true);
      case 2:
        return TouchingFaces(scale, false);
      case 3:
        return ParallelEdges(scale);
      case 4:
        return Nested(scale);
      case 5:
        return RodThroughSlab(scale);
      case 6:
        return NearContactBoxes(scale);
      case 7:
        return RandomGeneral(scale, /*taper=*/true, /*shear=*/false);
      case 8:
        return RandomGeneral(scale, false, true);
      default:
        return RandomGeneral(scale, true, true);
    }
  }

  std::mt19937_64& rng() { return rng_; }

  // Two boxes whose closest features are an edge of each, the edges at an
  // angle of 1e-7 to 1e-2 rad (either sign) and `gap` apart along their
  // common normal (gap < 0: overlapping by about -gap). The edge of B along
  // its x axis at (y, z) = (+hb.y, +hb.z); the common normal n = (y + z)/sqrt 2;
  // A's edge crosses over B's at the middle of both, A lying beyond n from
  // it with its two faces at the edge at 45 deg to n, so the boxes' distance
  // is exactly `gap` when gap > 0.
  Pair NearParallelEdges(double s, double gap_rel) {
    std::uniform_real_distribution<double> lg(-7.0, -2.0), u(-0.7, 0.7);
    std::uniform_int_distribution<int> sg(0, 1);
    const double theta = (sg(rng_) ? 1 : -1) * std::pow(10.0, lg(rng_));
    const Eigen::Vector3d ha = RandomHalf(s), hb = RandomHalf(s);
    const Eigen::Vector3d n = Eigen::Vector3d(0, 1, 1).normalized();
    const Eigen::Vector3d m = n.cross(Eigen::Vector3d::UnitX());
    const Eigen::Vector3d w = std::cos(theta) * Eigen::Vector3d::UnitX() + std::sin(theta) * m;
    const Eigen::Vector3d q = w.cross(n);
    Eigen::Matrix3d Ra;
    Ra.col(0) = w;
    Ra.col(1) = (n - q) / std::sqrt(2.0);
    Ra.col(2) = (n + q) / std::sqrt(2.0);
    // Gap relative to the pair's largest possible bounding-box diagonal
    // (2 sqrt 3 |half|), so |gap_rel| >= band means outside the band.
    const double diag = 2 * std::sqrt(3.0) * std::max(ha.norm(), hb.norm());
    const double gap = gap_rel * diag;
    const Eigen::Vector3d on_b(u(rng_) * hb.x(), hb.y(), hb.z());
    const Eigen::Vector3d edge_a = on_b + gap * n;
    const Eigen::Vector3d ca = edge_a + ha.y() * Ra.col(1) + ha.z() * Ra.col(2);
    const Eigen::Matrix3d R = RandomRotation(rng_);
    const Eigen::Vector3d cb = RandomPos(s);
    return {Box(cb + R * ca, R * Ra, ha), Box(cb, R, hb), "near-parallel edges"};
  }

 private:
  Eigen::Vector3d RandomHalf(double scale) {
    std::uniform_real_distribution<double> h(0.05, 0.5);
    return scale * Eigen::Vector3d(h(rng_), h(rng_), h(rng_));
  }
  Eigen::Vector3d RandomPos(double scale) {
    std::uniform_real_distribution<double> p(-0.8, 0.8);
    return scale * Eigen::Vector3d(p(rng_), p(rng_), p(rng_));
  }

  Pair RandomBoxes(double s) {
    return {Box(RandomPos(s), RandomRotation(rng_), RandomHalf(s)),
            Box(RandomPos(s), RandomRotation(rng_), RandomHalf(s)), "random boxes"};
  }

  // Face to face: exactly (axis-aligned, dyadic coordinates) or after a
  // common rotation (touching within rounding), each offset along the
  // normal by a signed gap from 0 to 1e-6 scale or exactly zero.
  Pair TouchingFaces(double s, bool exact) {
    std::uniform_int_distribution<int> small(1, 8);
    const double unit = std::ldexp(1.0, static_cast<int>(std::floor(std::log2(s))));
    Eigen::Vector3d ha(small(rng_), small(rng_), small(rng_)),
        hb(small(rng_), small(rng_), small(rng_));
    ha *= unit / 16;
    hb *= unit / 16;
    std::uniform_int_distribution<int> off(-4, 4);
    Eigen::Vector3d cb(ha.x() + hb.x(), off(rng_) * unit / 16, off(rng_) * unit / 16);
    std::uniform_int_distribution<int> gapsel(0, 6);
    const int g = gapsel(rng_);
    const double gap = g == 0 ? 0.0 : (g % 2 ? 1 : -1) * s * std::pow(10.0, -6 - g);
    cb.x() += gap;
    const Eigen::Matrix3d R = exact ? Eigen::Matrix3d::Identity() : RandomRotation(rng_);
    const Eigen::Vector3d ca = exact ? Eigen::Vector3d::Zero() : RandomPos(s);
    return {Box(ca, R, ha), Box(ca + R * cb, R, hb),
            exact ? "touching faces, exact" : "touching faces, rotated"};
  }

  Pair ParallelEdges(double s) {
    const Eigen::Matrix3d R = RandomRotation(rng_);
    const Eigen::Vector3d ha = RandomHalf(s), hb = RandomHalf(s);
    std::uniform_real_distribution<double> u(-1.1, 1.1);
    const Eigen::Vector3d c(u(rng_) * (ha.x() + hb.x()), u(rng_) * (ha.y() + hb.y()),
                            u(rng_) * (ha.z() + hb.z()));
    const Eigen::Vector3d ca = RandomPos(s);
    return {Box(ca, R, ha), Box(ca + R * c, R, hb), "parallel edges"};
  }

  Pair Nested(double s) {
    const Eigen::Vector3d c = RandomPos(s);
    const Eigen::Vector3d half = RandomHalf(s);
    const Eigen::Matrix3d R = RandomRotation(rng_);
    const double k = 0.3;  // inner half-extent factor; any rotation keeps it inside
    const Eigen::Vector3d inner = Eigen::Vector3d::Constant(k * half.minCoeff() / std::sqrt(3.0));
    Pair p{Box(c, R, half), Box(c, RandomRotation(rng_), inner), "one inside the other"};
    if (counter_ % 2) std::swap(p.a, p.b);
    return p;
  }

  // No vertex of either lies in the other: only the edge test finds these.
  Pair RodThroughSlab(double s) {
    const Eigen::Matrix3d R = RandomRotation(rng_);
    const Eigen::Vector3d c = RandomPos(s);
    std::uniform_real_distribution<double> tilt(-0.3, 0.3), shift(-0.4, 0.4);
    const Eigen::Matrix3d Rr =
        R * Eigen::AngleAxisd(tilt(rng_), Eigen::Vector3d::UnitX()).toRotationMatrix();
    const Eigen::Vector3d slab = s * Eigen::Vector3d(0.5, 0.5, 0.05);
    const bool beams = counter_ % 3 == 0;
    const Eigen::Vector3d rod =
        beams ? s * Eigen::Vector3d(0.05, 0.6, 0.05) : s * Eigen::Vector3d(0.04, 0.04, 0.6);
    const Eigen::Vector3d slab_or_beam = beams ? s * Eigen::Vector3d(0.6, 0.05, 0.05) : slab;
    const Eigen::Vector3d off = R * Eigen::Vector3d(shift(rng_) * s, shift(rng_) * s, 0);
    return {Box(c + off * (beams ? 0.1 : 1.0), Rr, rod), Box(c, R, slab_or_beam),
            beams ? "crossed beams" : "rod through slab"};
  }

  // Random boxes moved until they nearly touch: the hard cases near contact.
  Pair NearContactBoxes(double s) {
    Pair p = RandomBoxes(s);
    const Eigen::Vector3d dir = (p.b.box.centre - p.a.box.centre).cast<double>().normalized();
    const Eigen::Matrix3d Rb = [&] {
      Eigen::Matrix3d m;
      for (int k = 0; k < 3; ++k) m.col(k) = p.b.box.axis[k].cast<double>();
      return m;
    }();
    const Eigen::Vector3d hb(p.b.box.half[0], p.b.box.half[1], p.b.box.half[2]);
    // Bisect the distance along dir at which the boxes just touch.
    double lo = 0, hi = 4 * s;
    for (int i = 0; i < 60; ++i) {
      const double mid = 0.5 * (lo + hi);
      RefBox b = p.b.box;
      b.centre = p.a.box.centre + (mid * dir).cast<long double>();
      (BoxSatSeparation(p.a.box, b) > 0 ? hi : lo) = mid;
    }
    std::uniform_int_distribution<int> e(-12, -4);
    std::uniform_int_distribution<int> sg(0, 1);
    const double t = lo + (sg(rng_) ? 1 : -1) * s * std::pow(10.0, e(rng_));
    p.b = Box(p.a.box.centre.cast<double>() + t * dir, Rb, hb);
    p.kind = "near contact";
    return p;
  }

  Pair RandomGeneral(double s, bool taper, bool shear) {
    std::uniform_real_distribution<double> k(0.2, 1.0);
    auto make = [&] {
      const Eigen::Matrix3d M = shear ? RandomShear(rng_, 0.8) : RandomRotation(rng_);
      return General(RandomPos(s), M, RandomHalf(s), taper ? k(rng_) : 1.0);
    };
    return {make(), make(), taper && shear ? "skewed frusta" : taper ? "frusta" : "skewed boxes"};
  }

  std::mt19937_64 rng_;
  std::uint64_t counter_ = 0;
};

}  // namespace rms::reference
