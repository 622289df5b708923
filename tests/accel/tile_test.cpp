// The SIMD traversal paths against each other and against brute force: single rays and tiles,
// on every instruction set this machine runs; and the builder's determinism.

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "toonray/accel/triangle_accel.h"
#include "toonray/accel/wide_bvh.h"
#include "toonray/scene/camera.h"
#include "toonray/scene/obj_loader.h"
#include "accel/isas.h"
#include "accel/soup.h"

using namespace toonray;

namespace {

using test_support::from_obj;
using test_support::IsaGuard;
using test_support::isas;
using test_support::random_soup;
using test_support::Soup;
using test_support::unit_square;

// An axis-aligned grid of unit squares in the plane z = 0 (two triangles each): rays from a
// camera looking straight down hit shared edges and corners exactly.
Soup grid(int n) {
    Soup s;
    for (int y = 0; y <= n; ++y)
        for (int x = 0; x <= n; ++x)
            s.positions.push_back(Vec3f(static_cast<float>(x), static_cast<float>(y), 0.0f));
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            std::uint32_t a = y * (n + 1) + x, b = a + 1, c = a + n + 1, d = c + 1;
            s.tris.push_back({a, b, d});
            s.tris.push_back({a, d, c});
        }
    return s;
}

std::uint32_t bits(float f) {
    std::uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
}

Hit brute_force(const Soup& s, const Ray& ray) {
    Hit best;
    for (std::uint32_t i = 0; i < s.tris.size(); ++i) {
        float t, u, v;
        Ray r = ray;
        r.tmax = std::min(best.t, ray.tmax);
        if (intersect_triangle(r, s.positions[s.tris[i][0]], s.positions[s.tris[i][1]],
                               s.positions[s.tris[i][2]], t, u, v)) {
            best.t = t;
            best.prim = i;
            best.u = u;
            best.v = v;
        }
    }
    return best;
}

// Traces width x height pinhole rays through view (as trace_primary makes them) in tiles of
// tw x th, and checks every ray: the tile result equals the single-ray result bit for bit, and
// every `stride`-th equals brute force.
void check_view(const Soup& s, const TriangleAccel& accel, const ViewPlane& view, int width,
                int height, int tw, int th, int stride, int* hits_out = nullptr) {
    int hits = 0;
    for (int y0 = 0; y0 < height; y0 += th)
        for (int x0 = 0; x0 < width; x0 += tw) {
            const int w = std::min(tw, width - x0), h = std::min(th, height - y0);
            std::vector<Vec3f> dirs(static_cast<std::size_t>(w * h));
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x)
                    dirs[y * w + x] =
                        normalize(view.pixel_point(x0 + x + 0.5f, y0 + y + 0.5f) - view.eye);
            std::vector<Hit> tile(dirs.size());
            std::unique_ptr<bool[]> found(new bool[dirs.size()]);
            accel.intersect_tile(view.eye, dirs.data(), w, h, tile.data(), found.get());
            for (int i = 0; i < w * h; ++i) {
                Hit single;
                const Ray ray{view.eye, dirs[i]};
                const bool f = accel.intersect(ray, single);
                ASSERT_EQ(found[i], f) << "pixel " << x0 + i % w << "," << y0 + i / w;
                ASSERT_EQ(tile[i].prim, single.prim);
                ASSERT_EQ(bits(tile[i].t), bits(single.t));
                ASSERT_EQ(bits(tile[i].u), bits(single.u));
                ASSERT_EQ(bits(tile[i].v), bits(single.v));
                hits += f;
                if ((x0 + i % w) % stride == 0 && (y0 + i / w) % stride == 0) {
                    const Hit expected = brute_force(s, ray);
                    ASSERT_EQ(f, expected.valid());
                    if (f) {
                        ASSERT_EQ(bits(single.t), bits(expected.t));
                        ASSERT_EQ(single.prim, expected.prim);
                        ASSERT_EQ(bits(single.u), bits(expected.u));
                        ASSERT_EQ(bits(single.v), bits(expected.v));
                    }
                }
            }
        }
    if (hits_out) *hits_out = hits;
}

CameraSpec framing(const Soup& s, int w, int h) {
    std::vector<Vec3f> used;
    for (const auto& t : s.tris)
        for (std::uint32_t v : t) used.push_back(s.positions[v]);
    return auto_camera(used, w, h);
}

}  // namespace

