// The two-level BVH: instances of meshes placed by transforms, beside the accelerator's own
// triangles. Single rays, occlusion and tiles against brute force in each instance's object
// space, on every instruction set this machine runs; the tie rule between instances; moving
// instances; the memory an instance costs.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <vector>

#include "toonray/accel/triangle_accel.h"
#include "toonray/core/affine.h"
#include "toonray/scene/camera.h"
#include "accel/isas.h"
#include "accel/soup.h"
#include "support/instance_scenes.h"

using namespace toonray;

namespace {

using test_support::from_obj;
using test_support::IsaGuard;
using test_support::isas;
using test_support::random_soup;
using test_support::Soup;

std::shared_ptr<const TriangleAccel> accel_of(const Soup& s) {
    auto a = std::make_shared<TriangleAccel>();
    a->build(s.positions, s.tris);
    return a;
}

Affine3 placement(Vec3f axis, double angle, Vec3f scale, Vec3f move) {
    return test_support::placed(axis.x, axis.y, axis.z, angle, scale, move);
}

struct Placed {
    const Soup* mesh;
    Affine3 to_world;
};

// The ray in an instance's object space, as the kernels take it there: by the inverse rounded
// to float, each coordinate summed in double and rounded once.
Ray object_ray(const Affine3& to_world, const Ray& ray) {
    const Affine3 inv = to_world.inverse();
    float m[3][4];
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 4; ++k) m[i][k] = static_cast<float>(inv.m[i][k]);
    Ray o = ray;
    for (int i = 0; i < 3; ++i) {
        o.origin[i] =
            static_cast<float>(double(m[i][0]) * ray.origin.x + double(m[i][1]) * ray.origin.y +
                               double(m[i][2]) * ray.origin.z + double(m[i][3]));
        o.dir[i] = static_cast<float>(double(m[i][0]) * ray.dir.x + double(m[i][1]) * ray.dir.y +
                                      double(m[i][2]) * ray.dir.z);
    }
    return o;
}

// The lowest (t, instance + 1, triangle) over every triangle the watertight test hits: the own
// triangles in world space, each instance's in its object space.
Hit brute_force(const Soup* own, const std::vector<Placed>& placed, const Ray& ray) {
    Hit best;
    best.t = ray.tmax;
    auto scan = [&](const Soup& s, const Ray& r, std::uint32_t instance) {
        for (std::uint32_t i = 0; i < s.tris.size(); ++i) {
            float t, u, v;
            Ray q = r;
            q.tmax = best.t;
            if (intersect_triangle(q, s.positions[s.tris[i][0]], s.positions[s.tris[i][1]],
                                   s.positions[s.tris[i][2]], t, u, v))
                best = Hit{t, i, u, v, instance};
        }
    };
    if (own) scan(*own, ray, kNoIndex);
    for (std::uint32_t i = 0; i < placed.size(); ++i)
        scan(*placed[i].mesh, object_ray(placed[i].to_world, ray), i);
    if (best.prim == kNoIndex) return Hit{};
    return best;
}

std::uint32_t bits(float f) {
    std::uint32_t u;
    std::memcpy(&u, &f, 4);
    return u;
}

::testing::AssertionResult same_hit(const Hit& a, bool fa, const Hit& b, bool fb) {
    if (fa != fb) return ::testing::AssertionFailure() << "found " << fa << " against " << fb;
    if (!fa) return ::testing::AssertionSuccess();
    if (a.prim != b.prim || a.instance != b.instance || bits(a.t) != bits(b.t) ||
        bits(a.u) != bits(b.u) || bits(a.v) != bits(b.v))
        return ::testing::AssertionFailure()
               << "t " << a.t << " prim " << a.prim << " instance " << a.instance << " against t "
               << b.t << " prim " << b.prim << " instance " << b.instance;
    return ::testing::AssertionSuccess();
}

