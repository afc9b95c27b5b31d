#include "rms/wire/word_codec.h"

#include <cmath>
#include <cstdio>

#include "rms/base/check.h"

namespace rms::wire {

int FirstInvalidWord(std::span<const std::int32_t> words) {
  for (std::size_t i = 0; i < words.size(); ++i) {
    if (!IsValidWord(words[i])) return static_cast<int>(i);
  }
  return -1;
}

double FixedFormat::lsb() const { return std::ldexp(1.0, -frac_bits); }
double FixedFormat::min_value() const {
  return std::ldexp(static_cast<double>(raw_min), -frac_bits);
}
double FixedFormat::max_value() const {
  return std::ldexp(static_cast<double>(raw_max), -frac_bits);
}

namespace {

std::string Describe(const FixedFormat& f) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%.*s [%.9g, %.9g] %.*s", static_cast<int>(f.name.size()),
                f.name.data(), f.min_value(), f.max_value(), static_cast<int>(f.unit.size()),
                f.unit.data());
  return buf;
}

Word RawToWord(const FixedFormat& f, std::int64_t raw) {
  RMS_DASSERT(raw >= f.raw_min && raw <= f.raw_max);
  return f.is_signed ? FromSigned(static_cast<std::int32_t>(raw)) : static_cast<Word>(raw);
}

}  // namespace

Encoded Encode(const FixedFormat& f, double value) {
  if (!std::isfinite(value)) {
    throw InputError("cannot encode " + std::to_string(value) + " as " + Describe(f) +
                     ": not a finite number");
  }
  // Times 2^frac_bits (0..23): exact, as ldexp, without the library call.
  const double scaled = value * static_cast<double>(std::int64_t{1} << f.frac_bits);
  // Compare in double before rounding so huge values cannot overflow.
  if (scaled < static_cast<double>(f.raw_min) - 0.5) return {RawToWord(f, f.raw_min), true};
  if (scaled >= static_cast<double>(f.raw_max) + 0.5) return {RawToWord(f, f.raw_max), true};
  // std::llround's rounding (ties away from zero), without the library call:
  // |scaled| < 2^25 here, so the truncation and the fraction are exact.
  const auto truncated = static_cast<std::int64_t>(scaled);
  const double fraction = scaled - static_cast<double>(truncated);
  std::int64_t raw = truncated + (fraction >= 0.5) - (fraction <= -0.5);
  bool saturated = false;
  if (raw < f.raw_min) {
    raw = f.raw_min;
    saturated = true;
  }
  if (raw > f.raw_max) {
    raw = f.raw_max;
    saturated = true;
  }
  return {RawToWord(f, raw), saturated};
}

Word EncodeExact(const FixedFormat& f, double value) {
  const Encoded e = Encode(f, value);
  if (e.saturated) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.17g", value);
    throw InputError(std::string("value ") + buf + " is out of range for " + Describe(f));
  }
  return e.word;
}

std::int32_t DecodeRaw(const FixedFormat& f, std::int32_t carried) {
  if (!IsValidWord(carried)) {
    throw InputError("word " + FormatWord(carried) + " has bits above bit 23 set (format " +
                     std::string(f.name) + ")");
  }
  const std::int32_t raw = RawUnchecked(f, static_cast<Word>(carried));
  if (raw < f.raw_min || raw > f.raw_max) {
    throw InputError("word " + FormatWord(carried) + " (raw " + std::to_string(raw) +
                     ") is outside " + Describe(f));
  }
  return raw;
}

double Decode(const FixedFormat& f, std::int32_t carried) {
  // Divided by 2^frac_bits: exact (a power of two), as ldexp.
  return static_cast<double>(DecodeRaw(f, carried)) /
         static_cast<double>(std::int64_t{1} << f.frac_bits);
}

double RoundTrip(const FixedFormat& f, double value) {
  return Decode(f, static_cast<std::int32_t>(Encode(f, value).word));
}

Word EncodeAngleBam(double angle_deg) {
  if (!std::isfinite(angle_deg)) {
    throw InputError("cannot encode angle " + std::to_string(angle_deg) +
                     " deg as BAM24: not a finite number");
  }
  // Reduce to turns in [-0.5, 0.5), then to raw counts; wrap keeps it exact.
  double turns = angle_deg / 360.0;
  turns -= std::floor(turns + 0.5);
  std::int64_t raw = std::llround(turns * 16777216.0);
  raw &= 0xFFFFFF;  // wrap: +0.5 turn rounds to -0.5 turn
  return static_cast<Word>(raw);
}

double DecodeAngleBam(std::int32_t carried) {
  if (!IsValidWord(carried)) {
    throw InputError("word " + FormatWord(carried) + " has bits above bit 23 set (format BAM24)");
  }
  return ToSigned(static_cast<Word>(carried)) * kBamLsbDeg;
}

std::string FormatWord(std::int32_t carried) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%06X", static_cast<unsigned>(carried));
  return buf;
}

}  // namespace rms::wire
