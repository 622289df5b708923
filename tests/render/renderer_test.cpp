#include "toonray/render/renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string_view>
#include <thread>
#include <vector>

#include "toonray/io/png.h"
#include "toonray/render/classic.h"
#include "toonray/render/robust.h"
#include "toonray/scene/obj_loader.h"
#include "support/test_scenes.h"
#include "support/same_layers.h"
#include "support/test_support.h"

using namespace toonray;
namespace fs = std::filesystem;

namespace {

Scene load(const std::string& name) { return test_support::load_test_scene(name); }

// A square in the plane z = 0 from (-a,-a) to (a,a), facing +z, with the given Kd.
Scene square(float a, Vec3f kd) {
    Scene s;
    s.positions = {{-a, -a, 0}, {a, -a, 0}, {a, a, 0}, {-a, a, 0}};
    Material m("paint");
    m.kd = kd;
    s.materials.push_back(m);
    s.add_triangle({0, 1, 2}, 1, 0);
    s.add_triangle({0, 2, 3}, 1, 0);
    return s;
}

// The automatic camera for a whole scene at the settings' size.
CameraSpec framing_camera(const Scene& s, const RenderSettings& settings) {
    return test_support::framing_camera(s, settings.width, settings.height);
}

template <typename T>
std::uint64_t bytes_of(const Image<T>& image) {
    return image.size() * sizeof(T);
}

// Renders with the layers and returns them.
const FrameLayers& render_scene(Renderer& r, const Scene& s, const CameraSpec& cam,
                                RenderSettings settings, std::vector<Light> lights = {}) {
    static TriangleAccel accel;
    accel.build(s.positions, s.tri_positions);
    settings.layers = true;
    if (lights.empty()) lights = test_support::default_lights(s, cam);
    r.render(s, accel, cam, lights, settings);
    return r.layers();
}

std::vector<Light> point_light(const Vec3f& position) {
    return {Light{Light::Kind::Point, position, 1.0f}};
}

}  // namespace

TEST(Renderer, FlatSquareFacingTheLightIsItsKdWithoutLines) {
    Scene s = square(10.0f, {0.2f, 0.4f, 0.6f});
    // Looking straight down at a plane 5 units away; a narrow field of view keeps depth nearly
    // constant, and a light far along the normal gives l.n close to 1 everywhere.
    CameraSpec cam{{0, 0, 5}, {0, 0, 1}, {0, 1, 0}};
    for (LineMode mode : {LineMode::Classic, LineMode::Robust}) {
        RenderSettings settings;
        settings.lines.mode = mode;
        settings.width = 128;
        settings.height = 96;
        Renderer r;
        TriangleAccel accel;
        accel.build(s.positions, s.tri_positions);
        const ImageRgb8& out = r.render(s, accel, cam, point_light({0, 0, 1e4f}), settings);
        for (int y = 0; y < settings.height; ++y)
            for (int x = 0; x < settings.width; ++x)
                ASSERT_EQ(out(x, y), (Rgb8{51, 102, 153})) << x << "," << y;
    }
}

TEST(Renderer, CelBandsFollowThePointLight) {
    // Light 2 units above the origin of the plane z = 0: l.n = 2 / sqrt(4 + r^2) at distance r
    // from its foot. The bands must follow that formula pixel by pixel.
    Scene s = square(10.0f, {1.0f, 1.0f, 1.0f});
    CameraSpec cam{{0, 0, 8}, {0, 0, 7}, {0, 1, 0}};  // 90 degrees: sees x in [-8, 8]
    RenderSettings settings;
    settings.lines.mode = LineMode::Classic;  // one sample per pixel: bands are the formula's
    settings.width = 160;
    settings.height = 120;
    Renderer r;
    const FrameLayers& layers = render_scene(r, s, cam, settings, point_light({0, 0, 2}));
    ViewPlane view = make_view_plane(cam, settings.width, settings.height);
    int checked = 0, bands[3] = {0, 0, 0};
    for (int y = 0; y < settings.height; ++y)
        for (int x = 0; x < settings.width; ++x) {
            Vec3f p = view.pixel_point(x + 0.5f, y + 0.5f);
            Vec3f dir = p - cam.eye;
            Vec3f hit = cam.eye + dir * (-cam.eye.z / dir.z);  // on z = 0
            float l_dot_n = 2.0f / std::sqrt(4.0f + hit.x * hit.x + hit.y * hit.y);
            float scaled = l_dot_n * 16.0f;
            if (std::abs(scaled - std::round(scaled)) < 1e-3f) continue;  // on a band boundary
            const int band = l_dot_n < 0.25f ? 0 : (l_dot_n < 0.5f ? 1 : 2);
            ASSERT_EQ(layers.band(x, y), band) << x << "," << y;
            const float level = settings.shading.ramp.levels[band];
            ASSERT_EQ(layers.cel(x, y)[0], to_byte(level)) << x << "," << y;
            ASSERT_NEAR(layers.light(x, y), l_dot_n, 1e-4f) << x << "," << y;
            bands[band]++;
            ++checked;
        }
    EXPECT_GT(checked, settings.width * settings.height * 9 / 10);
    for (int b : bands) EXPECT_GT(b, 100);  // all three bands appear
}

