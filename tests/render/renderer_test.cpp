#include "toonray/render/renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string_view>
#include <variant>
#include <vector>

#include "toonray/io/png.h"
#include "toonray/render/classic.h"
#include "toonray/scene/obj_loader.h"
#include "support/test_scenes.h"
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

const Image<Vec3f>& render_scene(Renderer& r, const Scene& s, const CameraSpec& cam,
                                 RenderSettings settings) {
    static TriangleAccel accel;
    accel.build(s.positions, s.tri_positions);
    r.render(s, accel, cam, settings);
    return r.gbuffer().colour;
}

}  // namespace

TEST(Renderer, FlatSquareFacingTheLightIsItsKdWithoutLines) {
    Scene s = square(10.0f, {0.2f, 0.4f, 0.6f});
    // Looking straight down at a plane 5 units away; a narrow field of view keeps depth nearly
    // constant, and a light far along the normal gives l.n close to 1 everywhere.
    CameraSpec cam{{0, 0, 5}, {0, 0, 1}, {0, 1, 0}};
    for (EdgeMode mode : {EdgeMode::Classic, EdgeMode::Robust}) {
        RenderSettings settings;
        settings.edges = mode;
        settings.width = 128;
        settings.height = 96;
        settings.light = Vec3f(0, 0, 1e4f);
        Renderer r;
        TriangleAccel accel;
        accel.build(s.positions, s.tri_positions);
        const ImageRgb8& out = r.render(s, accel, cam, settings);
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
    settings.edges = EdgeMode::Classic;  // one sample per pixel: colours are the formula's
    settings.width = 160;
    settings.height = 120;
    settings.light = Vec3f(0, 0, 2);
    Renderer r;
    const Image<Vec3f>& colour = render_scene(r, s, cam, settings);
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
            float expect = l_dot_n < 0.25f ? 0.5f : (l_dot_n < 0.5f ? 0.75f : 1.0f);
            ASSERT_EQ(colour(x, y).x, expect) << x << "," << y;
            bands[expect == 0.5f ? 0 : (expect == 0.75f ? 1 : 2)]++;
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
    settings.edges = EdgeMode::Classic;
    settings.width = 200;
    settings.height = 200;
    settings.light = Vec3f(0, 0, 100);
    settings.feature_images = true;
    Renderer r;
    TriangleAccel accel;
    accel.build(s.positions, s.tri_positions);
    const ImageRgb8& out = r.render(s, accel, cam, settings);
    // Square covers pixels [75, 125). Its border pixels are lines; inside and far outside are not.
    EXPECT_EQ(out(100, 100), (Rgb8{128, 128, 128}));
    EXPECT_EQ(out(10, 10), (Rgb8{255, 255, 255}));
    for (int i = 80; i < 120; ++i) {
        EXPECT_LT(out(75, i)[0], 60) << i;
        EXPECT_LT(out(124, i)[0], 60) << i;
        EXPECT_LT(out(i, 75)[0], 60) << i;
        EXPECT_LT(out(i, 124)[0], 60) << i;
    }
    EXPECT_EQ(r.aovs().edges(75, 100), 0);
    EXPECT_EQ(r.aovs().edges(100, 100), 255);
    EXPECT_EQ(r.aovs().depth(10, 10), 255);                       // miss: white
    EXPECT_EQ(r.aovs().normal(10, 10), (Rgb8{0, 0, 0}));          // miss: black
    EXPECT_EQ(r.aovs().normal(100, 100), (Rgb8{128, 128, 255}));  // facing +z
}

TEST(Renderer, NormalsFaceTheViewer) {
    // The same square seen from below: its geometric normal (+z) is flipped to face the eye.
    Scene s = square(1.0f, {1, 1, 1});
    CameraSpec cam{{0, 0, -4}, {0, 0, -3}, {0, 1, 0}};
    RenderSettings settings;
    settings.edges = EdgeMode::Classic;
    settings.width = 32;
    settings.height = 32;
    Renderer r;
    render_scene(r, s, cam, settings);
    EXPECT_EQ(r.gbuffer().normal(16, 16), Vec3f(0, 0, -1));
}

TEST(Renderer, InterpolatesVertexNormalsOnlyWhenAllCornersHaveThem) {
    Scene s = square(1.0f, {1, 1, 1});
    s.normals = {normalize(Vec3f(1, 0, 1)), normalize(Vec3f(-1, 0, 1))};
    s.tri_normals[0] = {0, 1, 1};         // all corners: interpolated
    s.tri_normals[1] = {0, kNoIndex, 1};  // one missing: geometric
    CameraSpec cam{{0, 0, 4}, {0, 0, 3}, {0, 1, 0}};
    RenderSettings settings;
    settings.edges = EdgeMode::Classic;
    settings.width = 64;
    settings.height = 64;
    Renderer r;
    render_scene(r, s, cam, settings);
    // Pixel (34, 33) lies in triangle 0 (below the diagonal y = x), (30, 29) in triangle 1.
    Vec3f n0 = r.gbuffer().normal(36, 33);
    EXPECT_GT(std::abs(n0.x), 0.01f);
    EXPECT_NEAR(length(n0), 1.0f, 1e-5f);
    EXPECT_EQ(r.gbuffer().normal(28, 29), Vec3f(0, 0, 1));
}

TEST(Renderer, DefaultLightIsTheEyeMovedAlongUpAndRight) {
    Scene s = square(3.0f, {1, 1, 1});  // radius = half the diagonal of a 6 x 6 x 0 box
    CameraSpec cam{{0, 0, 4}, {0, 0, 3}, {0, 1, 0}};
    RenderSettings settings;
    settings.width = 16;
    settings.height = 16;
    Renderer r;
    render_scene(r, s, cam, settings);
    float half_radius = 0.5f * std::sqrt(72.0f) * 0.5f;
    EXPECT_NEAR(r.light().x, half_radius, 1e-5f);
    EXPECT_NEAR(r.light().y, half_radius, 1e-5f);
    EXPECT_NEAR(r.light().z, 4.0f, 1e-5f);
}

TEST(Renderer, OutputIsIdenticalForEveryThreadCount) {
    Scene s = load("teapot.obj");
    RenderSettings settings;
    settings.width = 320;
    settings.height = 180;
    settings.feature_images = true;
    CameraSpec cam = framing_camera(s, settings);
    TriangleAccel accel;
    accel.build(s.positions, s.tri_positions);
    Renderer one, two, many;
    settings.threads = 1;
    for (EdgeMode mode : {EdgeMode::Classic, EdgeMode::Robust}) {
        settings.edges = mode;
        settings.threads = 1;
        ImageRgb8 a = one.render(s, accel, cam, settings);
        settings.threads = 2;
        ImageRgb8 b = two.render(s, accel, cam, settings);
        settings.threads = 7;
        ImageRgb8 c = many.render(s, accel, cam, settings);
        ASSERT_EQ(0, std::memcmp(a.data(), b.data(), a.size() * 3));
        ASSERT_EQ(0, std::memcmp(a.data(), c.data(), a.size() * 3));
        ASSERT_EQ(0, std::memcmp(one.aovs().depth.data(), two.aovs().depth.data(), a.size()));
    }
}

TEST(Renderer, MatchesABruteForceReference) {
    // The same pixels traced by testing every triangle: the BVH must find the same surfaces.
    Scene s = load("spot.obj");
    RenderSettings settings;
    settings.edges = EdgeMode::Classic;  // its G-buffer holds the Euclidean distance
    settings.width = 160;
    settings.height = 90;
    CameraSpec cam = framing_camera(s, settings);
    TriangleAccel accel;
    accel.build(s.positions, s.tri_positions);
    Renderer r;
    r.render(s, accel, cam, settings);
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
            float got = r.gbuffer().distance(x, y);
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
    settings.edges = EdgeMode::Classic;
    CameraSpec cam = framing_camera(s, settings);
    TriangleAccel accel;
    accel.build(s.positions, s.tri_positions);
    Renderer r;
    const ImageRgb8& out = r.render(s, accel, cam, settings);
    DecodedPng golden =
        read_png(std::string(TOONRAY_TEST_DATA_DIR) + "/golden/teapot_classic_1280x720.png");
    ASSERT_EQ(golden.width, out.width());
    ASSERT_EQ(golden.height, out.height());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < out.size(); ++i)
        if (out.data()[i] != golden.rgb.data()[i]) ++differ;
    EXPECT_LE(differ, out.size() / 1000) << differ << " pixels differ";
}

