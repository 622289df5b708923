// shade_samples against the scalar shading functions, sample by sample, bit for bit.
#include "toonray/render/shade_samples.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <random>
#include <vector>

#include "toonray/render/renderer.h"
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

    std::vector<Vec3f> colour(n), geometric(n), shading(n);
    std::vector<float> view_depth(n), distance(n);
    std::vector<std::uint32_t> material(n), object(n);
    std::vector<std::uint8_t> hit_flags(n);
    for (int kind = 0; kind < 3; ++kind) {
        ShadedSamples out;
        out.colour = colour.data();
        if (kind != 2) out.found = hit_flags.data();
        if (kind == 1) {
            out.view_depth = view_depth.data();
            out.geometric_normal = geometric.data();
        }
        if (kind == 2) {
            out.distance = distance.data();
            out.shading_normal = shading.data();
        }
        if (kind != 0) {
            out.material = material.data();
            out.object = object.data();
        }
        shade_samples(ctx, view, background, n, dirs.data(), hits.data(), found.get(), out);
        for (int i = 0; i < n; ++i) {
            if (kind != 2) {
                ASSERT_EQ(hit_flags[i], found[i] ? 1 : 0);
            }
            if (!found[i]) {
                ASSERT_TRUE(same_bits(colour[i], background));
                continue;
            }
            const Vec3f normal = shading_normal(scene, hits[i], dirs[i]);
            ASSERT_TRUE(same_bits(colour[i], shade_hit(ctx, hits[i], view.eye, dirs[i], normal)))
                << "sample " << i;
            if (kind == 1) {
                ASSERT_TRUE(same_bits(geometric[i], geometric_normal(scene, hits[i], dirs[i])));
                ASSERT_EQ(view_depth[i], hits[i].t * dot(dirs[i], view.forward));
            }
            if (kind == 2) {
                ASSERT_TRUE(same_bits(shading[i], normal)) << "sample " << i;
                ASSERT_EQ(distance[i], hits[i].t);
            }
            if (kind != 0) {
                ASSERT_EQ(material[i], scene.tri_material[hits[i].prim]);
                ASSERT_EQ(object[i], scene.tri_object[hits[i].prim]);
            }
        }
    }
}
