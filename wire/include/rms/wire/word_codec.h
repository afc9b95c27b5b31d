#pragma once
// The 24-bit word and its fixed-point formats. docs/protocol.md, "Words and
// formats", is the one description; this file implements it.
//
// A word is a 24-bit value carried in an int32 on the wire (the ESG took
// 24-bit words; the Sigma-5 word was 32 bits). Bits 24-31 must be zero: a
// message holding a word with any of them set is malformed. Signed formats use
// 24-bit two's complement, so -1 is 0xFFFFFF.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace rms::wire {

using Word = std::uint32_t;  // always < 2^24 once validated

inline constexpr int kWordBits = 24;
inline constexpr Word kWordMask = 0xFFFFFFu;
inline constexpr std::int32_t kSignedMin = -(1 << 23);     // -8388608
inline constexpr std::int32_t kSignedMax = (1 << 23) - 1;  //  8388607

// True when the int32 carried on the wire is a valid 24-bit word.
constexpr bool IsValidWord(std::int32_t carried) {
  return (static_cast<std::uint32_t>(carried) & ~kWordMask) == 0;
}

// Index of the first invalid word, or -1 when every word is valid.
int FirstInvalidWord(std::span<const std::int32_t> words);

// Sign-extends a 24-bit two's complement word.
constexpr std::int32_t ToSigned(Word w) {
  return static_cast<std::int32_t>((w & kWordMask) ^ 0x800000u) - 0x800000;
}
// The 24-bit two's complement pattern of v; v must be in [kSignedMin, kSignedMax].
constexpr Word FromSigned(std::int32_t v) { return static_cast<Word>(v) & kWordMask; }

// A fixed-point format: value = raw * 2^-frac_bits (signed raw or unsigned raw).
// The integer formats (counts) are fixed-point formats with frac_bits = 0.
struct FixedFormat {
  std::string_view name;  // e.g. "SC22"
  std::string_view unit;  // e.g. "ft"
  int frac_bits;          // LSB = 2^-frac_bits units
  bool is_signed;
  std::int32_t raw_min;  // smallest raw value in range (may be narrower than 24 bits)
  std::int32_t raw_max;  // largest raw value in range

  double lsb() const;
  double min_value() const;
  double max_value() const;
};

// The formats of docs/protocol.md.
// SC22: sines, cosines, direction cosines. Q1.22 signed: [-2, 2 - 2^-22], LSB 2.38e-7.
inline constexpr FixedFormat kSC22{"SC22", "1", 22, true, kSignedMin, kSignedMax};
// FT12: lengths and positions in feet. Q11.12 signed: [-2048, 2048 - 2^-12] ft, LSB 2.44e-4 ft.
inline constexpr FixedFormat kFT12{"FT12", "ft", 12, true, kSignedMin, kSignedMax};
// ADC16: an analog input's converter counts, 15 bits plus sign: [-32768, 32767].
inline constexpr FixedFormat kADC16{"ADC16", "count", 0, true, -32768, 32767};
// U24: unsigned integer (counters): [0, 16777215].
inline constexpr FixedFormat kU24{"U24", "1", 0, false, 0, 0xFFFFFF};
// BAM24 is a binary angle, not a fixed-point fraction: angle = raw * 360/2^24 deg,
// raw signed, [-180, 180) deg, LSB 2.15e-5 deg. See EncodeAngleBam / DecodeAngleBam.

// Result of a saturating encode.
struct Encoded {
  Word word;
  bool saturated;  // true when the value was outside the format's range and clamped
};

// Encodes value to the nearest representable raw (ties away from zero),
// saturating at the format's range. Throws rms::InputError for NaN or
// infinity, naming the format.
Encoded Encode(const FixedFormat& f, double value);

// Like Encode, but a value outside the range is an error (rms::InputError with
// the value, the format and its range). A value within half an LSB of the
// range end is accepted and rounds to the end.
Word EncodeExact(const FixedFormat& f, double value);

// Raw value of a word in format f. Throws rms::InputError when the word has
// bits above bit 23 set, or (for narrow formats) the raw lies outside
// [raw_min, raw_max].
std::int32_t DecodeRaw(const FixedFormat& f, std::int32_t carried);
// value = raw * lsb. Same errors as DecodeRaw.
double Decode(const FixedFormat& f, std::int32_t carried);
// The value as a receiver reads it back: Decode(Encode(value)) (saturating).
double RoundTrip(const FixedFormat& f, double value);

// Raw of a word that the caller has already validated (IsValidWord): no checks.
inline std::int32_t RawUnchecked(const FixedFormat& f, Word w) {
  return f.is_signed ? ToSigned(w) : static_cast<std::int32_t>(w & kWordMask);
}

// Binary angular measure. EncodeAngleBam wraps any finite angle into
// [-180, 180) deg (angles do not saturate); NaN/Inf throw rms::InputError.
inline constexpr double kBamLsbDeg = 360.0 / 16777216.0;
Word EncodeAngleBam(double angle_deg);
double DecodeAngleBam(std::int32_t carried);  // throws on bits above 23

std::string FormatWord(std::int32_t carried);  // "0x12ABCD"

}  // namespace rms::wire