TEST(Tile, MatchesSingleRaysAndBruteForceOnMeshes) {
    for (const std::string& isa : isas()) {
        IsaGuard guard(isa);
        for (const char* name : {"teapot.obj", "spot.obj"}) {
            SCOPED_TRACE(std::string(name) + " " + isa);
            Soup s = from_obj(name);
            TriangleAccel accel;
            accel.build(s.positions, s.tris);
            const ViewPlane view = make_view_plane(framing(s, 160, 90), 160, 90);
            int hits = 0;
            check_view(s, accel, view, 160, 90, 16, 16, 7, &hits);
            EXPECT_GT(hits, 160 * 90 / 10);
            // Partial tiles, odd sizes.
            check_view(s, accel, view, 61, 37, 13, 5, 9);
            check_view(s, accel, view, 20, 20, 1, 1, 5);
            // Grids narrower and taller than a tile (lists of rays a few wide), and wider and
            // taller.
            check_view(s, accel, view, 61, 37, 4, 37, 9);
            check_view(s, accel, view, 61, 37, 61, 37, 9);
        }
    }
}

TEST(Tile, RandomCamerasOnASoup) {
    Soup s = random_soup(3000, 17);
    TriangleAccel accel;
    accel.build(s.positions, s.tris);
    std::mt19937 rng(5);
    std::normal_distribution<float> n(0.0f, 1.0f);
    for (const std::string& isa : isas()) {
        IsaGuard guard(isa);
        for (int c = 0; c < 6; ++c) {
            SCOPED_TRACE("camera " + std::to_string(c) + " " + isa);
            CameraSpec cam;
            cam.eye = normalize(Vec3f(n(rng), n(rng), n(rng))) * 3.0f;
            cam.gaze = cam.eye + normalize(Vec3f(0.0f) - cam.eye) * 1.5f;
            Vec3f right = normalize(cross(cam.gaze - cam.eye, Vec3f(0.0f, 1.0f, 0.0f)));
            cam.up = normalize(cross(right, cam.gaze - cam.eye));
            const ViewPlane view = make_view_plane(cam, 96, 64);
            check_view(s, accel, view, 96, 64, 16, 16, 6);
        }
    }
}

TEST(Tile, AxisAlignedViewOfAGridHitsEdgesExactly) {
    // Looking straight down the z axis: the view's centre row and column have direction
    // components that change sign inside a tile and rays along the grid's shared edges and
    // corners, where ties between triangles are decided by index.
    Soup s = grid(12);
    TriangleAccel accel;
    accel.build(s.positions, s.tris);
    CameraSpec cam{Vec3f(6.0f, 6.0f, 10.0f), Vec3f(6.0f, 6.0f, 9.0f), Vec3f(0.0f, 1.0f, 0.0f)};
    for (const std::string& isa : isas()) {
        IsaGuard guard(isa);
        SCOPED_TRACE(isa);
        for (int size : {48, 47, 60}) {
            const ViewPlane view = make_view_plane(cam, size, size);
            check_view(s, accel, view, size, size, 16, 16, 1);
        }
    }
}

TEST(Tile, TiesAmongTheDenormalsGoToTheLowerIndex) {
    // A grid with a large triangle under it, first and last in the index order, and the eye a
    // few denormals above them: t rounds to the coarse denormal grid, so most rays meet a grid
    // triangle and a large one at the same t, and the lower index must win whichever the
    // traversal meets first. A test on t * det (which underflows there) once let the first
    // one met win.
    Soup s = grid(8);
    const auto first = static_cast<std::uint32_t>(s.positions.size());
    for (const Vec3f& p :
         {Vec3f(-8.0f, -8.0f, 0.0f), Vec3f(24.0f, -8.0f, 0.0f), Vec3f(-8.0f, 24.0f, 0.0f)})
        s.positions.push_back(p);
    s.tris.insert(s.tris.begin(), {first, first + 1, first + 2});
    s.tris.push_back({first, first + 1, first + 2});
    TriangleAccel accel;
    accel.build(s.positions, s.tris);
    const float height = std::numeric_limits<float>::denorm_min() * 3.0f;
    for (const std::string& isa : isas()) {
        IsaGuard guard(isa);
        SCOPED_TRACE(isa);
        for (const Vec3f& gaze : {Vec3f(3.0f, 5.0f, -1.0f), Vec3f(4.3f, 4.1f, -2.0f)}) {
            const CameraSpec cam{Vec3f(4.3f, 4.1f, height), gaze, Vec3f(0.0f, 1.0f, 0.0f)};
            const ViewPlane view = make_view_plane(cam, 48, 32);
            int hits = 0;
            check_view(s, accel, view, 48, 32, 16, 16, 1, &hits);
            EXPECT_GT(hits, 48 * 32 / 4);
        }
    }
}

