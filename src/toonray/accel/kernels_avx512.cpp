// The traversal kernels compiled for AVX-512 (F, VL, BW, DQ): the same 8-wide code as
// kernels_avx2.cpp, which the compiler can then write with mask registers and three-input
// logic. Chosen at run time when the CPU has it. FMA only in the box tests (see kernels.inl).
//
// Everything is included before the pragma, so inline functions from headers keep the default
// target (they could otherwise be merged, AVX-512 code and all, into other translation units).
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
#define TOONRAY_ACCEL_HAVE_AVX512 1
#pragma GCC push_options
#pragma GCC target("avx2,bmi,bmi2,lzcnt,popcnt,avx512f,avx512vl,avx512bw,avx512dq,fma")
#define TOONRAY_ACCEL_AVX2 1
#define TOONRAY_ACCEL_FMA 1  // box tests only; fp-contract=off keeps it out of everything else

namespace toonray::accel {
namespace avx512 {
namespace {  // internal linkage: the instruction sets' copies must never be merged
#include "toonray/accel/simd8.inl"
#include "toonray/accel/kernels.inl"
}  // namespace
}  // namespace avx512
}  // namespace toonray::accel

#pragma GCC pop_options
#endif

namespace toonray::accel {

const KernelTable* kernels_avx512() {
#ifdef TOONRAY_ACCEL_HAVE_AVX512
    static const KernelTable table{"avx512", &avx512::intersect1, &avx512::occluded1, &avx512::intersect_tile};
    return &table;
#else
    return nullptr;
#endif
}

}  // namespace toonray::accel