TEST(Renderer, FeatureImagesAreComputedOnlyWhenAskedAndChangeNothingElse) {
    Scene s = load("teapot.obj");
    TriangleAccel accel;
    accel.build(s.positions, s.tri_positions);
    for (EdgeMode mode : {EdgeMode::Classic, EdgeMode::Robust, EdgeMode::Ink}) {
        RenderSettings settings;
        settings.edges = mode;
        settings.width = 160;
        settings.height = 90;
        const CameraSpec cam = framing_camera(s, settings);
        Renderer with, without;
        settings.feature_images = true;
        const ImageRgb8 a = with.render(s, accel, cam, settings);
        settings.feature_images = false;
        const ImageRgb8 b = without.render(s, accel, cam, settings);
        ASSERT_EQ(a.size(), b.size());
        EXPECT_EQ(0, std::memcmp(a.data(), b.data(), a.size() * sizeof(Rgb8)));
        for (const FeatureImage& f : feature_images()) {
            const std::size_t asked =
                std::visit([&](auto m) { return (with.aovs().*m).size(); }, f.image);
            const std::size_t not_asked =
                std::visit([&](auto m) { return (without.aovs().*m).size(); }, f.image);
            EXPECT_EQ(asked, f.in(mode) ? a.size() : 0u) << f.name;
            EXPECT_EQ(not_asked, 0u) << f.name;
        }
        // The same renderer, asked and then not: nothing of the earlier frame's features shows.
        with.render(s, accel, cam, settings);
        EXPECT_EQ(with.aovs().depth.size(), 0u);
        EXPECT_EQ(with.aovs().cel.size(), 0u);
    }
}

