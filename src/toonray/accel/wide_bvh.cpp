#include "toonray/accel/wide_bvh.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>
#include <memory>
#include <utility>

#include "toonray/accel/huge_pages.h"
#include "toonray/core/error.h"

namespace toonray::accel {
namespace {

// The collapse's step for I slots (2..8): the cheapest of I - 1 slots, or of k slots for the
// left child's subtree and I - k for the right's. I is a constant so that the loop unrolls: its
// varying trip count was a mispredicted branch per node and slot count.
template <int I>
void best_in_slots(const std::array<float, 8>& cl, const std::array<float, 8>& cr,
                   std::array<float, 8>& cost, std::array<std::int8_t, 8>& split) {
    float c = cost[I - 2];
    int s = 0;
    for (int k = 1; k < I; ++k) {
        // Selects, not branches: which side wins is data.
        const float v = cl[k - 1] + cr[I - k - 1];
        const bool better = v < c;
        c = better ? v : c;
        s = better ? k : s;
    }
    cost[I - 1] = c;
    split[I - 1] = static_cast<std::int8_t>(s);
}

// Collapses `bvh` into w.nodes (root, depth, max_stack set) and writes the leaves' primitives
// into slot_prim in the order leaves are made, the last of each leaf or'ed with kLeafEnd;
// returns how many slots were used. prim_box(p) is primitive p's box (for leaves spread one
// primitive per slot).
template <class PrimBox>
std::uint32_t collapse(WideBvh& w, const Bvh& bvh, std::span<const float> leaf_areas,
                       const WideBvh::CollapseCosts& costs, PrimBox&& prim_box,
                       std::uint32_t* slot_prim) {
    auto& nodes = w.nodes;
    auto& root = w.root;
    auto& depth = w.depth;
    auto& max_stack = w.max_stack;
    std::uint32_t next_slot = 0;
    auto make_leaf = [&](const BvhNode& leaf) {
        const std::uint32_t first = next_slot;
        for (std::uint32_t i = 0; i < leaf.count; ++i)
            slot_prim[next_slot++] =
                bvh.prim_indices[leaf.first + i] | (i + 1 == leaf.count ? kLeafEnd : 0u);
        return kLeafBit | ((leaf.count <= 15 ? leaf.count : 0u) << kLeafCountShift) | first;
    };
    if (bvh.nodes[0].is_leaf()) {
        root = make_leaf(bvh.nodes[0]);
        return next_slot;
    }
    // Collapse by dynamic programming over the binary tree (Ylitie, Karras and Laine 2017):
    // cost[n][i - 1] is the least SAH cost of representing binary node n's subtree as at most
    // i subtrees side by side (i slots of a wide node), where a wide node costs `node_cost`
    // times its area and a leaf `block_cost` times its area per block of 4 triangles. The
    // greedy alternative (open the largest child until 8) leaves many wide nodes near the
    // leaves with only 2 or 3 children.
    const std::size_t count = bvh.nodes.size();
    // Scratch, every entry written before it is read.
    auto cost = make_huge_array<std::array<float, 8>>(count);
    auto split = make_huge_array<std::array<std::int8_t, 8>>(count);
    // Subtrees cover contiguous ranges of prim_indices; small ones may become one leaf.
    auto first_prim = make_huge_array<std::uint32_t>(count);
    auto prim_count = make_huge_array<std::uint32_t>(count);
    auto flags = make_huge_array<std::uint8_t>(count);  // kAsLeaf, kSpread
    constexpr std::uint8_t kAsLeaf = 1, kSpread = 2;
    auto range = [&](std::uint32_t n) {
        return BvhNode{bvh.nodes[n].bounds, first_prim[n], prim_count[n]};
    };
    for (std::size_t n = count; n-- > 0;) {
        const BvhNode& b = bvh.nodes[n];
        const float area = b.bounds.half_area();
        if (b.is_leaf()) {
            first_prim[n] = b.first;
            prim_count[n] = b.count;
            flags[n] = kAsLeaf;
            cost[n].fill(costs.block * area *
                         static_cast<float>((b.count + costs.leaf_width - 1) / costs.leaf_width));
            // With as many slots as it has triangles, a small leaf may rather spread them
            // over the slots, one leaf each, so that boxes cull them one by one.
            if (b.count >= 2 && b.count <= 8) {
                float singles = 0.0f;
                for (std::uint32_t i = 0; i < b.count; ++i)
                    singles += costs.block * leaf_areas[b.first + i];
                if (singles < cost[n][0]) {
                    flags[n] |= kSpread;
                    for (std::uint32_t i = b.count; i <= 8; ++i) cost[n][i - 1] = singles;
                }
            }
            continue;
        }
        first_prim[n] = first_prim[b.first];
        prim_count[n] = prim_count[b.first] + prim_count[b.first + 1];
        flags[n] = 0;
        const auto& cl = cost[b.first];
        const auto& cr = cost[b.first + 1];
        // The minima below are selects, not branches: which side wins is data, and a branch
        // on it would be mispredicted about as often as not.
        float best = std::numeric_limits<float>::infinity();
        int best_k = 1;
        for (int k = 1; k < 8; ++k) {
            const float c = cl[k - 1] + cr[7 - k];
            const bool better = c < best;
            best = better ? c : best;
            best_k = better ? k : best_k;
        }
        cost[n][0] = costs.node * area + best;
        split[n][0] = static_cast<std::int8_t>(best_k);
        if (prim_count[n] <= costs.merge_leaf) {
            float leaf =
                costs.block * area *
                static_cast<float>((prim_count[n] + costs.leaf_width - 1) / costs.leaf_width);
            if (leaf <= cost[n][0]) {
                cost[n][0] = leaf;
                flags[n] |= kAsLeaf;
            }
        }
        [&]<int... I>(std::integer_sequence<int, I...>) {
            (best_in_slots<I + 2>(cl, cr, cost[n], split[n]), ...);
        }
        (std::make_integer_sequence<int, 7>{});
    }
    // The children that binary node n becomes with at most i slots: leaves (triangle ranges)
    // and inner nodes (binary node ids).
    struct Slot {
        BvhNode leaf;
        std::uint32_t inner;  // binary node, or kNoIndex for a leaf
    };
    auto gather = [&](auto&& self, std::uint32_t n, int i, Slot* out, int& len) -> void {
        const BvhNode& b = bvh.nodes[n];
        if (b.is_leaf()) {
            if ((flags[n] & kSpread) && static_cast<std::uint32_t>(i) >= b.count) {
                for (std::uint32_t k = 0; k < b.count; ++k)
                    out[len++] = {BvhNode{prim_box(bvh.prim_indices[b.first + k]), b.first + k, 1},
                                  kNoIndex};
            } else {
                out[len++] = {b, kNoIndex};
            }
            return;
        }
        while (i > 1 && split[n][i - 1] == 0) --i;
        if (i <= 1) {
            out[len++] = {range(n), (flags[n] & kAsLeaf) ? kNoIndex : n};
            return;
        }
        const int k = split[n][i - 1];
        self(self, b.first, k, out, len);
        self(self, b.first + 1, i - k, out, len);
    };

    if (flags[0] & kAsLeaf) {
        root = make_leaf(range(0));
        return next_slot;
    }
    struct Item {
        std::uint32_t binary, wide;
        int level;
    };
    std::vector<Item> todo{{0, 0, 1}};
    nodes.emplace_back();
    root = 0;
    while (!todo.empty()) {
        Item item = todo.back();
        todo.pop_back();
        depth = std::max(depth, item.level);
        Slot ch[8];
        int n = 0;
        const std::uint32_t first = bvh.nodes[item.binary].first;
        const int k = split[item.binary][0];
        gather(gather, first, k, ch, n);
        gather(gather, first + 1, 8 - k, ch, n);
        WideNode w;
        for (int a = 0; a < 3; ++a) {
            std::fill(std::begin(w.lo[a]), std::end(w.lo[a]),
                      std::numeric_limits<float>::infinity());
            std::fill(std::begin(w.hi[a]), std::end(w.hi[a]),
                      -std::numeric_limits<float>::infinity());
        }
        std::fill(std::begin(w.child), std::end(w.child), kEmptyChild);
        std::fill(std::begin(w.pad), std::end(w.pad), 0u);
        for (int i = 0; i < n; ++i) {
            const BBox& box = ch[i].leaf.bounds;
            for (int a = 0; a < 3; ++a) {
                w.lo[a][i] = box.lo[a];
                w.hi[a][i] = box.hi[a];
            }
            if (ch[i].inner == kNoIndex) {
                w.child[i] = make_leaf(ch[i].leaf);
            } else {
                w.child[i] = static_cast<std::uint32_t>(nodes.size());
                nodes.emplace_back();
                todo.push_back({ch[i].inner, w.child[i], item.level + 1});
            }
            w.pad[0] |= 1u << i;  // valid children
        }
        nodes[item.wide] = w;
    }
    // Traversal pushes at most 7 entries per level.
    max_stack = 8 * static_cast<std::size_t>(depth) + 8;
    return next_slot;
}

}  // namespace

void WideBvh::build(const Bvh& bvh, std::span<const float> leaf_areas,
                    std::span<const Vec3f> positions,
                    std::span<const std::array<std::uint32_t, 3>> tris,
                    const CollapseCosts& costs) {
    nodes.clear();
    blocks.clear();
    root = kEmptyChild;
    depth = 0;
    max_stack = 8;
    centre = Vec3f(0.0f);
    radius = 0.0f;
    if (bvh.nodes.empty()) return;
    centre = bvh.nodes[0].bounds.center();
    radius = 0.5f * length(bvh.nodes[0].bounds.extent());

    std::size_t leaves = 0;
    for (const BvhNode& n : bvh.nodes) leaves += n.is_leaf();
    const std::size_t tri_count = bvh.prim_indices.size();
    if (tri_count >= kMaxSlots) throw Error("too many triangles for the BVH (at most 134,217,727)");
    blocks.clear();
    reserve_huge(blocks, (tri_count + 3) / 4 + 2);
    reserve_huge(nodes, leaves / 4 + 1);
    TriBlock empty;
    {
        const float nan = std::numeric_limits<float>::quiet_NaN();
        for (auto& corner : empty.v)
            for (auto& axis : corner) std::fill(std::begin(axis), std::end(axis), nan);
        std::fill(std::begin(empty.prim), std::end(empty.prim), kNoIndex);
    }
    // Leaves take their slots in the order they are made (depth-first through the wide tree);
    // the triangles are copied into the blocks afterwards, block by block in parallel: reading
    // their corners is the slow part (gathers through the index buffer).
    auto slot_prim = make_huge_array<std::uint32_t>(tri_count);
    // A triangle's box from its corners: only spread leaves need it (one slot per triangle), so
    // it is computed here rather than kept for every triangle.
    auto tri_box = [&](std::uint32_t p) {
        BBox box;
        for (std::uint32_t v : tris[p]) box.extend(positions[v]);
        return box;
    };
    const std::uint32_t next_slot = collapse(*this, bvh, leaf_areas, costs, tri_box, &slot_prim[0]);
    // Fills the blocks, plus two empty ones after the last (8-wide loads may read up to two
    // blocks past a leaf).
    const std::size_t used = (next_slot + 3) / 4;
    blocks.resize(used + 2);
    blocks[used] = empty;
    blocks[used + 1] = empty;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, used, 2048), [&](const auto& r) {
        for (std::size_t b = r.begin(); b != r.end(); ++b) {
            TriBlock block = empty;
            const std::size_t lanes = std::min<std::size_t>(4, next_slot - 4 * b);
            for (std::size_t l = 0; l < lanes; ++l) {
                const std::uint32_t slot = slot_prim[4 * b + l];
                const std::uint32_t p = slot & ~kLeafEnd;
                for (int c = 0; c < 3; ++c) {
                    const Vec3f& v = positions[tris[p][c]];
                    block.v[c][0][l] = v.x;
                    block.v[c][1][l] = v.y;
                    block.v[c][2][l] = v.z;
                }
                block.prim[l] = slot;
            }
            blocks[b] = block;
        }
    });
}

void WideBvh::build_over_boxes(const Bvh& bvh, std::span<const float> leaf_areas,
                               std::span<const BBox> boxes, const CollapseCosts& costs,
                               std::vector<std::uint32_t>& slots) {
    nodes.clear();
    blocks.clear();
    root = kEmptyChild;
    depth = 0;
    max_stack = 8;
    slots.clear();
    if (bvh.nodes.empty()) return;
    if (bvh.prim_indices.size() >= kMaxSlots) throw Error("too many boxes for the BVH");
    slots.resize(bvh.prim_indices.size());
    slots.resize(collapse(
        *this, bvh, leaf_areas, costs, [&](std::uint32_t p) { return boxes[p]; }, slots.data()));
}

bool WideBvh::dense_for(const Vec3f& origin, float ray_angle2) const {
    const Vec3f d = origin - centre;
    const float dist2 = dot(d, d), r2 = radius * radius;
    if (!(dist2 > r2)) return true;  // at or inside the sphere (or NaN)
    const float rays = 3.14159265f * r2 / (dist2 * ray_angle2);
    return rays >= static_cast<float>(blocks.size());
}

}  // namespace toonray::accel