// Copies of a long triangle seen almost along its plane from far away (the render fuzzer's
// find). The computed t lay more than the box culling's 2^-20 before the triangles' box, so the
// single ray, having found one copy, culled the copy with the lower index, which the tile
// found. A hit's t is now held to its triangle's box (held_to_box in watertight.h).
TEST(Tile, TiesOnATriangleSeenEdgeOnGoToTheLowerIndex) {
    Soup s;
    s.positions = {{0.0f, 0.0f, 0.0f}, {0.0f, 9.0f, 2233721.0f}, {54.0f, 5.0f, 3.0f}};
    s.tris = {{0, 1, 2}, {0, 2, 1}, {0, 1, 2}, {0, 2, 1}, {0, 1, 2},
              {0, 2, 1}, {0, 1, 2}, {0, 2, 2}, {0, 2, 1}, {0, 1, 2}};
    TriangleAccel accel;
    accel.build(s.positions, s.tris);
    const ViewPlane view = make_view_plane(framing(s, 24, 16), 24, 16);
    for (const std::string& isa : isas()) {
        IsaGuard guard(isa);
        SCOPED_TRACE(isa);
        int hits = 0;
        check_view(s, accel, view, 24, 16, 24, 16, 1, &hits);
        EXPECT_GE(hits, 1);  // the triangle is edge-on: a pixel
        // Occlusion by the same held t: a hit strictly inside tmax only.
        for (int y = 0; y < 16; ++y)
            for (int x = 0; x < 24; ++x) {
                const Vec3f dir = normalize(view.pixel_point(x + 0.5f, y + 0.5f) - view.eye);
                Hit hit;
                if (!accel.intersect(Ray{view.eye, dir}, hit)) continue;
                EXPECT_FALSE(accel.occluded(Ray{view.eye, dir, hit.t})) << x << "," << y;
                EXPECT_TRUE(accel.occluded(Ray{
                    view.eye, dir, std::nextafter(hit.t, std::numeric_limits<float>::infinity())}))
                    << x << "," << y;
            }
    }
}

TEST(Tile, AxisAlignedRaysOnTriangleEdgesAndCornersHit) {
    // Rays straight down onto a square's edges, diagonal and corners: their zero direction
    // components make a corner's slab distance 0 * inf, which the box entry must ignore as the
    // box tests do (it once made the entry infinite and lost these hits).
    const Soup s = unit_square({{2, 0, 1}, {0, 2, 3}});
    TriangleAccel accel;
    accel.build(s.positions, s.tris);
    struct Expected {
        float x, y;
        std::uint32_t prim;
    };
    // Triangle 0 is the half below the diagonal, 1 the half above; ties go to 0.
    const Expected cases[] = {{0.5f, 0.0f, 0},   {0.5f, 0.5f, 0}, {1.0f, 1.0f, 0}, {0.0f, 0.0f, 0},
                              {0.25f, 0.75f, 1}, {0.0f, 0.5f, 1}, {0.5f, 1.0f, 1}, {1.0f, 0.5f, 0}};
    for (const std::string& isa : isas()) {
        IsaGuard guard(isa);
        for (const Expected& c : cases) {
            SCOPED_TRACE(isa + " at " + std::to_string(c.x) + "," + std::to_string(c.y));
            // +0 and -0 components: the box entry picks the corner by the sign bit.
            for (const Vec3f& dir : {Vec3f(0.0f, 0.0f, -1.0f), Vec3f(-0.0f, -0.0f, -1.0f)}) {
                const Ray ray{Vec3f(c.x, c.y, 1.0f), dir};
                Hit hit;
                ASSERT_TRUE(accel.intersect(ray, hit));
                EXPECT_EQ(hit.t, 1.0f);
                EXPECT_EQ(hit.prim, c.prim);
                const Hit expected = brute_force(s, ray);
                EXPECT_EQ(expected.prim, c.prim);
                EXPECT_EQ(expected.t, 1.0f);
                EXPECT_TRUE(accel.occluded(Ray{ray.origin, ray.dir, 1.5f}));
                EXPECT_FALSE(accel.occluded(Ray{ray.origin, ray.dir, 1.0f}));
            }
        }
    }
}

