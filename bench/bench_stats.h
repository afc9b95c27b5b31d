#pragma once
// Small statistics the benchmarks share.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace rms::bench {

// The p-quantile (0..1) by nearest rank; 0 for no samples.
inline double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1,
                    static_cast<std::size_t>(std::lround(p * static_cast<double>(v.size() - 1))))];
}

inline double Mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0 : s / v.size();
}

}  // namespace rms::bench
