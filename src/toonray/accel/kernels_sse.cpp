// The traversal kernels for the portable build, 8-wide vectors as pairs of SSE registers: SSE4.2
// on x86-64 (x86-64-v2), and the same intrinsics through SIMDe on other CPUs (aarch64), where
// they keep x86's exact results (core/simd_sse.h).
#include <algorithm>
#include <cstring>
#include <limits>

#include "toonray/accel/kernels.h"
#include "toonray/accel/watertight.h"
#include "toonray/core/simd_sse.h"

namespace toonray::accel {
namespace sse {
namespace {  // internal linkage: the instruction sets' copies must never be merged
#include "toonray/accel/simd8.inl"
#include "toonray/accel/kernels.inl"
}  // namespace
}  // namespace sse

const KernelTable& kernels_sse() {
    static const KernelTable table{"sse4.2",
                                   &sse::intersect1,
                                   &sse::occluded1,
                                   &sse::intersect_tile,
                                   &sse::intersect1_instances,
                                   &sse::occluded1_instances,
                                   &sse::intersect_tile_instances};
    return table;
}

}  // namespace toonray::accel