TEST(Tile, DegenerateDirectionsAgreeWithSingleRays) {
    Soup s = random_soup(500, 3);
    TriangleAccel accel;
    accel.build(s.positions, s.tris);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    std::vector<Vec3f> dirs = {
        {0, 0, 1},   {0, 0, -1},           {1, 0, 0},          {-1, 0, 0},
        {0, 1, 0},   {0, -1, 0},           {0, 0, 0},          {nan, 0, 1},
        {inf, 0, 0}, {0.0f, -0.0f, -1.0f}, {1e-30f, 0, 1},     {1, 1, 1},
        {-1, 1, -1}, {1e-40f, 1, 0},       {0.3f, 0.3f, 0.3f}, {-0.0f, 1, 0}};
    for (const std::string& isa : isas()) {
        IsaGuard guard(isa);
        for (const Vec3f& origin : {Vec3f(0.0f), Vec3f(0.1f, -0.2f, -3.0f)}) {
            std::vector<Hit> hits(dirs.size());
            std::unique_ptr<bool[]> found(new bool[dirs.size()]);
            accel.intersect_tile(origin, dirs.data(), 4, 4, hits.data(), found.get());
            for (std::size_t i = 0; i < dirs.size(); ++i) {
                Hit single;
                const bool f = accel.intersect(Ray{origin, dirs[i]}, single);
                ASSERT_EQ(found[i], f) << isa << " ray " << i;
                ASSERT_EQ(hits[i].prim, single.prim) << isa << " ray " << i;
                ASSERT_EQ(bits(hits[i].t), bits(single.t)) << isa << " ray " << i;
            }
        }
    }
}

// Rays said to be too sparse for the tree (as a frame's refined samples along the edges of a
// dense mesh are) are traced one by one: whatever the spacing given, every ray gets exactly the
// single ray's hit within tmax, and every result is written.
TEST(Tile, SparseRaysGetTheSingleRaysHits) {
    Soup s = from_obj("spot.obj");
    TriangleAccel accel;
    accel.build(s.positions, s.tris);
    const int width = 160, height = 90;
    const ViewPlane view = make_view_plane(framing(s, width, height), width, height);
    // Every third pixel, as a list four rays wide and longer than a tile.
    std::vector<Vec3f> dirs;
    for (int p = 0; p < width * height; p += 3)
        dirs.push_back(normalize(
            view.pixel_point(float(p % width) + 0.5f, float(p / width) + 0.5f) - view.eye));
    while (dirs.size() % 4) dirs.push_back(dirs.back());
    const int rows = static_cast<int>(dirs.size() / 4);
    ASSERT_GT(rows, 16);
    // A tmax that cuts off about half the hits.
    std::vector<float> ts;
    for (const Vec3f& d : dirs) {
        Hit h;
        if (accel.intersect(Ray{view.eye, d}, h)) ts.push_back(h.t);
    }
    ASSERT_GT(ts.size(), 400u);
    std::nth_element(ts.begin(), ts.begin() + ts.size() / 2, ts.end());
    const float inf = std::numeric_limits<float>::infinity();
    const float cut = ts[ts.size() / 2];
    for (const std::string& isa : isas()) {
        IsaGuard guard(isa);
        // The camera's spacing and a finer one (packets), a coarse one and none (ray by ray).
        for (const float ray_angle2 : {-1.0f, 1e-12f, 1.0f, inf})
            for (const float tmax : {inf, cut}) {
                SCOPED_TRACE(isa + " spacing " + std::to_string(ray_angle2) + " tmax " +
                             std::to_string(tmax));
                std::vector<Hit> hits(dirs.size(), Hit{0.5f, 7u, 0.25f, 0.25f});
                std::unique_ptr<bool[]> found(new bool[dirs.size()]);
                std::fill(found.get(), found.get() + dirs.size(), true);
                accel.intersect_tile(view.eye, dirs.data(), 4, rows, hits.data(), found.get(), tmax,
                                     ray_angle2);
                int hit = 0, missed = 0;
                for (std::size_t i = 0; i < dirs.size(); ++i) {
                    Hit single;
                    const bool f = accel.intersect(Ray{view.eye, dirs[i], tmax}, single);
                    ASSERT_EQ(found[i], f) << "ray " << i;
                    ASSERT_EQ(hits[i].prim, single.prim) << "ray " << i;
                    ASSERT_EQ(bits(hits[i].t), bits(single.t)) << "ray " << i;
                    ASSERT_EQ(bits(hits[i].u), bits(single.u)) << "ray " << i;
                    ASSERT_EQ(bits(hits[i].v), bits(single.v)) << "ray " << i;
                    (f ? hit : missed) += 1;
                }
                EXPECT_GT(hit, 100);
                EXPECT_GT(missed, 100);
            }
    }
}

