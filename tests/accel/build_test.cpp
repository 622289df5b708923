// The BVH builder's own guarantees: one tree however its nodes were made, the leaf-order box
// areas it hands the wide collapse, exact partitions on non-finite input, huge-page buffers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "accel/soup.h"
#include "toonray/accel/bvh.h"
#include "toonray/accel/huge_pages.h"
#include "toonray/accel/triangle_accel.h"

using namespace toonray;

namespace {

using test_support::random_soup;
using test_support::Soup;

std::vector<BBox> boxes_of(const Soup& s) {
    std::vector<BBox> boxes(s.tris.size());
    for (std::size_t i = 0; i < s.tris.size(); ++i)
        for (std::uint32_t v : s.tris[i]) boxes[i].extend(s.positions[v]);
    return boxes;
}

// Every node is reached exactly once from the root, children after their parent, and the
// leaves cover the primitive slots [0, n) once each, in order.
void expect_one_tree(const Bvh& bvh, std::size_t prims) {
    ASSERT_EQ(bvh.prim_indices.size(), prims);
    std::vector<int> reached(bvh.nodes.size(), 0);
    std::vector<std::uint32_t> stack{0};
    std::uint32_t next_slot = 0;
    while (!stack.empty()) {
        const std::uint32_t i = stack.back();
        stack.pop_back();
        ASSERT_LT(i, bvh.nodes.size());
        ASSERT_EQ(reached[i]++, 0) << "node " << i;
        const BvhNode& node = bvh.nodes[i];
        if (node.is_leaf()) {
            ASSERT_EQ(node.first, next_slot) << "node " << i;
            next_slot += node.count;
            continue;
        }
        ASSERT_GT(node.first, i);
        stack.push_back(node.first + 1);
        stack.push_back(node.first);
    }
    EXPECT_EQ(next_slot, prims);
    for (std::size_t i = 0; i < reached.size(); ++i) EXPECT_EQ(reached[i], 1) << "node " << i;
    std::vector<int> seen(prims, 0);
    for (std::uint32_t p : bvh.prim_indices) {
        ASSERT_LT(p, prims);
        seen[p]++;
    }
    for (std::size_t p = 0; p < prims; ++p) ASSERT_EQ(seen[p], 1) << "primitive " << p;
}

// The same nodes (bounds bit for bit) and primitive order.
void expect_same_tree(const Bvh& a, const Bvh& b) {
    ASSERT_EQ(a.prim_indices, b.prim_indices);
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    EXPECT_EQ(std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(BvhNode)), 0);
}

}  // namespace

TEST(Build, SubtreesBuiltApartJoinIntoOneTree) {
    // Large enough for subtrees built as tasks of their own (each into its own node chunk).
    Soup s = random_soup(120000, 5, 0.01f);
    const std::vector<BBox> boxes = boxes_of(s);
    const Bvh bvh = Bvh::build(boxes);
    expect_one_tree(bvh, boxes.size());
}

TEST(Build, LeafAreasAreTheBoxesInLeafOrder) {
    for (int count : {1, 7, 3000, 50000}) {  // a single leaf, small, serial, parallel top levels
        Soup s = random_soup(count, 17, 0.05f);
        const std::vector<BBox> boxes = boxes_of(s);
        std::vector<float> areas;
        const Bvh with = Bvh::build(boxes, Bvh::Config{}, &areas);
        const Bvh without = Bvh::build(boxes);
        expect_same_tree(with, without);
        ASSERT_EQ(areas.size(), boxes.size());
        for (std::size_t i = 0; i < areas.size(); ++i) {
            const float expected = boxes[with.prim_indices[i]].half_area();
            ASSERT_EQ(std::memcmp(&areas[i], &expected, sizeof(float)), 0) << "slot " << i;
        }
    }
}

TEST(Build, FromTrianglesIsFromTheirBoxes) {
    // The same tree, node bounds and leaf areas bit for bit, also with signed zeros, NaN and
    // infinite corners (where std::min and _mm_min_ps differ unless their operands are swapped).
    Soup s = random_soup(40000, 31, 0.02f);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    for (std::size_t v = 0; v < s.positions.size(); v += 53) s.positions[v].y = -0.0f;
    for (std::size_t v = 1; v < s.positions.size(); v += 59) s.positions[v].y = 0.0f;
    for (std::size_t v = 2; v < s.positions.size(); v += 211) s.positions[v].z = nan;
    for (std::size_t v = 3; v < s.positions.size(); v += 307) s.positions[v].x = -inf;
    std::vector<float> from_boxes_areas, from_tris_areas;
    const Bvh from_boxes = Bvh::build(boxes_of(s), Bvh::Config{}, &from_boxes_areas);
    const Bvh from_tris = Bvh::build(s.positions, s.tris, Bvh::Config{}, &from_tris_areas);
    expect_same_tree(from_tris, from_boxes);
    ASSERT_EQ(from_tris_areas.size(), from_boxes_areas.size());
    EXPECT_EQ(std::memcmp(from_tris_areas.data(), from_boxes_areas.data(),
                          from_tris_areas.size() * sizeof(float)),
              0);
}

