// Adaptive sampling (render/sampler.h): which pixels take all their samples, what those and the
// others come out as, and that frames do not depend on how they are cut into buckets.
#include "toonray/render/sampler.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>

#include "toonray/render/classic.h"
#include "toonray/render/renderer.h"
#include "toonray/render/trace.h"
#include "toonray/scene/obj_loader.h"
#include "support/image_compare.h"
#include "support/same_layers.h"
#include "support/test_scenes.h"

using namespace toonray;

namespace {

Scene load(const std::string& name) { return test_support::load_test_scene(name); }

// One scene, its BVH, camera and the renderer's lighting, for tracing samples by hand.
struct SceneView {
    Scene scene;
    TriangleAccel accel;
    RenderSettings settings;
    CameraSpec camera;
    ViewPlane view;
    std::vector<Light> lights;

    SceneView(const std::string& name, int width, int height) : scene(load(name)) {
        accel.build(scene.positions, scene.tri_positions);
        settings.width = width;
        settings.height = height;
        camera = test_support::framing_camera(scene, width, height);
        view = make_view_plane(camera, width, height);
        lights = test_support::default_lights(scene, camera);
    }

    // The colour of fine-grid sample (x, y), traced and shaded one ray at a time.
    [[nodiscard]] Vec3f sample_colour(int x, int y, int sub) const {
        const ShadingContext ctx{scene, accel, settings.shading, lights, nullptr};
        const Vec3f dir = sample_direction(view, x, y, sub);
        Hit hit;
        if (!accel.intersect(Ray{view.eye, dir}, hit)) return settings.background;
        return shade_hit(ctx, hit, view.eye, dir, shading_normal(scene, hit, dir));
    }
    // A pixel's mean over its sub x sub samples, summed row by row, as bytes.
    [[nodiscard]] Rgb8 mean_colour(int x, int y, int sub) const {
        Vec3f sum(0.0f);
        for (int j = 0; j < sub; ++j)
            for (int i = 0; i < sub; ++i) sum += sample_colour(x * sub + i, y * sub + j, sub);
        sum = sum * (1.0f / static_cast<float>(sub * sub));
        return {to_byte(sum.x), to_byte(sum.y), to_byte(sum.z)};
    }
};

Rgb8 bytes(const Vec3f& c) { return {to_byte(c.x), to_byte(c.y), to_byte(c.z)}; }

}  // namespace

TEST(PixelRect, GrowsWithinTheImage) {
    const PixelRect r{10, 0, 20, 5};
    EXPECT_EQ(r.grown(3, 22, 100), (PixelRect{7, 0, 22, 8}));
    EXPECT_TRUE(r.contains(10, 4));
    EXPECT_FALSE(r.contains(20, 4));
    const BucketGrid grid{130, 70, 64};
    EXPECT_EQ(grid.count(), 6);
    EXPECT_EQ(grid.bucket(2), (PixelRect{128, 0, 130, 64}));
    EXPECT_EQ(grid.bucket(5), (PixelRect{128, 64, 130, 70}));
}

