#pragma once
// Runs the DCP's collision algorithm against the references on generated
// pairs and classifies every disagreement by the pair's separation.
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace rms::reference {

struct CompareStats {
  long pairs = 0;
  long collide = 0;           // reference verdicts: intersecting pairs
  long disagree_in_band = 0;  // |separation| <= band x scale
  long disagree_outside = 0;  // must be zero
  long invalid = 0;           // DCP said kInvalid on valid input: must be zero
  long plane_missing = 0;     // separate, but no separating plane outside the band
  long plane_wrong = 0;       // a plane that does not separate (beyond band)
  long exact_checked = 0;     // pairs checked by the exact reference
  std::map<std::string, long> pairs_by_kind;
  std::map<std::string, long> in_band_by_kind;  // disagreements inside the band, by kind
  std::map<std::string, long> deciders;
  std::vector<std::string> examples;  // the first disagreements outside the band
  double dcp_seconds = 0, ref_seconds = 0;
};

// `count` pairs from `seed` across scales 1e-3 .. 1e4 ft. Boxes are checked
// against the long double separating-axis test (and every `exact_every`-th
// one also against the exact test); general hexahedra against the exact test.
CompareStats Compare(std::uint64_t seed, long count, double band_rel, int exact_every);

std::string Describe(const CompareStats& s);

}  // namespace rms::reference