TEST(Renderer, SilhouetteOfASquareOnBackgroundIsOutlined) {
    Scene s = square(1.0f, {0.5f, 0.5f, 0.5f});
    CameraSpec cam{
        {0, 0, 4}, {0, 0, 3}, {0, 1, 0}};  // sees x in [-4, 4]: the square is the middle quarter
    RenderSettings settings;
    settings.lines.mode = LineMode::Classic;
    settings.width = 200;
    settings.height = 200;
    settings.layers = true;
    Renderer r;
    TriangleAccel accel;
    accel.build(s.positions, s.tri_positions);
    const ImageRgb8& out = r.render(s, accel, cam, point_light({0, 0, 100}), settings);
    // Square covers pixels [75, 125). Its border pixels are lines; inside and far outside are not.
    EXPECT_EQ(out(100, 100), (Rgb8{128, 128, 128}));
    EXPECT_EQ(out(10, 10), (Rgb8{255, 255, 255}));
    for (int i = 80; i < 120; ++i) {
        EXPECT_LT(out(75, i)[0], 60) << i;
        EXPECT_LT(out(124, i)[0], 60) << i;
        EXPECT_LT(out(i, 75)[0], 60) << i;
        EXPECT_LT(out(i, 124)[0], 60) << i;
    }
    const FrameLayers& layers = r.layers();
    EXPECT_EQ(layers.lines(75, 100), 1.0f);
    EXPECT_EQ(layers.lines(100, 100), 0.0f);
    EXPECT_TRUE(std::isinf(layers.distance(10, 10)));  // miss
    EXPECT_EQ(layers.object(10, 10), kNoIndex);
    EXPECT_EQ(layers.band(10, 10), kNoBand);
    EXPECT_EQ(layers.normal(10, 10), Vec3f(0, 0, 0));
    EXPECT_EQ(layers.normal(100, 100), Vec3f(0, 0, 1));  // facing +z
    EXPECT_EQ(layers.position(100, 100).z, 0.0f);
}

TEST(Renderer, NormalsFaceTheViewer) {
    // The same square seen from below: its geometric normal (+z) is flipped to face the eye.
    Scene s = square(1.0f, {1, 1, 1});
    CameraSpec cam{{0, 0, -4}, {0, 0, -3}, {0, 1, 0}};
    RenderSettings settings;
    settings.lines.mode = LineMode::Classic;
    settings.width = 32;
    settings.height = 32;
    Renderer r;
    EXPECT_EQ(render_scene(r, s, cam, settings).normal(16, 16), Vec3f(0, 0, -1));
}

