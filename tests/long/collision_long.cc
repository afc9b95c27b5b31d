// The long target: the collision algorithm against the references on 10^6
// generated pairs (the suite runs 4 x 10^4). Run it with
//   ctest --test-dir build -L long --output-on-failure
// or build/tests/rms_long_tests [pairs].
#include <cstdio>
#include <cstdlib>

#include "rms/reference/compare.h"

int main(int argc, char** argv) {
  const long count = argc > 1 ? std::atol(argv[1]) : 1000000;
  const std::uint64_t seed = 19721122;
  std::printf("collision algorithm vs references: seed %llu, %ld pairs, band 1e-9 x scale\n",
              static_cast<unsigned long long>(seed), count);
  const rms::reference::CompareStats st =
      rms::reference::Compare(seed, count, 1e-9, /*exact_every=*/4);
  std::printf("%s", rms::reference::Describe(st).c_str());
  const bool ok =
      st.disagree_outside == 0 && st.invalid == 0 && st.plane_wrong == 0 && st.plane_missing == 0;
  std::printf("%s\n", ok ? "PASS" : "FAIL");
  return ok ? 0 : 1;
}
