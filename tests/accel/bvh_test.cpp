#include "toonray/accel/bvh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "toonray/accel/triangle_accel.h"
#include "toonray/accel/watertight.h"
#include "toonray/scene/obj_loader.h"
#include "accel/isas.h"
#include "accel/soup.h"

using namespace toonray;

namespace {

using test_support::from_obj;
using test_support::random_soup;
using test_support::Soup;

Hit brute_force(const Soup& s, const Ray& ray) {
    Hit best;
    for (std::uint32_t i = 0; i < s.tris.size(); ++i) {
        float t, u, v;
        Ray r = ray;
        r.tmax = best.t;
        if (intersect_triangle(r, s.positions[s.tris[i][0]], s.positions[s.tris[i][1]],
                               s.positions[s.tris[i][2]], t, u, v)) {
            best.t = t;
            best.prim = i;
        }
    }
    return best;
}

// Rays from random points on a sphere around the mesh towards random points inside it.
void expect_matches_brute_force(const Soup& s, const TriangleAccel& accel, int rays,
                                unsigned seed) {
    BBox box;
    for (const Vec3f& p : s.positions) box.extend(p);
    float radius = length(box.extent());
    std::mt19937 rng(seed);
    std::normal_distribution<float> n(0.0f, 1.0f);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    int hits = 0;
    for (int i = 0; i < rays; ++i) {
        Vec3f from = box.center() + normalize(Vec3f(n(rng), n(rng), n(rng))) * radius * 1.5f;
        Vec3f to(box.lo.x + u(rng) * box.extent().x, box.lo.y + u(rng) * box.extent().y,
                 box.lo.z + u(rng) * box.extent().z);
        Ray ray{from, normalize(to - from)};
        Hit expected = brute_force(s, ray);
        Hit got;
        bool found = accel.intersect(ray, got);
        ASSERT_EQ(found, expected.valid()) << "ray " << i;
        if (!found) continue;
        ++hits;
        // The same distance bit for bit, and on ties (a ray through a shared edge) the same
        // triangle: the lowest index, as brute force finds it.
        ASSERT_EQ(got.t, expected.t) << "ray " << i;
        ASSERT_EQ(got.prim, expected.prim) << "ray " << i;
    }
    EXPECT_GT(hits, rays / 10);  // the test must actually exercise hits
}

void expect_valid_tree(const Bvh& bvh, std::size_t prims, int max_leaf) {
    std::vector<int> seen(prims, 0);
    for (std::uint32_t p : bvh.prim_indices) seen[p]++;
    for (std::size_t i = 0; i < prims; ++i) ASSERT_EQ(seen[i], 1) << "primitive " << i;
    for (std::size_t i = 0; i < bvh.nodes.size(); ++i) {
        const BvhNode& node = bvh.nodes[i];
        if (node.is_leaf()) {
            ASSERT_LE(node.count, static_cast<std::uint32_t>(max_leaf));
        } else {
            ASSERT_GT(node.first, i);  // children after parents
            for (int c = 0; c < 2; ++c) {
                const BBox& child = bvh.nodes[node.first + c].bounds;
                ASSERT_LE(node.bounds.lo.x, child.lo.x);
                ASSERT_LE(node.bounds.lo.y, child.lo.y);
                ASSERT_LE(node.bounds.lo.z, child.lo.z);
                ASSERT_GE(node.bounds.hi.x, child.hi.x);
                ASSERT_GE(node.bounds.hi.y, child.hi.y);
                ASSERT_GE(node.bounds.hi.z, child.hi.z);
            }
        }
    }
}

}  // namespace

TEST(Bvh, RandomSoupMatchesBruteForce) {
    for (unsigned seed : {1u, 2u, 3u}) {
        Soup s = random_soup(2000, seed);
        TriangleAccel accel;
        accel.build(s.positions, s.tris);
        expect_valid_tree(accel.bvh(), s.tris.size(), Bvh::Config{}.max_leaf_size);
        expect_matches_brute_force(s, accel, 2000, seed + 10);
    }
}