TEST(Renderer, InterpolatesVertexNormalsOnlyWhenAllCornersHaveThem) {
    Scene s = square(1.0f, {1, 1, 1});
    s.normals = {normalize(Vec3f(1, 0, 1)), normalize(Vec3f(-1, 0, 1))};
    s.tri_normals[0] = {0, 1, 1};         // all corners: interpolated
    s.tri_normals[1] = {0, kNoIndex, 1};  // one missing: geometric
    CameraSpec cam{{0, 0, 4}, {0, 0, 3}, {0, 1, 0}};
    RenderSettings settings;
    settings.lines.mode = LineMode::Classic;
    settings.width = 64;
    settings.height = 64;
    Renderer r;
    const FrameLayers& layers = render_scene(r, s, cam, settings);
    // Pixel (34, 33) lies in triangle 0 (below the diagonal y = x), (30, 29) in triangle 1.
    Vec3f n0 = layers.normal(36, 33);
    EXPECT_GT(std::abs(n0.x), 0.01f);
    EXPECT_NEAR(length(n0), 1.0f, 1e-5f);
    EXPECT_EQ(layers.normal(28, 29), Vec3f(0, 0, 1));
    EXPECT_EQ(layers.geometric_normal(36, 33), Vec3f(0, 0, 1));
}

TEST(Renderer, OutputIsIdenticalForEveryThreadCount) {
    Scene s = load("teapot.obj");
    RenderSettings settings;
    settings.width = 320;
    settings.height = 180;
    settings.layers = true;
    CameraSpec cam = framing_camera(s, settings);
    TriangleAccel accel;
    accel.build(s.positions, s.tri_positions);
    Renderer one, two, many;
    settings.threads = 1;
    for (LineMode mode : {LineMode::Classic, LineMode::Robust, LineMode::Ink}) {
        settings.lines.mode = mode;
        settings.threads = 1;
        ImageRgb8 a = one.render(s, accel, cam, test_support::default_lights(s, cam), settings);
        settings.threads = 2;
        ImageRgb8 b = two.render(s, accel, cam, test_support::default_lights(s, cam), settings);
        settings.threads = 7;
        ImageRgb8 c = many.render(s, accel, cam, test_support::default_lights(s, cam), settings);
        ASSERT_EQ(0, std::memcmp(a.data(), b.data(), a.size() * 3));
        ASSERT_EQ(0, std::memcmp(a.data(), c.data(), a.size() * 3));
        ASSERT_TRUE(test_support::same_layers(one.layers(), two.layers()));
        ASSERT_TRUE(test_support::same_layers(one.layers(), many.layers()));
    }
}

TEST(Renderer, MatchesABruteForceReference) {
    // The same pixels traced by testing every triangle: the BVH must find the same surfaces.
    Scene s = load("spot.obj");
    RenderSettings settings;
    settings.lines.mode = LineMode::Classic;  // one sample at each pixel's centre
    settings.width = 160;
    settings.height = 90;
    settings.layers = true;  // the Euclidean distance of each pixel's sample
    CameraSpec cam = framing_camera(s, settings);
    TriangleAccel accel;
    accel.build(s.positions, s.tri_positions);
    Renderer r;
    r.render(s, accel, cam, test_support::default_lights(s, cam), settings);
    ViewPlane view = make_view_plane(cam, settings.width, settings.height);
    int mismatches = 0, hits = 0;
    for (int y = 0; y < settings.height; ++y)
        for (int x = 0; x < settings.width; ++x) {
            Vec3f dir = normalize(view.pixel_point(x + 0.5f, y + 0.5f) - cam.eye);
            Ray ray{cam.eye, dir};
            float best = std::numeric_limits<float>::infinity();
            for (std::size_t i = 0; i < s.triangle_count(); ++i) {
                float t, u, v;
                const auto& tri = s.tri_positions[i];
                ray.tmax = best;
                if (intersect_triangle(ray, s.positions[tri[0]], s.positions[tri[1]],
                                       s.positions[tri[2]], t, u, v))
                    best = t;
            }
            float got = r.layers().distance(x, y);
            if (std::isfinite(best)) ++hits;
            if (!(got == best)) ++mismatches;
        }
    EXPECT_GT(hits, 1000);
    EXPECT_EQ(mismatches, 0);
}

