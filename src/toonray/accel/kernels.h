#pragma once
/// The traversal kernels per instruction set (internal to the accel module): kernels_sse.cpp
/// (the portable build: SSE4.2, or SIMDe off x86), kernels_avx2.cpp and kernels_avx512.cpp (x86
/// only, with their instruction sets from CMake, chosen at run time when the CPU has them). All
/// compute bit-identical results.

#include <cstdint>

#include "toonray/accel/ray.h"
#include "toonray/accel/wide_bvh.h"

namespace toonray::accel {

/// A pending subtree of tile traversal: the groups of rays that may hit it.
struct TileEntry {
    std::uint32_t ref;
    std::uint32_t groups;
    float tnear;
};

struct KernelTable {
    const char* name;
    /// Closest hit of one ray; `stack` holds WideBvh::max_stack entries.
    bool (*intersect1)(const WideBvh& w, const Ray& ray, Hit& hit, std::uint64_t* stack);
    /// Whether one ray hits any triangle with 0 < t < ray.tmax; `stack` as for intersect1.
    bool (*occluded1)(const WideBvh& w, const Ray& ray, std::uint64_t* stack);
    /// Closest hits of a width x height (<= 16 x 16) row-major tile of rays from one origin.
    void (*intersect_tile)(const WideBvh& w, const Vec3f& origin, const Vec3f* dirs, int width,
                           int height, float tmax, Hit* hits, bool* found, TileEntry* stack,
                           std::uint64_t* stack1);
    /// The same three through an instance level: `stack` has lv.tree.max_stack entries and
    /// `bottom` lv.bottom_stack (tiles: `stack` and `stack1` lv.tree.max_stack, `bottom` and
    /// `bottom1` lv.bottom_stack).
    bool (*intersect1_instances)(const InstanceLevel& lv, const Ray& ray, Hit& hit,
                                 std::uint64_t* stack, std::uint64_t* bottom);
    bool (*occluded1_instances)(const InstanceLevel& lv, const Ray& ray, std::uint64_t* stack,
                                std::uint64_t* bottom);
    /// `ray_angle2`: the squared angle between neighbouring rays, for WideBvh::dense_for; negative: the
    /// angle between the first two rays; infinite: every record's tree ray by ray.
    void (*intersect_tile_instances)(const InstanceLevel& lv, const Vec3f& origin,
                                     const Vec3f* dirs, int width, int height, float tmax,
                                     float ray_angle2, Hit* hits, bool* found, TileEntry* stack,
                                     std::uint64_t* stack1, TileEntry* bottom,
                                     std::uint64_t* bottom1);
};

const KernelTable& kernels_sse();
/// Null when this build has no AVX2 kernels.
const KernelTable* kernels_avx2();
/// Null when this build has no AVX-512 kernels.
const KernelTable* kernels_avx512();

}  // namespace toonray::accel
