#pragma once
/// SSE4.2 intrinsics (`_mm_*`, `__m128`, `__m128i`) on every target. On x86 they are the
/// compiler's own; elsewhere (aarch64) SIMDe implements them with NEON or plain C++, keeping
/// x86's results exactly: NaN rules of min/max and comparisons, cvtt's out-of-range value,
/// blends by the sign bit. SIMDE_FAST_* must therefore stay undefined. Code written against
/// these intrinsics thus computes the same bits on every CPU.
///
/// TOONRAY_SIMD_SIMDE selects SIMDe's portable implementation on x86 too (SIMDE_NO_NATIVE): only
/// for measuring what the aarch64 path costs (docs/accel.md), in translation units that include
/// no x86 intrinsics header of their own.

#if (defined(__x86_64__) || defined(__i386__)) && !defined(TOONRAY_SIMD_SIMDE)
#include <smmintrin.h>
#include <nmmintrin.h>
#else
#if defined(SIMDE_FAST_MATH) || defined(SIMDE_FAST_NANS) || defined(SIMDE_FAST_ROUND_MODE) || \
    defined(SIMDE_FAST_ROUND_TIES) || defined(SIMDE_FAST_CONVERSION_RANGE)
#error "toonray needs SIMDe's exact x86 semantics: do not define SIMDE_FAST_*"
#endif
// Exact even under -ffast-math or -ffinite-math-only, which would otherwise turn these on.
#define SIMDE_NO_FAST_MATH
#define SIMDE_NO_FAST_NANS
#define SIMDE_NO_FAST_ROUND_MODE
#define SIMDE_NO_FAST_ROUND_TIES
#define SIMDE_NO_FAST_CONVERSION_RANGE
#if defined(TOONRAY_SIMD_SIMDE)
#define SIMDE_NO_NATIVE
#endif
#define SIMDE_ENABLE_NATIVE_ALIASES
#include <simde/x86/sse4.2.h>
#endif
