#pragma once
// Which pair collides: the collision bits of RMS_DCP_TELEMETRY's
// `collisions` and `slave_collisions` (docs/collision.md, "Collision bits").
// The DCP sets them; the operator station (status screen, autopilot) and the
// session tools read them.
#include <array>
#include <cstdint>
#include <string>
#include <string_view>

#include "rms/base/counters.h"

namespace rms::wire {

namespace collision_bits {
inline constexpr std::uint32_t kEffHexRecpt = 1u << 0;  // bits 0-2: EFF HEX 1, 2, 3 with the BAR
inline constexpr std::uint32_t kEffHexPayload =
    1u << 3;  // bits 3-5: EFF HEX 1, 2, 3 with the payload body
inline constexpr std::uint32_t kBayFace = 1u
                                          << 6;  // bits 6-11: a payload vertex beyond bay face a..f
inline constexpr std::uint32_t kPayloadCae = 1u
                                             << 12;  // a payload vertex inside the CAE's front half
inline constexpr std::uint32_t kEffHexBarPost =
    1u << 13;  // EFF HEX 1, 2 or 3 with a post under the bar
inline constexpr std::uint32_t kNonFinite = 1u
                                            << 14;  // the command's models are not finite: refused
inline constexpr std::uint32_t kRecptMask =
    0x7u;  // the end effector with the BAR (the essential contact: bit 2 alone, the movable finger
           // closing)
inline constexpr std::uint32_t kEePayloadMask = 0x7u << 3;
inline constexpr std::uint32_t kBayMask = 0x3Fu << 6;
inline constexpr int kCount = 15;
}  // namespace collision_bits

// The collision bits less the essential contact (docs/collision.md "The
// essential contact"): the movable finger closing onto the BAR, seen in the
// telemetry as bit 2 alone while the finger is held, the arm is not, and the
// master's finger lever is beyond the slave's (closing). The rest are
// detrimental (the control word's COLLISION and RECPT say the same).
inline std::uint32_t DetrimentalCollisions(std::uint32_t collisions, bool finger_held, bool held,
                                           bool closing) {
  const bool essential =
      closing && finger_held && !held && collisions == (collision_bits::kEffHexRecpt << 2);
  return essential ? 0u : collisions;
}

// "eff_hex_2-recpt", "payload-bay_b", ... for logs, counters and summaries.
inline constexpr std::array<const char*, collision_bits::kCount> kCollisionNames = {
    "eff_hex_1-recpt",   "eff_hex_2-recpt",   "eff_hex_3-recpt", "eff_hex_1-payload",
    "eff_hex_2-payload", "eff_hex_3-payload", "payload-bay_a",   "payload-bay_b",
    "payload-bay_c",     "payload-bay_d",     "payload-bay_e",   "payload-bay_f",
    "payload-cae",       "eff_hex-bar_post",  "non-finite"};
inline const char* CollisionName(int bit) {
  return bit >= 0 && bit < collision_bits::kCount ? kCollisionNames[bit] : "?";
}
// collisions.KIND and collision_frames.KIND for a collision bit (rms/base/counters.h).
constexpr Counter CollisionCounter(int bit) {
  return CounterAt(Counter::kCollisionsEffHex1Recpt, bit);
}
constexpr Counter CollisionFramesCounter(int bit) {
  return CounterAt(Counter::kCollisionFramesEffHex1Recpt, bit);
}
constexpr bool CollisionFamilyFollows(Counter first, std::string_view prefix) {
  for (int b = 0; b < collision_bits::kCount; ++b) {
    const std::string_view n = CounterName(CounterAt(first, b));
    if (n.substr(0, prefix.size()) != prefix || n.substr(prefix.size()) != kCollisionNames[b])
      return false;
  }
  return true;
}
static_assert(CollisionFamilyFollows(Counter::kCollisionsEffHex1Recpt, "collisions."));
static_assert(CollisionFamilyFollows(Counter::kCollisionFramesEffHex1Recpt, "collision_frames."));

// The names of the bits set in `bits`, in bit order, joined by `separator`
// ("eff_hex_1-recpt, payload-bay_b"); `none` when no bit is set.
inline std::string CollisionNames(std::uint32_t bits, std::string_view separator = ", ",
                                  std::string_view none = "") {
  std::string s;
  for (int b = 0; b < collision_bits::kCount; ++b) {
    if (!(bits & (1u << b))) continue;
    if (!s.empty()) s += separator;
    s += kCollisionNames[b];
  }
  return s.empty() ? std::string(none) : s;
}

}  // namespace rms::wire