TEST(Renderer, TeapotMatchesTheGoldenImage) {
    // Golden image made by this renderer at 1280x720 and checked by eye against the seed's
    // figures; tiny differences (a ray through a shared edge) are tolerated.
    Scene s = load("teapot.obj");
    RenderSettings settings;
    settings.lines.mode = LineMode::Classic;
    CameraSpec cam = framing_camera(s, settings);
    TriangleAccel accel;
    accel.build(s.positions, s.tri_positions);
    Renderer r;
    const ImageRgb8& out = r.render(s, accel, cam, test_support::default_lights(s, cam), settings);
    DecodedPng golden =
        read_png(std::string(TOONRAY_TEST_DATA_DIR) + "/golden/teapot_classic_1280x720.png");
    ASSERT_EQ(golden.width, out.width());
    ASSERT_EQ(golden.height, out.height());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < out.size(); ++i)
        if (out.data()[i] != golden.rgb.data()[i]) ++differ;
    EXPECT_LE(differ, out.size() / 1000) << differ << " pixels differ";
}

TEST(Renderer, LayersAreFilledOnlyWhenAskedAndChangeNothingElse) {
    Scene s = load("teapot.obj");
    TriangleAccel accel;
    accel.build(s.positions, s.tri_positions);
    for (LineMode mode : {LineMode::Classic, LineMode::Robust, LineMode::Ink}) {
        RenderSettings settings;
        settings.lines.mode = mode;
        settings.width = 160;
        settings.height = 90;
        const CameraSpec cam = framing_camera(s, settings);
        const std::vector<Light> lights = test_support::default_lights(s, cam);
        Renderer with, without;
        settings.layers = true;
        const ImageRgb8 a = with.render(s, accel, cam, lights, settings);
        settings.layers = false;
        const ImageRgb8 b = without.render(s, accel, cam, lights, settings);
        ASSERT_EQ(a.size(), b.size());
        EXPECT_EQ(0, std::memcmp(a.data(), b.data(), a.size() * sizeof(Rgb8)));
        const FrameLayers& l = with.layers();
        for (std::size_t size : {l.cel.size(), l.distance.size(), l.view_depth.size(),
                                 l.normal.size(), l.object.size(), l.band.size(), l.light.size(),
                                 l.position.size(), l.uv.size(), l.refined.size(), l.lines.size()})
            EXPECT_EQ(size, a.size());
        // The ink mode's tone layer (empty under the cel look, there all the same).
        EXPECT_EQ(l.tone.size(), mode == LineMode::Ink ? a.size() : 0u);
        const std::size_t types =
            mode == LineMode::Classic ? 2 : (mode == LineMode::Robust ? 5 : 8);
        ASSERT_EQ(l.line_types.size(), types);
        for (const LineLayer& type : l.line_types) EXPECT_EQ(type.coverage.size(), a.size());
        const FrameLayers& none = without.layers();
        EXPECT_EQ(none.distance.size() + none.object.size() + none.band.size(), 0u);
        EXPECT_TRUE(none.line_types.empty());
        // The same renderer, asked and then not: nothing of the earlier frame's layers shows.
        with.render(s, accel, cam, lights, settings);
        EXPECT_EQ(with.layers().distance.size(), 0u);
        EXPECT_EQ(with.layers().cel.size(), 0u);
        EXPECT_EQ(with.layers().lines.size(), 0u);
        EXPECT_EQ(with.layers().tone.size(), 0u);
        EXPECT_TRUE(with.layers().line_types.empty());
    }
}

// frame_buffer_bytes bounds what a renderer holds after a frame, not loosely: every sample of
// every bucket traced (adaptive off), with and without the layers.
TEST(Renderer, FrameBufferBytesBoundTheBuffersRendererHolds) {
    Scene s = load("spot.obj");
    TriangleAccel accel;
    accel.build(s.positions, s.tri_positions);
    struct Case {
        LineMode mode;
        int samples;
        float line_width;
    };
    // The last robust case draws lines so wide that each bucket uses the full distance image.
    for (const Case& c : {Case{LineMode::Classic, 1, 2.0f}, Case{LineMode::Robust, 1, 2.0f},
                          Case{LineMode::Robust, 4, 2.0f}, Case{LineMode::Robust, 9, 2.0f},
                          Case{LineMode::Robust, 4, 100.0f}, Case{LineMode::Ink, 1, 2.0f},
                          Case{LineMode::Ink, 4, 2.0f}})
        for (bool layers : {true, false}) {
            RenderSettings settings;
            settings.lines.mode = c.mode;
            settings.sampling.samples = c.samples;
            settings.lines.width = c.line_width;
            settings.width = 96;
            settings.height = 720;  // tall enough that 100-pixel lines need the distance image
            settings.layers = layers;
            settings.sampling.adaptive = false;  // every sample traced: the largest buffers
            settings.threads = 1;
            const CameraSpec cam = framing_camera(s, settings);
            Renderer r;
            r.render(s, accel, cam, test_support::default_lights(s, cam), settings);
            if (c.line_width > 50.0f) {
                EXPECT_GT(line_distance_band(line_thickness(c.line_width, settings.height, 2)),
                          kMaxDistanceBand);
            }
            const std::uint64_t estimate = frame_buffer_bytes(settings);
            const std::uint64_t held = r.held_bytes();
            EXPECT_LE(held, estimate) << c.samples << " layers " << layers;
            EXPECT_GT(static_cast<double>(held), 0.75 * static_cast<double>(estimate))
                << c.samples << " layers " << layers;
        }
    RenderSettings huge;
    huge.width = huge.height = 2147483647;
    huge.lines.mode = LineMode::Ink;
    huge.layers = true;
    EXPECT_EQ(frame_buffer_bytes(huge), UINT64_MAX);
}