TEST(Build, NonFiniteCoordinatesStillPartitionExactly) {
    // Partitions move primitives to where the bin counts say each side starts; a primitive
    // counted on one side and moved to the other would overwrite another. NaN and infinite
    // corners must therefore land on the same side in both, serial and parallel.
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    for (int count : {2000, 70000}) {
        Soup s = random_soup(count, 23, 0.02f);
        for (std::size_t v = 0; v < s.positions.size(); v += 97) s.positions[v].x = nan;
        for (std::size_t v = 50; v < s.positions.size(); v += 131) s.positions[v].y = inf;
        for (std::size_t v = 70; v < s.positions.size(); v += 157) s.positions[v].z = -inf;
        // Corners at -inf and +inf on one axis: a NaN centre there, while the other centres
        // keep the bounds finite.
        for (std::size_t t = 30; t < s.tris.size(); t += 89) {
            s.positions[s.tris[t][0]].x = -inf;
            s.positions[s.tris[t][1]].x = inf;
        }
        const std::vector<BBox> boxes = boxes_of(s);
        const Bvh bvh = Bvh::build(boxes);
        expect_one_tree(bvh, boxes.size());
        TriangleAccel accel;
        accel.build(s.positions, s.tris);
        Hit hit;
        accel.intersect(Ray{{0.0f, 0.0f, -5.0f}, {0.0f, 0.0f, 1.0f}}, hit);  // must not crash
    }
}

TEST(Build, EveryNodeIsTheBoxOfItsPrimitives) {
    // A node's bounds come from the bins of its parent's split, before the partition moves any
    // primitive: they are exactly the union of the node's primitives' boxes only when the
    // partition put exactly the primitives the bins counted on each side. Small (serial),
    // parallel top levels, and clustered (long runs on one side, misplaced ones in bursts).
    for (int count : {3000, 70000}) {
        for (float size : {0.02f, 0.3f}) {
            Soup s = random_soup(count, 41, size);
            const std::vector<BBox> boxes = boxes_of(s);
            const Bvh bvh = Bvh::build(boxes);
            expect_one_tree(bvh, boxes.size());
            // Refitting sets every node to the union of its primitives' boxes.
            Bvh refitted = bvh;
            refitted.refit(boxes);
            for (std::size_t i = 0; i < bvh.nodes.size(); ++i)
                ASSERT_EQ(
                    std::memcmp(&refitted.nodes[i].bounds, &bvh.nodes[i].bounds, sizeof(BBox)), 0)
                    << "node " << i << " of " << count << " primitives";
        }
    }
}

TEST(Build, TheTreeDoesNotDependOnThePrimitivesOrder) {
    // Bins and the children's centre bounds are minima, maxima and counts, whatever order the
    // partitions leave the primitives in: the same boxes in another order give the same nodes,
    // and each leaf the same primitives.
    for (int count : {3000, 70000}) {
        Soup s = random_soup(count, 43, 0.05f);
        const std::vector<BBox> boxes = boxes_of(s);
        std::vector<std::uint32_t> order(boxes.size());
        for (std::size_t i = 0; i < order.size(); ++i)
            order[i] = static_cast<std::uint32_t>((i * 7919) % order.size());  // 7919 is prime
        std::vector<BBox> shuffled(boxes.size());
        for (std::size_t i = 0; i < order.size(); ++i) shuffled[i] = boxes[order[i]];
        const Bvh a = Bvh::build(boxes), b = Bvh::build(shuffled);
        ASSERT_EQ(a.nodes.size(), b.nodes.size());
        ASSERT_EQ(std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(BvhNode)), 0)
            << count << " primitives";
        for (const BvhNode& leaf : a.nodes) {
            if (!leaf.is_leaf()) continue;
            std::vector<std::uint32_t> in_a, in_b;
            for (std::uint32_t k = leaf.first; k < leaf.first + leaf.count; ++k) {
                in_a.push_back(a.prim_indices[k]);
                in_b.push_back(order[b.prim_indices[k]]);
            }
            std::sort(in_a.begin(), in_a.end());
            std::sort(in_b.begin(), in_b.end());
            ASSERT_EQ(in_a, in_b);
        }
    }
}

TEST(Build, IdenticalCentresAtScaleSplitToLeafSize) {
    // No split separates identical centres: lists are cut in two, also at the parallel sizes.
    Soup s;
    s.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    s.tris.assign(40000, {0u, 1u, 2u});
    const std::vector<BBox> boxes = boxes_of(s);
    const Bvh bvh = Bvh::build(boxes);
    expect_one_tree(bvh, boxes.size());
    for (const BvhNode& node : bvh.nodes) {
        if (node.is_leaf()) {
            EXPECT_LE(node.count, 8u);
        }
    }
    // Halving 40,000 down to leaves of at most 8 takes 13 splits (14 levels); peeling a few off
    // at a time would take thousands of levels.
    EXPECT_LE(bvh.depth(), 16);
}

TEST(HugePages, LargeArraysStartOnAHugePage) {
    auto large = accel::make_huge_array<std::uint32_t>(3 * (accel::kHugePage / 4) + 5);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(large.get()) % accel::kHugePage, 0u);
    auto small = accel::make_huge_array<double>(3);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(small.get()) % 16, 0u);
    // Usable end to end.
    const std::size_t n = 3 * (accel::kHugePage / 4) + 5;
    for (std::size_t i = 0; i < n; ++i) large[i] = static_cast<std::uint32_t>(i);
    std::uint64_t sum = 0;
    for (std::size_t i = 0; i < n; ++i) sum += large[i];
    EXPECT_EQ(sum, static_cast<std::uint64_t>(n) * (n - 1) / 2);
    std::vector<int> v;
    accel::reserve_huge(v, 1u << 20);
    EXPECT_GE(v.capacity(), 1u << 20);
    EXPECT_TRUE(v.empty());
}
