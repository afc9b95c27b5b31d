#include "rms/wire/priority_words.h"

namespace rms::wire {

namespace {

// The wire position of every non-DCP pair, in pair order.
struct WireLayout {
  std::array<int, scene_model::kNumPairs> slot{};  // -1 for DCP pairs
  WireLayout() {
    int k = 0;
    for (int p = 0; p < scene_model::kNumPairs; ++p)
      slot[p] = scene_model::DcpPairSlot(p) >= 0 ? -1 : k++;
  }
};
const WireLayout& Layout() {
  static const WireLayout layout;
  return layout;
}

}  // namespace

void PackPriority(const scene_model::PriorityBits& bits, ControlWord* cw,
                  std::array<std::int32_t, esg_words::kPriorityCount>* words) {
  cw->priority_dynamic = 0;
  cw->priority_fixed = 0;
  words->fill(0);
  for (int k = 0; k < 3; ++k) {
    if (bits[scene_model::PairIndex(scene_model::kDcpPairs[k].first,
                                    scene_model::kDcpPairs[k].second)])
      cw->priority_dynamic |= 1u << k;
  }
  const WireLayout& L = Layout();
  for (int p = 0; p < scene_model::kNumPairs; ++p) {
    const int s = L.slot[p];
    if (s < 0 || !bits[p]) continue;
    if (s < 7)
      cw->priority_fixed |= 1u << s;
    else
      (*words)[(s - 7) / 24] |= static_cast<std::int32_t>(1u << ((s - 7) % 24));
  }
}

std::string PriorityBitPlace(int pair) {
  const int k = scene_model::DcpPairSlot(pair);
  if (k >= 0) return "control word bit " + std::to_string(control_bits::kPriorityDynamicShift + k);
  const int s = Layout().slot[pair];
  if (s < 7) return "control word bit " + std::to_string(control_bits::kPriorityFixedShift + s);
  return "ESG word " + std::to_string(esg_words::kPriority + (s - 7) / 24) + " bit " +
         std::to_string((s - 7) % 24);
}

scene_model::PriorityBits UnpackPriority(const ControlWord& cw,
                                         std::span<const std::int32_t> words) {
  scene_model::PriorityBits bits;
  for (int k = 0; k < 3; ++k) {
    if (cw.priority_dynamic & (1u << k))
      bits.set(scene_model::PairIndex(scene_model::kDcpPairs[k].first,
                                      scene_model::kDcpPairs[k].second));
  }
  const WireLayout& L = Layout();
  for (int p = 0; p < scene_model::kNumPairs; ++p) {
    const int s = L.slot[p];
    if (s < 0) continue;
    const bool on = s < 7
                        ? (cw.priority_fixed >> s) & 1u
                        : (static_cast<std::uint32_t>(words[(s - 7) / 24]) >> ((s - 7) % 24)) & 1u;
    if (on) bits.set(p);
  }
  return bits;
}

}  // namespace rms::wire