TEST(Renderer, SampleCountsAreSquareGrids) {
    EXPECT_EQ(samples_per_side(9), 3);
    try {
        (void)samples_per_side(5);
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()),
                  "5 samples per pixel: must be 1, 4, 9 or 16 (a square grid per pixel)");
    }
}

// Ink mode: the cel colours (the mean of each pixel's samples) with the ink coverage
// composited over them, and the `edges` feature image that coverage, black on white.
TEST(Renderer, InkLinesAreTheCoverageOverTheCelColours) {
    Scene s = load("teapot.obj");
    TriangleAccel accel;
    accel.build(s.positions, s.tri_positions);
    RenderSettings settings;
    settings.lines.mode = LineMode::Ink;
    settings.width = 320;
    settings.height = 180;
    settings.layers = true;
    settings.lines.colour = Vec3f(0.2f, 0.0f, 0.0f);
    const CameraSpec cam = framing_camera(s, settings);
    Renderer r;
    const ImageRgb8 image = r.render(s, accel, cam, test_support::default_lights(s, cam), settings);
    const ink::InkLines& lines = r.ink_lines();
    ASSERT_EQ(lines.coverage.width(), 320);
    ImageRgb8 expected = r.layers().cel;
    ink::composite_lines(lines.coverage, settings.lines.colour, expected);
    ASSERT_EQ(0, std::memcmp(image.data(), expected.data(), image.size() * sizeof(Rgb8)));
    ASSERT_TRUE(test_support::same_image(lines.coverage, r.layers().lines, "lines"));
    ImageGray8 gray;
    ink::coverage_to_gray(lines.coverage, gray);
    long line_pixels = 0;
    for (std::size_t i = 0; i < gray.size(); ++i) line_pixels += gray.data()[i] < 128;
    EXPECT_GT(line_pixels, 300);
    // One layer per line type: together (the most per pixel) they are the lines layer, and
    // the teapot (a mesh without normals, open at the spout's and lid's rims) has silhouettes,
    // creases and borders.
    const std::vector<LineLayer>& types = r.layers().line_types;
    ASSERT_EQ(types.size(), 8u);
    const char* names[] = {"silhouette",   "border",   "crease", "material",
                           "intersection", "polyline", "band",   "shadow"};
    for (std::size_t t = 0; t < types.size(); ++t) EXPECT_EQ(types[t].name, names[t]);
    std::vector<long> type_pixels(types.size(), 0);
    for (std::size_t i = 0; i < gray.size(); ++i) {
        float most = 0.0f;
        for (std::size_t t = 0; t < types.size(); ++t) {
            ASSERT_EQ(types[t].coverage.size(), gray.size());
            most = std::max(most, types[t].coverage.data()[i]);
            type_pixels[t] += types[t].coverage.data()[i] > 0.5f;
        }
        ASSERT_EQ(most, lines.coverage.data()[i]) << i;
    }
    EXPECT_GT(type_pixels[0], 100);  // silhouettes
    EXPECT_GT(type_pixels[1], 10);   // borders
    EXPECT_EQ(type_pixels[5], 0);    // no polylines in the scene
    // Hidden lines are kept with the strokes (for SVG) but not drawn; any thread count gives the
    // same pixels.
    settings.strokes = true;
    settings.hidden_lines = true;
    settings.threads = 1;
    Renderer one;
    const ImageRgb8 again =
        one.render(s, accel, cam, test_support::default_lights(s, cam), settings);
    EXPECT_EQ(0, std::memcmp(image.data(), again.data(), image.size() * sizeof(Rgb8)));
    bool hidden = false;
    for (const auto& stroke : one.ink_lines().strokes) hidden = hidden || !stroke.visible;
    EXPECT_TRUE(hidden);
    // Line types map onto the ink's: none draws nothing.
    settings.lines.types = 0;
    const ImageRgb8 bare =
        one.render(s, accel, cam, test_support::default_lights(s, cam), settings);
    EXPECT_EQ(0, std::memcmp(bare.data(), one.layers().cel.data(), bare.size() * sizeof(Rgb8)));
}