// A crowd: `n` instances of the two meshes, rotated about tilted axes, scaled unevenly (some
// mirrored), on a jittered grid so that neighbours overlap.
std::vector<Placed> crowd(const Soup& a, const Soup& b, int n, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    // The draws one statement each: the order in which a call's arguments are evaluated is
    // left open (GCC takes them right to left on x86-64, left to right on aarch64), and the
    // crowd must be the same on every CPU.
    auto draw3 = [&] {
        const float x = u(rng), y = u(rng), z = u(rng);
        return Vec3f(x, y, z);
    };
    std::vector<Placed> out;
    const int side = static_cast<int>(std::ceil(std::sqrt(double(n))));
    for (int i = 0; i < n; ++i) {
        const Vec3f axis = draw3() + Vec3f(0.0f, 2.0f, 0.0f);
        Vec3f scale = Vec3f(0.6f) + draw3() * 0.3f;
        if (i % 5 == 3) scale.x = -scale.x;  // mirrored
        const Vec3f jitter = draw3() * 0.3f;
        const Vec3f move(1.2f * static_cast<float>(i % side - side / 2) + jitter.x, jitter.y,
                         1.2f * static_cast<float>(i / side - side / 2) + jitter.z);
        const double angle = 3.0 * u(rng);
        out.push_back({i % 3 == 1 ? &b : &a, placement(axis, angle, scale, move)});
    }
    return out;
}

std::vector<AccelInstance> accel_instances(const std::vector<Placed>& placed,
                                           const std::shared_ptr<const TriangleAccel>& a,
                                           const Soup& sa,
                                           const std::shared_ptr<const TriangleAccel>& b) {
    std::vector<AccelInstance> out;
    for (const Placed& p : placed) out.push_back({p.mesh == &sa ? a : b, p.to_world});
    return out;
}

// Every ray of a view: tiles against single rays against brute force (every `stride`-th), and
// occlusion against the closest hit, on every instruction set; `hits` gets the rays that hit.
void check_view(const TriangleAccel& accel, const Soup* own, const std::vector<Placed>& placed,
                const CameraSpec& camera, int width, int height, int stride, float tmax,
                int& hits) {
    const ViewPlane view = make_view_plane(camera, width, height);
    for (const std::string& isa : isas()) {
        SCOPED_TRACE(isa);
        IsaGuard guard(isa);
        hits = 0;
        for (int y0 = 0; y0 < height; y0 += 16)
            for (int x0 = 0; x0 < width; x0 += 16) {
                const int w = std::min(16, width - x0), h = std::min(16, height - y0);
                std::vector<Vec3f> dirs;
                for (int y = 0; y < h; ++y)
                    for (int x = 0; x < w; ++x)
                        dirs.push_back(
                            normalize(view.pixel_point(float(x0 + x) + 0.5f, float(y0 + y) + 0.5f) -
                                      view.eye));
                std::vector<Hit> tile(dirs.size());
                std::unique_ptr<bool[]> found(new bool[dirs.size()]);
                accel.intersect_tile(view.eye, dirs.data(), w, h, tile.data(), found.get(), tmax);
                // Told that the rays are too sparse for any instance's tree (as visibility's
                // samples along lines are): each crosses the trees alone.
                std::vector<Hit> alone(dirs.size());
                std::unique_ptr<bool[]> found_alone(new bool[dirs.size()]);
                accel.intersect_tile(view.eye, dirs.data(), w, h, alone.data(), found_alone.get(),
                                     tmax, std::numeric_limits<float>::infinity());
                for (std::size_t i = 0; i < dirs.size(); ++i) {
                    const Ray ray{view.eye, dirs[i], tmax};
                    Hit single;
                    const bool f = accel.intersect(ray, single);
                    ASSERT_TRUE(same_hit(tile[i], found[i], single, f))
                        << "tile against single ray at " << x0 + int(i) % w << ","
                        << y0 + int(i) / w;
                    ASSERT_TRUE(same_hit(alone[i], found_alone[i], single, f))
                        << "sparse tile against single ray at " << x0 + int(i) % w << ","
                        << y0 + int(i) / w;
                    ASSERT_EQ(accel.occluded(ray), f);
                    hits += f;
                    if ((x0 + int(i) % w + y0 + int(i) / w) % stride) continue;
                    const Hit ref = brute_force(own, placed, ray);
                    ASSERT_TRUE(same_hit(single, f, ref, ref.prim != kNoIndex))
                        << "single ray against brute force at " << x0 + int(i) % w << ","
                        << y0 + int(i) / w;
                }
            }
    }
}