TEST(Bvh, RealMeshesMatchBruteForce) {
    for (const char* name : {"teapot.obj", "spot.obj"}) {
        Soup s = from_obj(name);
        TriangleAccel accel;
        accel.build(s.positions, s.tris);
        expect_valid_tree(accel.bvh(), s.tris.size(), Bvh::Config{}.max_leaf_size);
        expect_matches_brute_force(s, accel, 1500, 42);
    }
}

TEST(Bvh, LeafSizeIsAConfigValue) {
    Soup s = random_soup(3000, 9);
    for (int leaf : {1, 4, 10}) {
        Bvh::Config config;
        config.max_leaf_size = leaf;
        TriangleAccel accel;
        accel.build(s.positions, s.tris, config);
        expect_valid_tree(accel.bvh(), s.tris.size(), leaf);
        expect_matches_brute_force(s, accel, 300, 5);
    }
}

TEST(Bvh, IdenticalCentroidsStillSplitToLeafSize) {
    // 100 copies of the same triangle: no SAH split exists, the list is cut instead.
    Soup s;
    s.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    for (int i = 0; i < 100; ++i) s.tris.push_back({0, 1, 2});
    TriangleAccel accel;
    accel.build(s.positions, s.tris);
    expect_valid_tree(accel.bvh(), 100, Bvh::Config{}.max_leaf_size);
    Hit hit;
    EXPECT_TRUE(accel.intersect({{0.2f, 0.2f, 1.0f}, {0, 0, -1}}, hit));
    EXPECT_FLOAT_EQ(hit.t, 1.0f);
}

TEST(Bvh, EmptyAndSingle) {
    TriangleAccel empty;
    empty.build({}, {});
    Hit hit;
    EXPECT_FALSE(empty.intersect({{0, 0, 0}, {0, 0, 1}}, hit));
    Soup one;
    one.positions = {{-1, -1, 5}, {1, -1, 5}, {0, 1, 5}};
    one.tris = {{0, 1, 2}};
    TriangleAccel accel;
    accel.build(one.positions, one.tris);
    ASSERT_TRUE(accel.intersect({{0, 0, 0}, {0, 0, 1}}, hit));
    EXPECT_FLOAT_EQ(hit.t, 5.0f);
    EXPECT_EQ(hit.prim, 0u);
    EXPECT_FALSE(accel.intersect({{0, 0, 0}, {0, 0, -1}}, hit));
    Ray short_ray{{0, 0, 0}, {0, 0, 1}, 4.0f};
    EXPECT_FALSE(accel.intersect(short_ray, hit));
}

TEST(Bvh, DeepDegenerateTreesStillTraverse) {
    // Triangles at exponentially growing distances make SAH peel one off per level; the
    // builder must not recurse and traversal must not overflow its stack.
    Soup s;
    for (int i = 0; i < 400; ++i) {
        float x = std::ldexp(1.0f, i / 4) * (1.0f + (i % 4) * 0.1f);
        auto base = static_cast<std::uint32_t>(s.positions.size());
        s.positions.push_back({x, 0, 0});
        s.positions.push_back({x, 1, 0});
        s.positions.push_back({x, 0, 1});
        s.tris.push_back({base, base + 1, base + 2});
    }
    TriangleAccel accel;
    accel.build(s.positions, s.tris);
    expect_valid_tree(accel.bvh(), s.tris.size(), Bvh::Config{}.max_leaf_size);
    Hit hit;
    ASSERT_TRUE(accel.intersect({{-1.0f, 0.25f, 0.25f}, {1, 0, 0}}, hit));
    EXPECT_EQ(hit.prim, 0u);
}

TEST(Bvh, TiesGoToTheLowestTriangleIndexWhateverTheTree) {
    // Two coincident copies of a surface: every hit is a tie; the lower index must win for
    // every leaf size (different trees).
    Soup s = random_soup(500, 4);
    std::size_t n = s.tris.size();
    for (std::size_t i = 0; i < n; ++i) s.tris.push_back(s.tris[i]);
    std::reverse(s.tris.begin(), s.tris.end());  // copies now come first, at indices < n
    for (int leaf : {1, 3, 8}) {
        Bvh::Config config;
        config.max_leaf_size = leaf;
        TriangleAccel accel;
        accel.build(s.positions, s.tris, config);
        expect_matches_brute_force(s, accel, 500, 8);
    }
}

