// The traversal kernels for the portable build (x86-64-v2: SSE4.2), 8-wide vectors as pairs of
// SSE registers.
// Every float operation of the triangle tests must round exactly as written, in every build:
// no fused multiply-adds, which -march=native (TOONRAY_NATIVE) would otherwise let GCC form.
#pragma GCC optimize("fp-contract=off")
#include <smmintrin.h>

#include <algorithm>
#include <cstring>
#include <limits>

#include "toonray/accel/kernels.h"
#include "toonray/accel/watertight.h"

namespace toonray::accel {
namespace sse {
namespace {  // internal linkage: the instruction sets' copies must never be merged
#include "toonray/accel/simd8.inl"
#include "toonray/accel/kernels.inl"
}  // namespace
}  // namespace sse

const KernelTable& kernels_sse() {
    static const KernelTable table{"sse4.2", &sse::intersect1, &sse::occluded1, &sse::intersect_tile};
    return table;
}

}  // namespace toonray::accel
