// The traversal kernels compiled for AVX-512 (F, VL, BW, DQ): the same 8-wide code as
// kernels_avx2.cpp, which the compiler can then write with mask registers and three-input
// logic. Chosen at run time when the CPU has it. CMake compiles this file, and only this file,
// with the AVX2 options plus -mavx512f -mavx512vl -mavx512bw -mavx512dq (top-level
// CMakeLists.txt). FMA only in the box tests (see kernels.inl).
//
// Why compiling the whole file with these options cannot put AVX instructions into code that
// other translation units run on CPUs without them: the kernels are in an anonymous namespace
// (internal linkage), so no other object file can link to them, and the only function this
// file exports, kernels_avx512(), returns the address of a constant-initialised table (no
// vector code) and is called only after the CPU check. What remains are inline functions from
// the headers (std::, Vec3f, watertight.h), which the compiler may emit here as weak symbols
// that the linker could pick for every translation unit. The CTest test accel_isa_symbols
// (cmake/check_isa_symbols.cmake) checks with nm that this object defines no weak or global
// symbol but kernels_avx512() and the table's guard variable; a header change that breaks this
// fails that test instead of crashing on an older CPU.
#include <algorithm>
#include <cstring>
#include <limits>

#include "toonray/accel/kernels.h"
#include "toonray/accel/watertight.h"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>

#define TOONRAY_ACCEL_HAVE_AVX512 1
#define TOONRAY_ACCEL_AVX2 1
#define TOONRAY_ACCEL_FMA 1  // box tests only (see kernels.inl)

namespace toonray::accel {
namespace avx512 {
namespace {  // internal linkage: the instruction sets' copies must never be merged
#include "toonray/accel/simd8.inl"
#include "toonray/accel/kernels.inl"
}  // namespace
}  // namespace avx512
}  // namespace toonray::accel
#endif

namespace toonray::accel {

const KernelTable* kernels_avx512() {
#ifdef TOONRAY_ACCEL_HAVE_AVX512
    static const KernelTable table{"avx512",
                                   &avx512::intersect1,
                                   &avx512::occluded1,
                                   &avx512::intersect_tile,
                                   &avx512::intersect1_instances,
                                   &avx512::occluded1_instances,
                                   &avx512::intersect_tile_instances};
    return &table;
#else
    return nullptr;
#endif
}

}  // namespace toonray::accel