TEST(Instances, RaysFindTheClosestHitInObjectSpace) {
    const Soup teapot = from_obj("teapot.obj");
    Soup small = random_soup(300, 7, 0.3f);
    for (Vec3f& p : small.positions) p = p * 0.8f;
    // The teapot is about 6 units across: scale it to the crowd's spacing.
    Soup pot = teapot;
    for (Vec3f& p : pot.positions) p = p * 0.2f;
    const auto a = accel_of(pot), b = accel_of(small);
    const std::vector<Placed> placed = crowd(pot, small, 40, 3);
    // Own triangles among them: a ground of random triangles.
    Soup ground = random_soup(200, 11, 0.5f);
    for (Vec3f& p : ground.positions) p = Vec3f(p.x * 5.0f, p.y * 0.1f - 0.6f, p.z * 5.0f);
    TriangleAccel accel;
    accel.build(ground.positions, ground.tris);
    accel.set_instances(accel_instances(placed, a, pot, b));
    EXPECT_EQ(accel.instance_count(), placed.size());
    const float inf = std::numeric_limits<float>::infinity();
    int hits = 0;
    check_view(accel, &ground, placed, CameraSpec{Vec3f(6, 4, 7), Vec3f(0, 0, 0), Vec3f(0, 1, 0)},
               96, 64, 23, inf, hits);
    EXPECT_GT(hits, 1500);
    // From inside the crowd, looking along a row; and with a finite tmax.
    check_view(accel, &ground, placed,
               CameraSpec{Vec3f(-3.5f, 0.2f, 0.3f), Vec3f(3, 0, 0.5f), Vec3f(0, 1, 0)}, 64, 48, 17,
               4.0f, hits);
    EXPECT_GT(hits, 500);
}

TEST(Instances, FarInstancesUnderFewRaysAreTracedRayByRayWithTheSameHits) {
    // Seen from far away each teapot (6,320 triangles) covers fewer rays than it has blocks of
    // four triangles, so a tile's rays go through it one by one; near, as groups. Both must
    // find what single rays and brute force find, ties included (coinciding instances).
    const Soup teapot = from_obj("teapot.obj");
    Soup pot = teapot;
    for (Vec3f& p : pot.positions) p = p * 0.2f;
    const auto a = accel_of(pot);
    std::vector<Placed> placed = crowd(pot, pot, 40, 5);
    placed.push_back(placed[7]);  // a twin: ties go to the lower instance
    TriangleAccel accel;
    accel.set_instances(accel_instances(placed, a, pot, a));
    const float inf = std::numeric_limits<float>::infinity();
    int hits = 0;
    check_view(accel, nullptr, placed,
               CameraSpec{Vec3f(40, 25, 45), Vec3f(0, 0, 0), Vec3f(0, 1, 0)}, 96, 64, 29, inf,
               hits);
    EXPECT_GT(hits, 300);
    check_view(accel, nullptr, placed,
               CameraSpec{Vec3f(2, 1.5f, 2.5f), Vec3f(0, 0, 0), Vec3f(0, 1, 0)}, 64, 48, 31, inf,
               hits);
    EXPECT_GT(hits, 500);
}

