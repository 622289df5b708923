#pragma once
/// A binary bounding volume hierarchy that knows nothing about triangles: it is built from
/// boxes, and traversal is left to the caller (see triangle_accel.h, which collapses it into an
/// 8-wide tree for SIMD traversal).

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "toonray/core/bbox.h"
#include "toonray/core/math.h"

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
    /// Build settings; defaults suit triangle meshes traced with SIMD leaf tests.
    struct Config {
        int max_leaf_size = 8;           ///< leaves never hold more (clamped to [1, 128])
        int bin_count = 16;              ///< SAH bins per axis (clamped to [2, 64])
        float traversal_cost = 1.0f;     ///< cost of visiting a node, relative to...
        float intersection_cost = 1.0f;  ///< ...testing one block of `block_size` primitives
        int block_size =
            2;  ///< primitives tested together (the leaf test's SIMD width; a power of two)

        bool operator==(const Config&) const = default;
    };

    std::vector<BvhNode>
        nodes;  ///< nodes[0] is the root; children follow parents; empty if no primitives
    std::vector<std::uint32_t> prim_indices;  ///< primitive ids in leaf order

    /// Builds with binned SAH on the boxes' centres: all three axes binned in one pass over the
    /// primitives, the large top levels binned in parallel (TBB), partitions in place, and subtrees
    /// built as parallel tasks. Deterministic: the same input gives the same tree for any thread
    /// count (work is cut at fixed sizes, merges are exact min/max and sums, and each subtree
    /// task numbers its nodes in a chunk of its own; the chunks are joined in the order of their
    /// first primitive, not of when they were made).
    [[nodiscard]] static Bvh build(std::span<const BBox> boxes, const Config& config) {
        return build(boxes, config, nullptr);
    }
    [[nodiscard]] static Bvh build(std::span<const BBox> boxes) { return build(boxes, Config{}); }
    /// The same, and when `leaf_areas` is not null, fills it with the half area of each
    /// primitive's box in leaf order (leaf_areas[i] = boxes[prim_indices[i]].half_area(), bit
    /// for bit), which the leaves write as they are made: a wide collapse reads it in order
    /// instead of gathering boxes.
    [[nodiscard]] static Bvh build(std::span<const BBox> boxes, const Config& config,
                                   std::vector<float>* leaf_areas);
    /// The same over triangles, their boxes computed as it goes (the same boxes, bit for bit,
    /// as BBox::extend over the corners gives): one pass over the triangles fewer.
    [[nodiscard]] static Bvh build(std::span<const Vec3f> positions,
                                   std::span<const std::array<std::uint32_t, 3>> tris,
                                   const Config& config, std::vector<float>* leaf_areas);

    /// Recomputes node bounds for moved primitives, keeping the topology (for animation where
    /// only poses change).
    void refit(std::span<const BBox> boxes);

    [[nodiscard]] int depth() const;
};

}  // namespace toonray
