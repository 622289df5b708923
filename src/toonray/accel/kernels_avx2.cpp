// The traversal kernels with AVX2, compiled with a target pragma so that the portable build
// (-march=x86-64-v2) has them too; TriangleAccel picks them at run time when the CPU supports
// AVX2. FMA only in the box tests (see kernels.inl); the triangle tests never fuse.
//
// Everything is included before the pragma, so inline functions from headers keep the default
// target (they could otherwise be merged, AVX2 code and all, into other translation units).
// Every float operation of the triangle tests must round exactly as written, in every build:
// no fused multiply-adds, which -march=native (TOONRAY_NATIVE) would otherwise let GCC form.
#pragma GCC optimize("fp-contract=off")
#include <immintrin.h>

#include <algorithm>
#include <cstring>
#include <limits>

#include "toonray/accel/kernels.h"
#include "toonray/accel/watertight.h"

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#define TOONRAY_ACCEL_HAVE_AVX2 1
#pragma GCC push_options
#pragma GCC target("avx2,bmi,bmi2,lzcnt,popcnt,fma")
#define TOONRAY_ACCEL_AVX2 1
#define TOONRAY_ACCEL_FMA 1  // box tests only; fp-contract=off keeps it out of everything else

namespace toonray::accel {
namespace avx2 {
namespace {  // internal linkage: the instruction sets' copies must never be merged
#include "toonray/accel/simd8.inl"
#include "toonray/accel/kernels.inl"
}  // namespace
}  // namespace avx2
}  // namespace toonray::accel

#pragma GCC pop_options
#endif

namespace toonray::accel {

const KernelTable* kernels_avx2() {
#ifdef TOONRAY_ACCEL_HAVE_AVX2
    static const KernelTable table{"avx2", &avx2::intersect1, &avx2::occluded1, &avx2::intersect_tile};
    return &table;
#else
    return nullptr;
#endif
}

}  // namespace toonray::accel