TEST(Renderer, ProgressCountsEveryBucket) {
    Scene s = load("teapot.obj");
    RenderSettings settings;
    settings.width = 200;
    settings.height = 100;
    settings.sampling.tile_size = 32;  // 7 x 4 buckets
    CameraSpec cam = framing_camera(s, settings);
    TriangleAccel accel;
    accel.build(s.positions, s.tri_positions);
    Renderer with, without;
    RenderProgress progress;
    const ImageRgb8 a = with.render(s, accel, cam, test_support::default_lights(s, cam), settings,
                                    nullptr, &progress);
    EXPECT_EQ(progress.buckets.load(), 28u);
    EXPECT_EQ(progress.buckets_done.load(), 28u);
    // Following a frame changes nothing in it.
    const ImageRgb8& b =
        without.render(s, accel, cam, test_support::default_lights(s, cam), settings);
    ASSERT_EQ(0, std::memcmp(a.data(), b.data(), a.size() * 3));
}

TEST(Renderer, CancelStopsTheFrameAndTheNextFrameIsWhole) {
    Scene s = load("teapot.obj");
    RenderSettings settings;
    settings.width = 640;
    settings.height = 360;
    settings.sampling.tile_size = 8;  // 3600 buckets: the stopper sees the first few done
    settings.threads = 2;
    settings.layers = true;
    CameraSpec cam = framing_camera(s, settings);
    TriangleAccel accel;
    accel.build(s.positions, s.tri_positions);
    const auto lights = test_support::default_lights(s, cam);
    for (LineMode mode : {LineMode::Classic, LineMode::Robust, LineMode::Ink}) {
        settings.lines.mode = mode;
        Renderer r, reference;
        // Cancelled before it starts: nothing is rendered.
        RenderProgress cancelled;
        cancelled.cancel = true;
        EXPECT_THROW(r.render(s, accel, cam, lights, settings, nullptr, &cancelled),
                     RenderCancelled);
        EXPECT_EQ(cancelled.buckets_done.load(), 0u);
        // Cancelled while its buckets render: a thread stops it once a few are done.
        RenderProgress progress;
        std::thread stopper([&] {
            while (progress.buckets_done.load() < 3) std::this_thread::yield();
            progress.cancel = true;
        });
        bool threw = false;
        try {
            r.render(s, accel, cam, lights, settings, nullptr, &progress);
        } catch (const RenderCancelled& e) {
            threw = true;
            EXPECT_STREQ(e.what(), "rendering cancelled");
        }
        stopper.join();
        ASSERT_TRUE(threw) << line_mode_name(mode);
        EXPECT_EQ(progress.buckets.load(), 3600u);
        EXPECT_LT(progress.buckets_done.load(), 3600u);
        // The same renderer renders the next frame whole, as a fresh one does.
        const ImageRgb8 a = r.render(s, accel, cam, lights, settings);
        const ImageRgb8& b = reference.render(s, accel, cam, lights, settings);
        ASSERT_EQ(0, std::memcmp(a.data(), b.data(), a.size() * 3)) << line_mode_name(mode);
        ASSERT_TRUE(test_support::same_layers(r.layers(), reference.layers()));
    }
}
