#pragma once
// Run-time dispatch to AVX where the processor has it (private to the DCP's
// library). The build targets baseline x86-64 so one binary runs on every
// lab machine; the AVX paths carry __attribute__((target("avx"))), never
// fused multiply-adds, and compute each number with the same operations in
// the same order as the scalar code: the same bits on every machine, so a
// session re-simulates identically anywhere (docs/performance.md).
#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define RMS_DCP_X86 1
#endif

namespace rms::dcp_model {

#if defined(RMS_DCP_X86)
// Use the AVX paths: checked once, at start; UseAvx (hexahedron.h) turns
// them off for a test. Read before it is initialised (another static
// initialiser), it is false: the scalar code, the same bits.
inline bool avx_enabled = __builtin_cpu_supports("avx");
#endif

}  // namespace rms::dcp_model
