#pragma once
/// Closest-hit and occlusion ray queries against a triangle mesh: the binary BVH of bvh.h,
/// collapsed into an 8-wide tree traversed with SIMD (AVX2 when the CPU has it, SSE4.2
/// otherwise), single rays and coherent tiles of rays from one origin. docs/accel.md describes
/// the design.

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <string_view>
#include <vector>

#include "toonray/accel/bvh.h"
#include "toonray/accel/ray.h"
#include "toonray/accel/wide_bvh.h"
#include "toonray/core/math.h"

namespace toonray {

class TriangleAccel {
public:
    /// Largest tile intersect_tile takes.
    static constexpr int kTileSize = 16;

    /// Builds the BVH over the triangles and copies them in leaf order for traversal.
    void build(std::span<const Vec3f> positions, std::span<const std::array<std::uint32_t, 3>> tris,
               const Bvh::Config& config = {});
    /// Updates for moved vertices with the same triangles (topology kept).
    void refit(std::span<const Vec3f> positions,
               std::span<const std::array<std::uint32_t, 3>> tris);

    /// Closest hit with 0 < t < ray.tmax. Returns true and fills `hit` when there is one.
    /// Among hits at the same distance the lowest triangle index wins, whatever the tree.
    bool intersect(const Ray& ray, Hit& hit) const;

    /// Whether any triangle is hit with 0 < t < ray.tmax: exactly when intersect(ray, hit) would
    /// return true (the same triangle test), but traversal stops at the first such hit, in no
    /// particular order. For shadow rays.
    [[nodiscard]] bool occluded(const Ray& ray) const;

    /// The closest hits of a grid of rays from one origin: `dirs` holds width x height
    /// directions row by row, and hits/found receive, for each, exactly what
    /// intersect(Ray{origin, dir, tmax}, hit) gives (misses get Hit{} and false). Neighbouring
    /// rays should be coherent (a pinhole camera's): each kTileSize x kTileSize tile is
    /// traversed once, as a frustum of 4 x 2 ray packets (larger grids are cut into tiles).
    void intersect_tile(const Vec3f& origin, const Vec3f* dirs, int width, int height, Hit* hits,
                        bool* found, float tmax = std::numeric_limits<float>::infinity()) const;

    [[nodiscard]] const Bvh& bvh() const { return bvh_; }
    [[nodiscard]] std::size_t triangle_count() const { return triangle_count_; }
    /// Bytes held (binary tree, wide tree, triangle blocks).
    [[nodiscard]] std::size_t memory_bytes() const;

private:
    Bvh bvh_;
    accel::WideBvh wide_;
    accel::WideBvh::CollapseCosts collapse_;
    std::size_t triangle_count_ = 0;
};

/// The watertight ray/triangle test the traversal uses (Woop et al. 2013): 0 < t < ray.tmax.
/// Exposed for brute-force reference checks in tests.
bool intersect_triangle(const Ray& ray, const Vec3f& v0, const Vec3f& v1, const Vec3f& v2, float& t,
                        float& u, float& v);

/// The instruction set the traversal kernels use: "avx2" or "sse4.2". By default the best the
/// CPU supports; the environment variable TOONRAY_ACCEL_ISA=sse4.2 forces the portable one.
const char* accel_isa();
/// Selects the kernels ("avx2", "sse4.2" or "auto"); false when not available here. For tests
/// and benchmarks: results are bit-identical either way.
bool set_accel_isa(std::string_view isa);

}  // namespace toonray