// Packets pay when the rays over a tree's bounding sphere are at least its blocks.
TEST(Tile, DenseForCountsTheRaysOverTheTreesSphere) {
    accel::WideBvh tree;
    tree.centre = Vec3f(0.0f, 0.0f, 10.0f);
    tree.radius = 1.0f;
    tree.blocks.resize(100);
    // Seen from the origin the sphere covers about pi / 100 sr.
    EXPECT_TRUE(tree.dense_for(Vec3f(0.0f), 1e-4f));   // about 314 rays
    EXPECT_FALSE(tree.dense_for(Vec3f(0.0f), 1e-3f));  // about 31
    EXPECT_FALSE(tree.dense_for(Vec3f(0.0f), std::numeric_limits<float>::infinity()));
    EXPECT_TRUE(tree.dense_for(Vec3f(0.0f, 0.0f, 10.5f), 1.0f));  // inside the sphere
    tree.blocks.resize(1000);
    EXPECT_FALSE(tree.dense_for(Vec3f(0.0f), 1e-4f));
}

TEST(Tile, TmaxAndEmptyAccelerator) {
    Soup one;
    one.positions = {{-1, -1, 5}, {1, -1, 5}, {0, 1, 5}};
    one.tris = {{0, 1, 2}};
    TriangleAccel accel;
    accel.build(one.positions, one.tris);
    const Vec3f dirs[2] = {{0, 0, 1}, {0, 0, -1}};
    Hit hits[2];
    bool found[2];
    accel.intersect_tile(Vec3f(0.0f), dirs, 2, 1, hits, found);
    EXPECT_TRUE(found[0]);
    EXPECT_FLOAT_EQ(hits[0].t, 5.0f);
    EXPECT_FALSE(found[1]);
    accel.intersect_tile(Vec3f(0.0f), dirs, 2, 1, hits, found, 4.0f);
    EXPECT_FALSE(found[0]);
    accel.intersect_tile(Vec3f(0.0f), dirs, 2, 1, hits, found,
                         5.0f);  // hits must be strictly inside tmax
    EXPECT_FALSE(found[0]);
    TriangleAccel empty;
    empty.build({}, {});
    accel = empty;
    accel.intersect_tile(Vec3f(0.0f), dirs, 2, 1, hits, found);
    EXPECT_FALSE(found[0]);
    EXPECT_FALSE(hits[0].valid());
}

TEST(Tile, LargeLeavesAndLargeTiles) {
    // Leaves of more than 15 triangles are ended by a flag rather than a count.
    Soup s = random_soup(400, 8, 0.05f);
    for (int i = 0; i < 200; ++i)
        s.tris.push_back(s.tris[static_cast<std::size_t>(i) * 2]);  // exact duplicates
    Bvh::Config config;
    config.max_leaf_size = 64;
    config.traversal_cost = 100.0f;  // leaves as large as allowed
    TriangleAccel accel;
    accel.build(s.positions, s.tris, config);
    const ViewPlane view = make_view_plane(framing(s, 50, 40), 50, 40);
    for (const std::string& isa : isas()) {
        IsaGuard guard(isa);
        SCOPED_TRACE(isa);
        check_view(s, accel, view, 50, 40, 16, 16, 3);
        // A tile larger than kTileSize is cut into tiles.
        check_view(s, accel, view, 50, 40, 50, 40, 4);
    }
}

TEST(Tile, AfterRefit) {
    Soup s = from_obj("teapot.obj");
    TriangleAccel accel;
    accel.build(s.positions, s.tris);
    for (Vec3f& p : s.positions) p = Vec3f(p.x + 0.3f * p.y, p.y * 1.2f, p.z - 0.1f * p.x);
    accel.refit(s.positions, s.tris);
    const ViewPlane view = make_view_plane(framing(s, 80, 60), 80, 60);
    for (const std::string& isa : isas()) {
        IsaGuard guard(isa);
        SCOPED_TRACE(isa);
        check_view(s, accel, view, 80, 60, 16, 16, 3);
    }
}

TEST(Build, SameTreeForAnyThreadCount) {
    // Large enough for the parallel top levels (binning and partitioning in chunks) and for
    // subtrees as tasks.
    Soup s = random_soup(150000, 99, 0.01f);
    std::vector<BBox> boxes(s.tris.size());
    for (std::size_t i = 0; i < s.tris.size(); ++i)
        for (std::uint32_t v : s.tris[i]) boxes[i].extend(s.positions[v]);
    Bvh one, many;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = Bvh::build(boxes);
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 8);
        many = Bvh::build(boxes);
    }
    ASSERT_EQ(one.nodes.size(), many.nodes.size());
    ASSERT_EQ(one.prim_indices, many.prim_indices);
    for (std::size_t i = 0; i < one.nodes.size(); ++i) {
        ASSERT_EQ(std::memcmp(&one.nodes[i], &many.nodes[i], sizeof(BvhNode)), 0) << "node " << i;
    }
}