TEST(Renderer, FeatureImageTableListsEachModesImages) {
    std::vector<std::string_view> classic, robust, ink;
    for (const FeatureImage& f : feature_images()) {
        if (f.in(EdgeMode::Classic)) classic.push_back(f.name);
        if (f.in(EdgeMode::Robust)) robust.push_back(f.name);
        if (f.in(EdgeMode::Ink)) ink.push_back(f.name);
    }
    EXPECT_EQ(ink, (std::vector<std::string_view>{
                       "depth", "normal", "edges", "cel", "lines_silhouette", "lines_crease",
                       "lines_material", "lines_border", "lines_intersection", "lines_polyline",
                       "object_id", "material_id", "samples"}));
    EXPECT_EQ(classic, (std::vector<std::string_view>{"depth", "normal", "edges_depth",
                                                      "edges_normal", "edges", "cel"}));
    EXPECT_EQ(robust, (std::vector<std::string_view>{
                          "depth", "normal", "edges", "cel", "lines_silhouette", "lines_crease",
                          "lines_depth", "lines_object", "lines_material", "object_id",
                          "material_id", "samples"}));
}

// frame_buffer_bytes counts the buffers a renderer holds after a frame: exactly the frame-sized
// ones, and per thread at most bucket_buffer_bytes (which every sample of a bucket reaches).
TEST(Renderer, FrameBufferBytesCountTheBuffersRendererHolds) {
    Scene s = load("spot.obj");
    TriangleAccel accel;
    accel.build(s.positions, s.tri_positions);
    struct Case {
        EdgeMode mode;
        int samples;
        float line_width;
    };
    // The last robust case draws lines so wide that each bucket uses the full distance image.
    for (const Case& c : {Case{EdgeMode::Classic, 1, 2.0f}, Case{EdgeMode::Robust, 1, 2.0f},
                          Case{EdgeMode::Robust, 4, 2.0f}, Case{EdgeMode::Robust, 9, 2.0f},
                          Case{EdgeMode::Robust, 4, 100.0f}, Case{EdgeMode::Ink, 1, 2.0f},
                          Case{EdgeMode::Ink, 4, 2.0f}}) {
        RenderSettings settings;
        settings.edges = c.mode;
        settings.samples = c.samples;
        settings.lines.width = c.line_width;
        settings.width = 96;
        settings.height = 720;  // tall enough that 100-pixel lines need the full distance image
        settings.feature_images = true;
        settings.adaptive = false;  // every sample traced: the buckets' largest buffers
        settings.threads = 1;
        const CameraSpec cam = framing_camera(s, settings);
        Renderer r;
        const ImageRgb8& out = r.render(s, accel, cam, settings);
        const GBuffer& g = r.gbuffer();
        std::uint64_t held = bytes_of(out) + bytes_of(g.distance) + bytes_of(g.normal) +
                             bytes_of(g.view_depth) + bytes_of(g.geometric_normal) +
                             bytes_of(g.colour) + bytes_of(g.material) + bytes_of(g.object);
        std::uint64_t features = 0;
        for (const FeatureImage& f : feature_images())
            features += std::visit([&](auto m) { return bytes_of(r.aovs().*m); }, f.image);
        held += features;
        if (c.mode != EdgeMode::Classic) {
            // The first samples' depths the depth feature image is scaled by.
            features += static_cast<std::uint64_t>(settings.width) * settings.height * 4;
            held += static_cast<std::uint64_t>(settings.width) * settings.height * 4;
        }
        if (c.mode == EdgeMode::Ink) {
            const ink::InkLines& ink = r.ink_lines();
            // The line layer, and the same again while each line type's feature image is drawn.
            held += 2 * (bytes_of(ink.coverage) + bytes_of(ink.style));
        }
        if (c.line_width > 50.0f) {
            EXPECT_GT(line_distance_band(line_thickness(c.line_width, settings.height, 2)),
                      kMaxDistanceBand);
        }
        const std::uint64_t buckets =
            c.mode == EdgeMode::Classic ? 0 : bucket_buffer_bytes(settings);
        if (c.mode != EdgeMode::Classic) {
            EXPECT_GT(r.bucket_bytes(), 0u);
            EXPECT_LE(r.bucket_bytes(), buckets) << c.samples;
            EXPECT_GT(r.bucket_bytes(), buckets / 2) << c.samples;  // not a loose bound
        }
        EXPECT_EQ(frame_buffer_bytes(settings), held + buckets) << c.samples;
        // Without feature images: classic keeps the maps its lines come from, less cel.
        settings.feature_images = false;
        const std::uint64_t kept =
            c.mode == EdgeMode::Classic ? features - bytes_of(r.aovs().cel) : 0;
        // Ink without feature images: the layer each line type is drawn into is not needed,
        // and the mask of pixels the lines hide (a byte each) is.
        const std::uint64_t type_layer =
            c.mode == EdgeMode::Ink
                ? bytes_of(r.ink_lines().coverage) + bytes_of(r.ink_lines().style)
                : 0;
        const std::uint64_t hidden = c.mode == EdgeMode::Ink ? bytes_of(out) / sizeof(Rgb8) : 0;
        EXPECT_EQ(frame_buffer_bytes(settings),
                  held + buckets - features + kept - type_layer + hidden)
            << c.samples;
    }
    RenderSettings huge;
    huge.width = huge.height = 2147483647;
    huge.edges = EdgeMode::Ink;
    huge.feature_images = true;
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
    settings.edges = EdgeMode::Ink;
    settings.width = 320;
    settings.height = 180;
    settings.feature_images = true;
    settings.lines.colour = Vec3f(0.2f, 0.0f, 0.0f);
    const CameraSpec cam = framing_camera(s, settings);
    Renderer r;
    const ImageRgb8 image = r.render(s, accel, cam, settings);
    const ink::InkLines& lines = r.ink_lines();
    ASSERT_EQ(lines.coverage.width(), 320);
    ImageRgb8 expected = r.aovs().cel;
    ink::composite_lines(lines.coverage, settings.lines.colour, expected);
    ASSERT_EQ(0, std::memcmp(image.data(), expected.data(), image.size() * sizeof(Rgb8)));
    ImageGray8 gray;
    ink::coverage_to_gray(lines.coverage, gray);
    ASSERT_EQ(0, std::memcmp(gray.data(), r.aovs().edges.data(), gray.size()));
    long line_pixels = 0;
    for (std::size_t i = 0; i < gray.size(); ++i) line_pixels += gray.data()[i] < 128;
    EXPECT_GT(line_pixels, 300);
    // One image per line type: together (the darkest per pixel) they are the edges image, and
    // the teapot (a mesh without normals, open at the spout's and lid's rims) has silhouettes,
    // creases and borders.
    const ImageGray8* types[] = {&r.aovs().lines_silhouette,   &r.aovs().lines_crease,
                                 &r.aovs().lines_material,     &r.aovs().lines_border,
                                 &r.aovs().lines_intersection, &r.aovs().lines_polyline};
    std::vector<long> type_pixels(std::size(types), 0);
    for (std::size_t i = 0; i < gray.size(); ++i) {
        std::uint8_t darkest = 255;
        for (std::size_t t = 0; t < std::size(types); ++t) {
            ASSERT_EQ(types[t]->size(), gray.size());
            darkest = std::min(darkest, types[t]->data()[i]);
            type_pixels[t] += types[t]->data()[i] < 128;
        }
        ASSERT_EQ(darkest, gray.data()[i]) << i;
    }
    EXPECT_GT(type_pixels[0], 100);  // silhouettes
    EXPECT_EQ(type_pixels[5], 0);    // no polylines in the scene
    // Hidden lines are found for SVG but not drawn; any thread count gives the same pixels.
    settings.hidden_lines = true;
    settings.threads = 1;
    Renderer one;
    const ImageRgb8 again = one.render(s, accel, cam, settings);
    EXPECT_EQ(0, std::memcmp(image.data(), again.data(), image.size() * sizeof(Rgb8)));
    bool hidden = false;
    for (const auto& stroke : one.ink_lines().strokes) hidden = hidden || !stroke.visible;
    EXPECT_TRUE(hidden);
    // Line types map onto the ink's: none draws nothing.
    settings.lines.types = 0;
    const ImageRgb8 bare = one.render(s, accel, cam, settings);
    EXPECT_EQ(0, std::memcmp(bare.data(), one.aovs().cel.data(), bare.size() * sizeof(Rgb8)));
}
