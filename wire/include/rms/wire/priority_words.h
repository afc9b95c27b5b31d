#pragma once
// The visual-priority bits on the wire (docs/protocol.md "Visual priority
// bits"): the DCP pairs in the control word's PRIORITY_DYNAMIC bits, then the
// other 558 pairs in pair order: the first 7 in PRIORITY_FIXED, the rest in
// the ESG frame's priority words, bit 0 of word 0 first, 24 to a word.
#include <array>
#include <cstdint>
#include <span>
#include <string>

#include "rms/scene_model/cluster_pairs.h"
#include "rms/wire/control_word.h"
#include "rms/wire/word_blocks.h"

namespace rms::wire {

void PackPriority(const scene_model::PriorityBits& bits, ControlWord* cw,
                  std::array<std::int32_t, esg_words::kPriorityCount>* words);
scene_model::PriorityBits UnpackPriority(const ControlWord& cw,
                                         std::span<const std::int32_t> priority_words);
// Where a pair's bit travels, for the priority table: "control word bit 14",
// "ESG word 41 bit 0" (ESG frame word numbering, docs/protocol.md).
std::string PriorityBitPlace(int pair);

}  // namespace rms::wire
