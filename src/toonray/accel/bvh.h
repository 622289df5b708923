#pragma once
/// A binary bounding volume hierarchy that knows nothing about triangles: it is built from
/// boxes and centres, and traversal is left to the caller (see triangle_accel.h).

#include <cstdint>
#include <span>
#include <vector>

#include "toonray/core/bbox.h"

namespace toonray {

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
        int max_leaf_size = 8;      ///< leaves never hold more (the seed used 10)
        int bin_count = 16;         ///< SAH bins per axis
        float traversal_cost = 1.0f;  ///< cost of visiting a node, relative to...
        float intersection_cost = 1.0f;  ///< ...testing one primitive
    };

    std::vector<BvhNode> nodes;  ///< nodes[0] is the root; children follow parents; empty if no primitives
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

}  // namespace toonray