// A bucket sampled by hand: refined pixels are exactly full supersampling's; the others are
// their first sample, and differ from their neighbours' first samples nowhere.
TEST(BucketSampler, RefinedPixelsAreFullSupersamplingAndTheRestTheirFirstSample) {
    SceneView s("spot.obj", 160, 90);
    const int sub = 2;
    const ShadingContext ctx{s.scene, s.accel, s.settings.shading, s.lights, nullptr};
    const LookFrame look{s.scene, s.settings.shading, s.settings.background, false};
    for (bool adaptive : {true, false}) {
        const SamplerFrame frame{s.accel, ctx, look, s.view, 160, 90, sub, adaptive, RefineRule{}};
        BucketSampler sampler;
        const PixelRect decided{40, 20, 104, 70};
        sampler.sample(frame, decided.grown(1, 160, 90), decided);
        ImageRgb8 out(decided.width(), decided.height());
        sampler.resolve_colours(decided, out, decided.x0, decided.y0);
        int refined = 0;
        for (int y = decided.y0; y < decided.y1; ++y)
            for (int x = decided.x0; x < decided.x1; ++x) {
                const Rgb8 got = out(x - decided.x0, y - decided.y0);
                if (sampler.refined(x, y)) {
                    ++refined;
                    ASSERT_EQ(got, s.mean_colour(x, y, sub)) << x << "," << y;
                    continue;
                }
                const Rgb8 first = bytes(s.sample_colour(x * sub, y * sub, sub));
                ASSERT_EQ(got, first) << x << "," << y;
                for (auto [dx, dy] : {std::pair{-1, 0}, {1, 0}, {0, -1}, {0, 1}})
                    ASSERT_EQ(bytes(s.sample_colour((x + dx) * sub, (y + dy) * sub, sub)), first);
            }
        EXPECT_EQ(static_cast<std::size_t>(refined), sampler.refined_count());
        if (adaptive) {
            // Spot's outline and bands cross the bucket: some pixels, far from all.
            EXPECT_GT(refined, 100);
            EXPECT_LT(refined, decided.width() * decided.height() / 2);
        } else {
            EXPECT_EQ(refined, decided.width() * decided.height());
        }
    }
}

TEST(AdaptiveSampling, FramesAreTheSameForAnyBucketSizeAndThreadCount) {
    for (const char* name : {"teapot.obj", "spot.obj"}) {
        SceneView s(name, 200, 120);
        for (LineMode mode : {LineMode::Ink, LineMode::Robust}) {
            RenderSettings settings = s.settings;
            settings.lines.mode = mode;
            settings.layers = true;
            Renderer reference_renderer;
            const ImageRgb8 reference = reference_renderer.render(
                s.scene, s.accel, s.camera, test_support::default_lights(s.scene, s.camera),
                settings);
            for (int tile : {1, 7, 64, 1000})
                for (int threads : {1, 2, 3}) {
                    settings.sampling.tile_size = tile;
                    settings.threads = threads;
                    Renderer r;
                    const ImageRgb8& image =
                        r.render(s.scene, s.accel, s.camera,
                                 test_support::default_lights(s.scene, s.camera), settings);
                    ASSERT_EQ(0, std::memcmp(image.data(), reference.data(), image.size() * 3))
                        << name << " tile " << tile << " threads " << threads;
                    EXPECT_EQ(r.refined_pixels(), reference_renderer.refined_pixels());
                    ASSERT_TRUE(test_support::same_layers(r.layers(), reference_renderer.layers()))
                        << name << " tile " << tile << " threads " << threads;
                }
        }
    }
}

// Adaptive frames against full supersampling (--adaptive off), the pictures the users had:
// at most 0.5% of pixels may differ by more than 2/255, with far fewer samples traced.
TEST(AdaptiveSampling, StaysWithinFullSupersampling) {
    for (const char* name : {"teapot.obj", "spot.obj"}) {
        SceneView s(name, 640, 360);
        for (LineMode mode : {LineMode::Ink, LineMode::Robust}) {
            RenderSettings settings = s.settings;
            settings.lines.mode = mode;
            Renderer adaptive, full;
            const ImageRgb8 a =
                adaptive.render(s.scene, s.accel, s.camera,
                                test_support::default_lights(s.scene, s.camera), settings);
            settings.sampling.adaptive = false;
            const ImageRgb8& b =
                full.render(s.scene, s.accel, s.camera,
                            test_support::default_lights(s.scene, s.camera), settings);
            const double differing = test_support::share_differing(a, b, 2);
            const double refined =
                static_cast<double>(adaptive.refined_pixels()) / static_cast<double>(a.size());
            std::printf("%s %s: %.3f%% of pixels differ by more than 2/255; %.1f%% refined\n", name,
                        mode == LineMode::Ink ? "ink" : "robust", 100 * differing, 100 * refined);
            EXPECT_LE(differing, 0.005) << name;
            EXPECT_EQ(full.refined_pixels(), a.size());
            EXPECT_LT(refined, 0.25) << name;
        }
    }
}