TEST(Instances, WithoutOwnTrianglesAndAxisAlignedViews) {
    // Rays along the axes in object space make groups irregular there (zero components),
    // which the tiles then trace ray by ray.
    const Soup teapot = from_obj("teapot.obj");
    Soup pot = teapot;
    for (Vec3f& p : pot.positions) p = p * 0.2f;
    const auto a = accel_of(pot);
    std::vector<Placed> placed;
    for (int i = 0; i < 4; ++i)
        placed.push_back({&pot, placement(Vec3f(0, 1, 0), 1.5707963267948966 * i, Vec3f(1.0f),
                                          Vec3f(1.5f * float(i) - 2.0f, 0, 0))});
    TriangleAccel accel;
    accel.set_instances(accel_instances(placed, a, pot, a));
    int hits = 0;
    check_view(accel, nullptr, placed, CameraSpec{Vec3f(0, 0, 9), Vec3f(0, 0, 0), Vec3f(0, 1, 0)},
               80, 32, 7, std::numeric_limits<float>::infinity(), hits);
    EXPECT_GT(hits, 200);
}

TEST(Instances, TiesOnATriangleSeenEdgeOnGoToTheOwnTrianglesThenTheLowestInstance) {
    // The render fuzzer's copies of a long triangle seen almost along its plane from far away
    // (Tile.TiesOnATriangleSeenEdgeOnGoToTheLowerIndex), as the own triangles and as two
    // instances in the same place: every hit ties three ways, and each tile, single ray and
    // occlusion query must agree with brute force.
    Soup s;
    s.positions = {{0.0f, 0.0f, 0.0f}, {0.0f, 9.0f, 2233721.0f}, {54.0f, 5.0f, 3.0f}};
    s.tris = {{0, 1, 2}, {0, 2, 1}, {0, 1, 2}, {0, 2, 1}, {0, 1, 2},
              {0, 2, 1}, {0, 1, 2}, {0, 2, 2}, {0, 2, 1}, {0, 1, 2}};
    const auto a = accel_of(s);
    const std::vector<Placed> placed{{&s, Affine3{}}, {&s, Affine3{}}};
    TriangleAccel accel;
    accel.build(s.positions, s.tris);
    accel.set_instances(accel_instances(placed, a, s, a));
    int hits = 0;
    check_view(accel, &s, placed, auto_camera(s.positions, 24, 16), 24, 16, 1,
               std::numeric_limits<float>::infinity(), hits);
    EXPECT_GE(hits, 1);  // the triangle is edge-on: a pixel
    // Without the own triangles the tie is between the instances.
    TriangleAccel instances_only;
    instances_only.set_instances(accel_instances(placed, a, s, a));
    check_view(instances_only, nullptr, placed, auto_camera(s.positions, 24, 16), 24, 16, 1,
               std::numeric_limits<float>::infinity(), hits);
    EXPECT_GE(hits, 1);
}

TEST(Instances, TiesGoToTheOwnTrianglesThenTheLowestInstance) {
    const Soup grid = random_soup(50, 5, 0.4f);
    const auto a = accel_of(grid);
    // Instances 0 and 1 at the same place (every hit at the same distance in both), instance 2
    // elsewhere; the own triangles are the mesh itself, where the identity puts instance 3.
    const Affine3 moved = placement(Vec3f(1, 1, 0), 0.7, Vec3f(1.0f), Vec3f(0.5f, 0, 0));
    std::vector<AccelInstance> instances{
        {a, moved}, {a, moved}, {a, Affine3::translation({9, 9, 9})}, {a, Affine3{}}};
    TriangleAccel accel;
    accel.build(grid.positions, grid.tris);
    accel.set_instances(instances);
    TriangleAccel reversed;  // the same two, listed the other way round
    reversed.set_instances(std::vector<AccelInstance>{{a, moved}, {a, moved}});
    const ViewPlane view =
        make_view_plane(CameraSpec{Vec3f(0, 0, 5), Vec3f(0, 0, 0), Vec3f(0, 1, 0)}, 48, 48);
    int own = 0, first = 0;
    for (const std::string& isa : isas()) {
        IsaGuard guard(isa);
        own = first = 0;
        for (int y = 0; y < 48; ++y)
            for (int x = 0; x < 48; ++x) {
                const Ray ray{view.eye, normalize(view.pixel_point(x + 0.5f, y + 0.5f) - view.eye)};
                Hit hit;
                if (!accel.intersect(ray, hit)) continue;
                // Instance 3 is the own triangles exactly: never reported; instance 1 never
                // beats instance 0.
                EXPECT_NE(hit.instance, 3u);
                EXPECT_NE(hit.instance, 1u);
                own += hit.instance == kNoIndex;
                Hit two;
                if (reversed.intersect(ray, two)) {
                    EXPECT_EQ(two.instance, 0u);
                    first += 1;
                }
            }
    }
    EXPECT_GT(own, 100);
    EXPECT_GT(first, 100);
}

