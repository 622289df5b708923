// TriangleAccel::occluded against intersect and brute force: a ray is occluded exactly when
// some triangle is hit with 0 < t < tmax, on every instruction set this machine runs.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "toonray/accel/triangle_accel.h"
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

bool brute_force_occluded(const Soup& s, const Ray& ray) {
    for (const auto& tri : s.tris) {
        float t, u, v;
        if (intersect_triangle(ray, s.positions[tri[0]], s.positions[tri[1]], s.positions[tri[2]],
                               t, u, v))
            return true;
    }
    return false;
}

// The tmax values that decide occlusion for a ray whose closest hit is at `t`: the hit itself
// (not occluded: the range is open), the floats on either side of it, half of it, and none.
std::vector<float> tmax_around(float t) {
    const float inf = std::numeric_limits<float>::infinity();
    if (!std::isfinite(t)) return {inf, 1.0f, 0.5f};
    return {inf, t, std::nextafter(t, inf), std::nextafter(t, 0.0f), t * 0.5f, t * 2.0f};
}

// Rays between random points around and inside the mesh, with tmax around each closest hit:
// occluded agrees with intersect on every ray, and with brute force on every `check`-th.
void expect_agrees(const Soup& s, int rays, unsigned seed, int check) {
    TriangleAccel accel;
    accel.build(s.positions, s.tris);
    BBox box;
    for (const Vec3f& p : s.positions) box.extend(p);
    const float radius = length(box.extent());
    std::mt19937 rng(seed);
    std::normal_distribution<float> n(0.0f, 1.0f);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    auto inside = [&] {
        return Vec3f(box.lo.x + u(rng) * box.extent().x, box.lo.y + u(rng) * box.extent().y,
                     box.lo.z + u(rng) * box.extent().z);
    };
    for (const std::string& isa : isas()) {
        IsaGuard guard(isa);
        SCOPED_TRACE(isa);
        int occluded = 0, clear = 0;
        for (int i = 0; i < rays; ++i) {
            // Half from outside, half from inside (as shadow rays start on surfaces).
            const Vec3f from =
                i % 2 ? inside()
                      : box.center() + normalize(Vec3f(n(rng), n(rng), n(rng))) * radius * 1.5f;
            const Vec3f dir = inside() - from;
            Hit closest;
            accel.intersect(Ray{from, dir}, closest);
            for (float tmax : tmax_around(closest.t)) {
                const Ray ray{from, dir, tmax};
                Hit hit;
                const bool expected = accel.intersect(ray, hit);
                const bool got = accel.occluded(ray);
                ASSERT_EQ(got, expected) << "ray " << i << " tmax " << tmax;
                if (i % check == 0) {
                    ASSERT_EQ(got, brute_force_occluded(s, ray)) << "ray " << i << " tmax " << tmax;
                }
                (got ? occluded : clear)++;
            }
        }
        // Both answers must actually occur.
        EXPECT_GT(occluded, rays / 4);
        EXPECT_GT(clear, rays / 4);
    }
}

}  // namespace

TEST(Occlusion, RandomSoupsAgreeWithIntersectAndBruteForce) {
    for (unsigned seed : {1u, 2u, 3u}) {
        SCOPED_TRACE(seed);
        expect_agrees(random_soup(2000, seed), 1000, seed, 4);
    }
}

TEST(Occlusion, LargeTrianglesAndLongLeaves) {
    // Few large, overlapping triangles: many hits per ray and leaves of many triangles.
    expect_agrees(random_soup(300, 7, 1.0f), 1000, 7, 1);
}

TEST(Occlusion, RealMeshesAgreeWithIntersect) {
    for (const char* name : {"teapot.obj", "spot.obj"}) {
        SCOPED_TRACE(name);
        expect_agrees(from_obj(name), 2000, 11, 16);
    }
}

TEST(Occlusion, SharedEdgesLetNoRayThrough) {
    // Two triangles sharing the diagonal of a unit square; rays straight down through points on
    // the diagonal are blocked, exactly as intersect finds them.
    const Soup s = unit_square({{0, 1, 2}, {0, 2, 3}});
    TriangleAccel accel;
    accel.build(s.positions, s.tris);
    for (const std::string& isa : isas()) {
        IsaGuard guard(isa);
        for (int i = 1; i < 64; ++i) {
            const float x = static_cast<float>(i) / 64.0f;
            const Ray ray{{x, x, 1.0f}, {0.0f, 0.0f, -1.0f}};
            Hit hit;
            ASSERT_TRUE(accel.intersect(ray, hit)) << isa << " " << x;
            EXPECT_TRUE(accel.occluded(ray)) << isa << " " << x;
            // The surface is at t = 1: a shorter ray is not blocked, a ray ending exactly there
            // is not either (0 < t < tmax).
            EXPECT_FALSE(accel.occluded(Ray{ray.origin, ray.dir, 0.5f})) << isa << " " << x;
            EXPECT_FALSE(accel.occluded(Ray{ray.origin, ray.dir, 1.0f})) << isa << " " << x;
            EXPECT_TRUE(accel.occluded(Ray{ray.origin, ray.dir, std::nextafter(1.0f, 2.0f)}))
                << isa << " " << x;
        }
    }
}

TEST(Occlusion, EmptyAcceleratorOccludesNothing) {
    TriangleAccel accel;
    accel.build({}, {});
    EXPECT_FALSE(accel.occluded(Ray{{0, 0, 0}, {0, 0, 1}}));
}
