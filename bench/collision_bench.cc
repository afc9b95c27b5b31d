// Time per pair of the DCP's collision algorithm and of the references, on
// the same pre-generated pairs (Google Benchmark). The full comparison with
// the peers and the frame budget is the performance issue's; this measures
// what the collision issue reports.
#include <benchmark/benchmark.h>

#include <vector>

#include "box_sat.h"
#include "collision.h"
#include "exact_hull.h"
#include "generators.h"

namespace {

using rms::ref::Pair;

const std::vector<Pair>& Pairs(bool boxes) {
  static std::vector<Pair> box_pairs, general_pairs;
  auto& v = boxes ? box_pairs : general_pairs;
  if (v.empty()) {
    rms::ref::PairGenerator gen(12345);
    std::mt19937_64& rng = gen.rng();
    while (v.size() < 4096) {
      // Random pairs at unit scale: random boxes, or random frusta / skewed solids.
      Pair p = gen.Next(1.0, boxes);
      if (boxes ? p.kind == "random boxes" : (!p.a.is_box && !p.b.is_box)) v.push_back(p);
      (void)rng;
    }
  }
  return v;
}

void BM_DcpCollideBoxes(benchmark::State& state) {
  const auto& pairs = Pairs(true);
  rms::dcp::CollideOptions opt;
  opt.want_plane = state.range(0) != 0;
  std::size_t i = 0;
  for (auto _ : state) {
    const Pair& p = pairs[i++ & 4095];
    benchmark::DoNotOptimize(rms::dcp::Collide(p.a.hex, p.b.hex, opt).verdict);
  }
}
BENCHMARK(BM_DcpCollideBoxes)->Arg(0)->Arg(1)->ArgName("plane");

void BM_DcpCollideGeneral(benchmark::State& state) {
  const auto& pairs = Pairs(false);
  std::size_t i = 0;
  for (auto _ : state) {
    const Pair& p = pairs[i++ & 4095];
    benchmark::DoNotOptimize(rms::dcp::Collide(p.a.hex, p.b.hex).verdict);
  }
}
BENCHMARK(BM_DcpCollideGeneral);

void BM_RefLongDoubleSatBoxes(benchmark::State& state) {
  const auto& pairs = Pairs(true);
  std::size_t i = 0;
  for (auto _ : state) {
    const Pair& p = pairs[i++ & 4095];
    benchmark::DoNotOptimize(rms::ref::BoxesIntersect(p.a.box, p.b.box));
  }
}
BENCHMARK(BM_RefLongDoubleSatBoxes);

void BM_RefExactBoxes(benchmark::State& state) {
  const auto& pairs = Pairs(true);
  std::size_t i = 0;
  for (auto _ : state) {
    const Pair& p = pairs[i++ & 4095];
    benchmark::DoNotOptimize(rms::ref::ExactHullsIntersect(p.a.v, p.b.v));
  }
}
BENCHMARK(BM_RefExactBoxes);

void BM_RefExactGeneral(benchmark::State& state) {
  const auto& pairs = Pairs(false);
  std::size_t i = 0;
  for (auto _ : state) {
    const Pair& p = pairs[i++ & 4095];
    benchmark::DoNotOptimize(rms::ref::ExactHullsIntersect(p.a.v, p.b.v));
  }
}
BENCHMARK(BM_RefExactGeneral);

}  // namespace

BENCHMARK_MAIN();
