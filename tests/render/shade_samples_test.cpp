// shade_samples against the scalar shading functions, sample by sample, bit for bit.
#include "toonray/render/shade_samples.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <random>
#include <vector>

#include "toonray/render/look.h"
#include "toonray/render/trace.h"
#include "support/test_scenes.h"
#include "support/same_bits.h"

using namespace toonray;

namespace {

using test_support::same_bits;

// The teapot (no vertex normals) beside a fan with vertex normals, one of them zero (so
// interpolation fails near it), and a degenerate triangle; two materials.
Scene mixed_scene() {
    Scene s = test_support::load_test_scene("teapot.obj");
    const auto base = static_cast<std::uint32_t>(s.positions.size());
    s.positions.insert(s.positions.end(),
                       {{-4, -1, 2}, {4, -1, 2}, {4, 3, 1}, {-4, 3, 2}, {0, 5, 2}, {1, 5, 2}});
    const auto normals = static_cast<std::uint32_t>(s.normals.size());
    s.normals.insert(s.normals.end(), {{0, 0, 1}, {0.6f, 0, 0.8f}, {0, 0, 0}, {0, 0.6f, 0.8f}});
    Material paint("paint");
    paint.kd = Vec3f(0.9f, 0.3f, 0.2f);
    s.materials.push_back(paint);
    const auto m = static_cast<std::uint32_t>(s.materials.size() - 1);
    s.add_triangle({base, base + 1, base + 2}, m, 0);
    s.tri_normals.back() = {normals, normals + 1, normals + 2};
    s.add_triangle({base, base + 2, base + 3}, m, 0);
    s.tri_normals.back() = {normals, normals + 1, normals + 3};
    s.add_triangle({base + 3, base + 4, base + 5}, m, 0);  // no normals
    s.add_triangle({base, base, base + 1}, m, 0);          // degenerate
    return s;
}

}  // namespace

TEST(ShadeSamples, EqualsTheScalarShadingOfEverySample) {
    const Scene scene = mixed_scene();
    TriangleAccel accel;
    accel.build(scene.positions, scene.tri_positions);
    const int w = 160, h = 120;
    const CameraSpec camera = test_support::framing_camera(scene, w, h);
    const ViewPlane view = make_view_plane(camera, w, h);
    const std::vector<Light> lights{{Light::Kind::Point, Vec3f(2, 6, 9), 1.0f}};
    ShadingSettings settings;
    const ShadingContext ctx{scene, accel, settings, lights, nullptr};
    const Vec3f background(0.25f, 0.5f, 1.0f);

    // Every pixel centre, then the same rays shuffled so that runs on one triangle are short.
    std::vector<Vec3f> dirs;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) dirs.push_back(sample_direction(view, x, y, 1));
    std::vector<Vec3f> shuffled = dirs;
    std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(3));
    dirs.insert(dirs.end(), shuffled.begin(), shuffled.end());
    const int n = static_cast<int>(dirs.size());
    std::vector<Hit> hits(n);
    std::unique_ptr<bool[]> found(new bool[n]);
    int hit_count = 0;
    for (int i = 0; i < n; ++i) {
        found[i] = accel.intersect(Ray{view.eye, dirs[i]}, hits[i]);
        hit_count += found[i];
    }
    ASSERT_GT(hit_count, n / 8);

    const LookFrame look{scene, settings, background, false};
    // Every set of fields a line mode keeps, and all of them.
    for (unsigned fields : {0u, unsigned(kSurfaceKeys), unsigned(kSurfaceDistance),
                            unsigned(kSurfaceKeys | kSurfaceViewDepth), unsigned(kSurfaceAll)}) {
        SurfaceSamples out;
        out.resize(static_cast<std::size_t>(n) + 3, fields, 1);
        shade_samples(ctx, look, view, n, dirs.data(), hits.data(), found.get(), out, 3);
        for (int k = 0; k < n; ++k) {
            const std::size_t i = static_cast<std::size_t>(k) + 3;
            ASSERT_EQ(out.found[i], found[k] ? 1 : 0);
            if (!found[k]) {
                ASSERT_TRUE(same_bits(out.colour[i], background));
                if (out.has(kSurfaceKeys)) {
                    ASSERT_EQ(out.object[i], kNoIndex);
                    ASSERT_EQ(out.band[i], kNoBand);
                }
                continue;
            }
            const Hit& hit = hits[k];
            const Vec3f normal = shading_normal(scene, hit, dirs[k]);
            ASSERT_TRUE(same_bits(out.colour[i], shade_hit(ctx, hit, view.eye, dirs[k], normal)))
                << "sample " << k;
            float n_dot_l = 0.0f;
            const LightTerms terms = light_terms(ctx, hit, view.eye, dirs[k], normal, &n_dot_l);
            if (out.has(kSurfaceKeys)) {
                ASSERT_EQ(out.band[i], terms.band);
                ASSERT_EQ(out.accents[i], terms.accents);
                ASSERT_EQ(out.material[i], scene.tri_material[hit.prim]);
                ASSERT_EQ(out.object[i], scene.tri_object[hit.prim]);
            }
            if (out.has(kSurfaceDistance)) {
                ASSERT_TRUE(same_bits(out.normal[i], normal)) << "sample " << k;
                ASSERT_EQ(out.distance[i], hit.t);
            }
            if (out.has(kSurfaceViewDepth)) {
                ASSERT_TRUE(
                    same_bits(out.geometric_normal[i], geometric_normal(scene, hit, dirs[k])));
                ASSERT_EQ(out.view_depth[i], hit.t * dot(dirs[k], view.forward));
            }
            if (out.has(kSurfaceWhere)) {
                ASSERT_EQ(out.prim[i], hit.prim);
                ASSERT_TRUE(same_bits(out.albedo[i], terms.albedo));
                ASSERT_TRUE(same_bits(out.position[i], view.eye + dirs[k] * hit.t));
                ASSERT_EQ(out.diffuse[i], terms.diffuse);
                ASSERT_EQ(out.n_dot_l[i], n_dot_l);
                ASSERT_EQ(out.shadowed[i], 0u);
            }
        }
        // Only the arrays of the fields asked for are kept.
        EXPECT_EQ(out.object.size(), out.has(kSurfaceKeys) ? out.size() : 0u);
        EXPECT_EQ(out.distance.size(), out.has(kSurfaceDistance) ? out.size() : 0u);
        EXPECT_EQ(out.view_depth.size(), out.has(kSurfaceViewDepth) ? out.size() : 0u);
        EXPECT_EQ(out.position.size(), out.has(kSurfaceWhere) ? out.size() : 0u);
    }
}