TEST(Bvh, RefitFollowsMovedVertices) {
    Soup s = random_soup(1500, 21);
    TriangleAccel accel;
    accel.build(s.positions, s.tris);
    // Move every vertex: a shear and a shift.
    for (Vec3f& p : s.positions) p = Vec3f(p.x + 0.5f * p.y, p.y * 1.5f, p.z - 0.3f);
    accel.refit(s.positions, s.tris);
    expect_valid_tree(accel.bvh(), s.tris.size(), Bvh::Config{}.max_leaf_size);
    expect_matches_brute_force(s, accel, 1500, 77);
}

TEST(Bvh, ACrossingBehindTheOriginIsNoHitOnAnyPath) {
    // Triangles in the plane x = 0, and rays from just in front of it. A ray leaving the plane
    // crossed it behind its origin, though the watertight test's rounding can put that crossing
    // at a small positive t; the triangle's box is then behind the origin, which brute force
    // and the traversal both refuse. A ray towards the plane must still find its triangle. (Two
    // triangles make one leaf: what is tested is the hit's hold, on every path, not culling.)
    Soup s;
    s.positions = {Vec3f(0, 0, 0), Vec3f(0, 5, 0), Vec3f(0, 5, 5), Vec3f(0, 0, 5)};
    s.tris = {{0, 1, 2}, {0, 2, 3}};
    TriangleAccel accel;
    accel.build(s.positions, s.tris);
    for (const std::string& isa : test_support::isas()) {
        test_support::IsaGuard guard(isa);
        SCOPED_TRACE(isa);
        std::mt19937 rng(7);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        int towards_hits = 0;
        for (int i = 0; i < 20000; ++i) {
            const float offset = std::ldexp(1.0f, -10 - static_cast<int>(u(rng) * 24.0f));
            const Vec3f from(offset, 0.5f + 4.0f * u(rng), 0.5f + 4.0f * u(rng));
            // Leaving, towards, or along the plane (a zero x component of either sign).
            const float dx = i % 8 == 7 ? (i % 16 == 7 ? 0.0f : -0.0f)
                                        : std::ldexp(1.0f, -static_cast<int>(u(rng) * 20.0f));
            const bool towards = i % 2 == 0;
            const Ray ray{from, normalize(Vec3f(towards ? -dx : dx, u(rng) - 0.5f, u(rng) - 0.5f))};
            const Hit expected = brute_force(s, ray);
            Hit got;
            const bool found = accel.intersect(ray, got);
            ASSERT_EQ(found, expected.valid()) << "ray " << i;
            ASSERT_EQ(accel.occluded(ray), found) << "ray " << i;
            if (towards) {
                towards_hits += found ? 1 : 0;
            } else {
                ASSERT_FALSE(found) << "ray " << i << " leaving the plane from x = " << offset
                                    << " hit at t = " << got.t;
            }
            if (found) {
                ASSERT_EQ(got.t, expected.t) << "ray " << i;
                ASSERT_EQ(got.prim, expected.prim) << "ray " << i;
            }
        }
        EXPECT_GT(towards_hits, 8000);
        // The same through tiles of 8 x 8 rays, whose regular groups test a triangle for 8
        // rays at once: leaving rays find nothing, and every ray what the single ray finds.
        constexpr int kSide = 8;
        std::vector<Vec3f> dirs(kSide * kSide);
        std::vector<Hit> hits(dirs.size());
        auto found = std::make_unique<bool[]>(dirs.size());
        int tile_hits = 0;
        for (int exponent = 10; exponent < 34; ++exponent)
            for (float dx : {1.0f, 1.0f / 64, 1.0f / 4096, -1.0f / 4096, -1.0f}) {
                const Vec3f origin(std::ldexp(1.0f, -exponent), 1.0f, 1.5f);
                for (int y = 0; y < kSide; ++y)
                    for (int x = 0; x < kSide; ++x)
                        dirs[static_cast<std::size_t>(y * kSide + x)] =
                            normalize(Vec3f(dx, 0.5f + 0.03f * x, 0.25f + 0.03f * y));
                accel.intersect_tile(origin, dirs.data(), kSide, kSide, hits.data(), found.get());
                for (std::size_t i = 0; i < dirs.size(); ++i) {
                    Hit single;
                    const bool single_found = accel.intersect(Ray{origin, dirs[i]}, single);
                    ASSERT_EQ(found[i], single_found) << "2^-" << exponent << ", dx " << dx;
                    if (dx > 0.0f) {
                        ASSERT_FALSE(found[i]) << "2^-" << exponent << ", dx " << dx;
                    }
                    if (single_found) {
                        ++tile_hits;
                        ASSERT_EQ(hits[i].t, single.t);
                        ASSERT_EQ(hits[i].prim, single.prim);
                    }
                }
            }
        // Rays towards the plane from (2^-e, 1, 1.5) at these slopes reach it inside the quad.
        EXPECT_EQ(tile_hits, 24 * 2 * kSide * kSide);
    }
}

