#pragma once
/// The accelerator as it was before the issue-6 rewrite (commit 8643eb9): binary BVH, binned
/// SAH, scalar watertight traversal. Kept verbatim (namespace toonray::legacy) as the
/// bit-exact reference the new traversal is checked against in accel_embree_compare.

#include "toonray/accel/triangle_accel.h"  // Ray, Hit

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>
#include "toonray/core/bbox.h"
#include "toonray/core/math.h"

namespace toonray::legacy {
/// A binary bounding volume hierarchy that knows nothing about triangles: it is built from
/// boxes and centres, and traversal is left to the caller (see triangle_accel.h).

/// 32 bytes: two nodes share a cache line. Inner nodes have count == 0 and their two children
/// at `first` and `first + 1`; leaves cover prim_indices[first, first + count).
struct BvhNode {
    BBox bounds;
    std::uint32_t first = 0;
    std::uint32_t count = 0;

    [[nodiscard]] bool is_leaf() const { return count != 0; }
};

struct Bvh {
    /// Build settings; defaults suit triangle meshes.
    struct Config {
        int max_leaf_size = 8;           ///< leaves never hold more (the seed used 10)
        int bin_count = 16;              ///< SAH bins per axis
        float traversal_cost = 1.0f;     ///< cost of visiting a node, relative to...
        float intersection_cost = 1.0f;  ///< ...testing one primitive
    };

    std::vector<BvhNode>
        nodes;  ///< nodes[0] is the root; children follow parents; empty if no primitives
    std::vector<std::uint32_t> prim_indices;  ///< primitive ids in leaf order

    /// Builds with binned SAH. Deterministic: the same input gives the same tree.
    [[nodiscard]] static Bvh build(std::span<const BBox> boxes, std::span<const Vec3f> centers,
                                   const Config& config);
    [[nodiscard]] static Bvh build(std::span<const BBox> boxes, std::span<const Vec3f> centers) {
        return build(boxes, centers, Config{});
    }

    /// Recomputes node bounds for moved primitives, keeping the topology (for animation where
    /// only poses change).
    void refit(std::span<const BBox> boxes);

    [[nodiscard]] int depth() const;
};

/// Closest-hit ray queries against a triangle mesh, on top of the generic Bvh.

class TriangleAccel {
public:
    /// Builds the BVH over the triangles and copies them in leaf order for traversal.
    void build(std::span<const Vec3f> positions, std::span<const std::array<std::uint32_t, 3>> tris,
               const Bvh::Config& config = {});
    /// Updates for moved vertices with the same triangles (topology kept).
    void refit(std::span<const Vec3f> positions,
               std::span<const std::array<std::uint32_t, 3>> tris);

    /// Closest hit with 0 < t < ray.tmax. Returns true and fills `hit` when there is one.
    /// Among hits at the same distance the lowest triangle index wins, whatever the tree.
    bool intersect(const Ray& ray, Hit& hit) const;

    [[nodiscard]] const Bvh& bvh() const { return bvh_; }
    [[nodiscard]] std::size_t triangle_count() const { return tris_.size(); }

private:
    struct PackedTriangle {
        Vec3f v0, v1, v2;
    };
    void pack(std::span<const Vec3f> positions, std::span<const std::array<std::uint32_t, 3>> tris);
    template <typename Stack>
    bool traverse(const Ray& ray, Hit& hit, Stack& stack) const;

    Bvh bvh_;
    std::vector<PackedTriangle> tris_;  ///< in bvh_.prim_indices order
    int depth_ = 0;
};

}  // namespace toonray::legacy