TEST(ShadeSamples, LightTermsRecordEachLightAndItsShadow) {
    // A floor and a square hovering over its middle; two directional lights from above, the
    // second dimmer and slanted. Below the square the first light is blocked.
    Scene s;
    s.positions = {{-10, -10, 0}, {10, -10, 0}, {10, 10, 0}, {-10, 10, 0},
                   {-2, -2, 3},   {2, -2, 3},   {2, 2, 3},   {-2, 2, 3}};
    s.add_triangle({0, 1, 2}, 0, 0);
    s.add_triangle({0, 2, 3}, 0, 0);
    s.add_triangle({4, 5, 6}, 0, 0);
    s.add_triangle({4, 6, 7}, 0, 0);
    TriangleAccel accel;
    accel.build(s.positions, s.tri_positions);
    ShadingSettings settings;
    settings.shadows = true;
    const std::vector<Light> lights{{Light::Kind::Directional, {0, 0, -1}, 1.0f},
                                    {Light::Kind::Directional, {0.6f, 0, -0.8f}, 0.25f}};
    const ShadingContext ctx{s, accel, settings, lights, nullptr};
    const LookFrame look{s, settings, Vec3f(1.0f), false};
    // Straight down onto the floor: under the square (blocked) and beside it (lit).
    const Vec3f eye(0, 0, 20);
    std::vector<Vec3f> dirs{normalize(Vec3f(0, 0, -20)), normalize(Vec3f(8, 0, -20))};
    std::vector<Hit> hits(2);
    bool found[2];
    // The first ray hits the square's top, so aim the first one under it from the side.
    const Vec3f side(-6, 0, 0.5f);
    dirs[0] = normalize(Vec3f(0, 0, 0) - side);
    found[0] = accel.intersect(Ray{side, dirs[0]}, hits[0]);
    found[1] = accel.intersect(Ray{eye, dirs[1]}, hits[1]);
    ASSERT_TRUE(found[0] && found[1]);
    const ViewPlane view0{side, {}, {}, {}, {1, 0, 0}, {0, 0, 1}, dirs[0]};
    SurfaceSamples out;
    out.resize(1, kSurfaceAll, 2);
    shade_samples(ctx, look, view0, 1, dirs.data(), hits.data(), found, out, 0);
    EXPECT_EQ(out.shadowed[0], 1u);  // the first light is blocked, the slanted one is not
    EXPECT_FLOAT_EQ(out.n_dot_l[0], 1.0f);
    EXPECT_FLOAT_EQ(out.n_dot_l[1], 0.8f);
    EXPECT_FLOAT_EQ(out.diffuse[0], 0.25f * 0.8f);
    const ViewPlane view1{eye, {}, {}, {}, {1, 0, 0}, {0, 1, 0}, {0, 0, -1}};
    shade_samples(ctx, look, view1, 1, dirs.data() + 1, hits.data() + 1, found + 1, out, 0);
    EXPECT_EQ(out.shadowed[0], 0u);
    EXPECT_FLOAT_EQ(out.diffuse[0], 1.0f + 0.25f * 0.8f);
}
