#include "rms/scene_model/cluster_pairs.h"

#include "rms/base/check.h"

namespace rms::scene_model {

std::pair<int, int> PairOf(int index) {
  for (int a = 0; a < kNumClusters; ++a) {
    const int first = PairIndex(a, a + 1);
    const int count = kNumClusters - a - 1;
    if (index < first + count) return {a, a + 1 + (index - first)};
  }
  RMS_CHECK(false);
  return {0, 0};
}

int DcpPairSlot(int pair) {
  for (int k = 0; k < 3; ++k) {
    if (PairIndex(kDcpPairs[k].first, kDcpPairs[k].second) == pair) return k;
  }
  return -1;
}

}  // namespace rms::scene_model