TEST(Instances, MovingInstancesEqualsPlacingThemAgain) {
    Soup pot = from_obj("teapot.obj");
    for (Vec3f& p : pot.positions) p = p * 0.2f;
    const Soup small = random_soup(100, 9, 0.3f);
    const auto a = accel_of(pot), b = accel_of(small);
    const std::vector<Placed> before = crowd(pot, small, 12, 21), after = crowd(pot, small, 12, 22);
    TriangleAccel moved;
    moved.set_instances(accel_instances(before, a, pot, b));
    std::vector<Affine3> transforms;
    for (std::size_t i = 0; i < after.size(); ++i) transforms.push_back(after[i].to_world);
    // The meshes stay those of `before`: place the same meshes by `after`'s transforms.
    std::vector<Placed> expected = before;
    for (std::size_t i = 0; i < expected.size(); ++i) expected[i].to_world = transforms[i];
    moved.move_instances(transforms);
    int hits = 0;
    check_view(moved, nullptr, expected, CameraSpec{Vec3f(5, 5, 5), Vec3f(0, 0, 0), Vec3f(0, 1, 0)},
               64, 48, 13, std::numeric_limits<float>::infinity(), hits);
    EXPECT_GT(hits, 300);
    EXPECT_THROW(moved.move_instances(std::span(transforms).first(3)), Error);
}

TEST(Instances, BadInstancesAreRefused) {
    const Soup small = random_soup(10, 1);
    const auto a = accel_of(small);
    TriangleAccel accel;
    Affine3 flat;
    flat.m[2] = {0, 0, 0, 1};  // squashes z: no inverse
    EXPECT_THROW(accel.set_instances(std::vector<AccelInstance>{{a, flat}}), Error);
    EXPECT_THROW(accel.set_instances(std::vector<AccelInstance>{{nullptr, Affine3{}}}), Error);
    auto nested = std::make_shared<TriangleAccel>();
    nested->set_instances(std::vector<AccelInstance>{{a, Affine3{}}});
    EXPECT_THROW(accel.set_instances(std::vector<AccelInstance>{{nested, Affine3{}}}), Error);
}

TEST(Instances, MemoryPerInstanceIsSmall) {
    Soup pot = from_obj("teapot.obj");
    const auto a = accel_of(pot);
    std::vector<AccelInstance> many;
    for (int i = 0; i < 10000; ++i)
        many.push_back({a, placement(Vec3f(0, 1, 0), 0.001 * i, Vec3f(1.0f),
                                     Vec3f(float(i % 100) * 8, 0, float(i / 100) * 8))});
    TriangleAccel accel;
    accel.set_instances(many);
    const double per_instance = double(accel.instance_level_bytes()) / 10000.0;
    EXPECT_LE(per_instance, double(kBytesPerInstance));
    // The mesh's tree is counted once, however many instances use it.
    EXPECT_EQ(accel.memory_bytes(), a->memory_bytes() + accel.instance_level_bytes());
    std::printf("instance level: %.1f bytes per instance\n", per_instance);
}

}  // namespace
