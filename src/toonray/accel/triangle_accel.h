#pragma once
/// Closest-hit and occlusion ray queries against a triangle mesh: the binary BVH of bvh.h,
/// collapsed into an 8-wide tree traversed with SIMD (AVX2 when the CPU has it, SSE4.2
/// otherwise), single rays and coherent tiles of rays from one origin; and against instances of
/// other meshes placed by transforms (a two-level BVH). docs/accel.md describes the design.

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "toonray/accel/bvh.h"
#include "toonray/accel/ray.h"
#include "toonray/accel/wide_bvh.h"
#include "toonray/core/affine.h"
#include "toonray/core/math.h"

namespace toonray {

class TriangleAccel;

/// A mesh placed in the world, for TriangleAccel::set_instances.
struct AccelInstance {
    /// Built over the mesh's triangles in object space, with no instances of its own. Shared:
    /// every instance of a mesh uses its one tree.
    std::shared_ptr<const TriangleAccel> mesh;
    Affine3 to_world;  ///< object space to world space; must be invertible
};

/// Bytes an instance costs the accelerator, beside its mesh's tree, which all instances share:
/// its record for traversal (64: the inverse transform in float, the tree, the rank), its
/// transform (96, doubles, to rebuild the top level), its slot and mesh index (8) and its share
/// of the top level's wide nodes (about 52 with 10,000 instances): checked by
/// Instances.MemoryPerInstanceIsSmall.
inline constexpr std::size_t kBytesPerInstance = 224;

class TriangleAccel {
public:
    /// Largest tile intersect_tile takes.
    static constexpr int kTileSize = 16;

    TriangleAccel() = default;
    TriangleAccel(const TriangleAccel& other);
    TriangleAccel& operator=(const TriangleAccel& other);
    TriangleAccel(TriangleAccel&&) noexcept = default;
    TriangleAccel& operator=(TriangleAccel&&) noexcept = default;
    ~TriangleAccel() = default;

    /// Builds the BVH over the triangles and copies them in leaf order for traversal.
    void build(std::span<const Vec3f> positions, std::span<const std::array<std::uint32_t, 3>> tris,
               const Bvh::Config& config = {});
    /// Updates for moved vertices with the same triangles (topology kept).
    void refit(std::span<const Vec3f> positions,
               std::span<const std::array<std::uint32_t, 3>> tris);

    /// Places instances of other meshes beside the triangles of build() (a two-level BVH: a
    /// top level over the world boxes of the instances, and of the own triangles when there
    /// are any; below it each mesh's own tree, traced with the ray taken into its object
    /// space, in double and rounded once, so that every CPU finds the same hits). Replaces any
    /// earlier instances; none removes them. Queries then report Hit::instance. Throws Error
    /// for a missing mesh, a mesh with instances of its own or a transform that cannot be
    /// inverted.
    void set_instances(std::span<const AccelInstance> instances, const Bvh::Config& config = {});
    /// New transforms for the instances of set_instances, in their order (an animation's next
    /// pose): the top level is refitted, the meshes' trees are kept.
    void move_instances(std::span<const Affine3> to_world);
    [[nodiscard]] std::size_t instance_count() const { return instance_count_; }

    /// Closest hit with 0 < t < ray.tmax. Returns true and fills `hit` when there is one.
    /// Among hits at the same distance the lowest triangle index wins, whatever the tree; with
    /// instances, the own triangles first, then the lowest instance (Hit).
    bool intersect(const Ray& ray, Hit& hit) const;

    /// Whether any triangle is hit with 0 < t < ray.tmax: exactly when intersect(ray, hit) would
    /// return true (the same triangle test), but traversal stops at the first such hit, in no
    /// particular order. For shadow rays.
    [[nodiscard]] bool occluded(const Ray& ray) const;

    /// The closest hits of a grid of rays from one origin: `dirs` holds width x height
    /// directions row by row, and hits/found receive, for each, exactly what
    /// intersect(Ray{origin, dir, tmax}, hit) gives (misses get Hit{} and false). Neighbouring
    /// rays should be coherent (a pinhole camera's): each kTileSize x kTileSize tile is
    /// traversed once, as a frustum of 4 x 2 ray packets (larger grids are cut into tiles),
    /// unless `ray_angle2` says the rays are sparse. `ray_angle2` is the squared angle between
    /// neighbouring rays, infinite for rays too sparse for any tree. With instances, the groups
    /// that reach an instance go through its tree as packets only when they are dense for it
    /// (WideBvh::dense_for, with a negative `ray_angle2` taken from the first two rays;
    /// otherwise each crosses it alone, and only the top level is traversed by groups).
    /// Without, a `ray_angle2` of zero or more that is sparse for the tree sends each ray
    /// through it alone, and a negative one always packets. Only speed depends on it.
    void intersect_tile(const Vec3f& origin, const Vec3f* dirs, int width, int height, Hit* hits,
                        bool* found, float tmax = std::numeric_limits<float>::infinity(),
                        float ray_angle2 = -1.0f) const;

    /// The binary tree over the own triangles (not the instances).
    [[nodiscard]] const Bvh& bvh() const { return bvh_; }
    /// The own triangles (build()), not the instances'.
    [[nodiscard]] std::size_t triangle_count() const { return triangle_count_; }
    /// Bytes held (binary tree, wide tree, triangle blocks), with instances their level and
    /// each distinct mesh's tree once.
    [[nodiscard]] std::size_t memory_bytes() const;
    /// Of memory_bytes, the instance level's (records, slots, top-level trees).
    [[nodiscard]] std::size_t instance_level_bytes() const;

private:
    void build_instance_level();

    Bvh bvh_;
    // Held by pointer: the instance level's record of the own triangles points to it, so it
    // must not move with the accelerator.
    std::unique_ptr<accel::WideBvh> wide_ = std::make_unique<accel::WideBvh>();
    accel::WideBvh::CollapseCosts collapse_;
    std::size_t triangle_count_ = 0;

    // Instances (empty without).
    std::unique_ptr<accel::InstanceLevel> level_;
    Bvh::Config top_config_;
    std::vector<std::shared_ptr<const TriangleAccel>> meshes_;  ///< distinct, in first use
    std::vector<std::uint32_t> instance_mesh_;                  ///< per instance, into meshes_
    std::vector<Affine3> to_world_;                             ///< per instance
    std::size_t instance_count_ = 0;
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
