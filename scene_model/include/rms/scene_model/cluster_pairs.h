#pragma once
// Visual priority's bookkeeping (docs/scene.md "Visual priority"): every pair
// of the scene's 34 convex clusters has a separating plane and one priority
// bit. The Visual Scene Program (scene_proc) sets the bits, the ESG frame
// carries them (rms/wire/priority_words.h), the ESG (esg_renderer) orders
// clusters by them. The planes of the three pairs EFF HEX 1, 2, 3 / BAR are
// the DCP's dynamic separating planes (report IV.A.1).
#include <array>
#include <bitset>
#include <utility>

#include "rms/scene_model/scene_model.h"

namespace rms::scene_model {

inline constexpr int kNumPairs = kNumClusters * (kNumClusters - 1) / 2;  // 561
static_assert(kNumClusters <= 64, "DrawOrder keeps a cluster set in 64 bits");
// Index of the pair (a, b), a < b, in lexicographic order.
constexpr int PairIndex(int a, int b) { return a * (2 * kNumClusters - a - 1) / 2 + (b - a - 1); }
std::pair<int, int> PairOf(int index);

// The three pairs whose planes the DCP computes: control word bits 14-16.
inline constexpr std::array<std::pair<int, int>, 3> kDcpPairs = {
    {{kEffHex1, kBar}, {kEffHex2, kBar}, {kEffHex3, kBar}}};
// The slot (0-2) of a DCP pair in kDcpPairs, or -1 for any other pair.
int DcpPairSlot(int pair);

// bit[pair] = 1: the viewpoint is on the pair's first cluster's side (the
// lower id), which can then hide the second but not be hidden by it.
using PriorityBits = std::bitset<kNumPairs>;

}  // namespace rms::scene_model