TEST(BoxHold, TheFusedTestKeepsEveryBoxItsShortcutVouchesFor) {
    // held_to_box skips the fused box test where fused_test_keeps vouches for it from the
    // two-rounding interval; if that were ever wrong, paths with and without the fused test
    // would disagree. Triangles at scales from 2^-60 to 2^60, some flat along an axis, and
    // rays aimed at a corner of their box, so that entry and exit often nearly meet.
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::uniform_int_distribution<int> exponent(-60, 60), axis_of(0, 2);
    int vouched = 0, tight = 0, fused_tight = 0;
    for (int i = 0; i < 300000; ++i) {
        const float scale = std::ldexp(1.0f, exponent(rng));
        const float reach = std::ldexp(scale, i % 24 - 12);  // the origin's distance
        const Vec3f centre(u(rng) * scale * 8.0f, u(rng) * scale * 8.0f, u(rng) * scale * 8.0f);
        float q[3][3];
        for (auto& corner : q)
            for (int a = 0; a < 3; ++a) corner[a] = centre[a] + u(rng) * scale;
        if (i % 3 == 0) {  // flat along one axis, as an axis-aligned face
            const int a = axis_of(rng);
            q[1][a] = q[2][a] = q[0][a];
        }
        // Near the box, or near the coordinates' zero, where the fused test's margins vanish.
        const Vec3f around = i % 2 ? centre : Vec3f(0, 0, 0);
        const float o[3] = {around.x + u(rng) * reach, around.y + u(rng) * reach,
                            around.z + u(rng) * reach};
        // Towards a corner of the box, nudged by a few ulps of the direction.
        float dir[3];
        for (int a = 0; a < 3; ++a) {
            const float lo = std::min({q[0][a], q[1][a], q[2][a]});
            const float hi = std::max({q[0][a], q[1][a], q[2][a]});
            const float d = ((rng() & 1) ? lo : hi) - o[a];
            dir[a] = d * (1.0f + u(rng) * 0x1p-20f);
        }
        const float inv[3] = {1.0f / dir[0], 1.0f / dir[1], 1.0f / dir[2]};
        const accel::BoxInterval box = accel::two_rounding_interval(q, o, inv);
        if (box.behind || !box.kept()) continue;
        const accel::BoxInterval fused = accel::fused_interval(q, o, inv);
        const bool fused_kept = fused.kept();
        fused_tight += fused.entry > fused.exit ? 1 : 0;
        if (!accel::fused_test_keeps(box.entry, box.exit)) continue;
        ++vouched;
        if (box.entry >= box.exit) ++tight;
        ASSERT_TRUE(fused_kept) << "ray " << i << ": entry " << box.entry << ", exit " << box.exit;
    }
    EXPECT_GT(vouched, 100000);
    EXPECT_GT(tight, 1000);        // boxes the ray only grazes, where the shortcut's bound is tight
    EXPECT_GT(fused_tight, 1000);  // the fused test keeping a box only by its kBoxSlack
}
