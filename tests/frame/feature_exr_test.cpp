// EXR feature images read back: with OpenEXR (values agree with the PNG feature images and the
// renderer's buffers) and with a second reader, OpenImageIO's `oiiotool --info -v`.

#include "toonray/frame/feature_exr.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>

#include "toonray/frame/feature_images.h"
#include "toonray/frame/frame_renderer.h"
#include "toonray/ink/line_style.h"
#include "toonray/io/exr.h"
#include "toonray/io/png.h"
#include "toonray/scene/obj_loader.h"
#include "support/test_scenes.h"
#include "support/test_support.h"

#if TOONRAY_WITH_OPENEXR
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#endif

using namespace toonray;
namespace fs = std::filesystem;

namespace {

Scene load(const std::string& name) { return test_support::load_test_scene(name); }

// Renders the spot model with both PNG feature images and the EXR; returns the EXR's path.
fs::path render_both(const fs::path& dir, LineMode mode) {
    const Scene scene = load("spot.obj");
    FrameOptions options;
    options.settings.width = 96;
    options.settings.height = 64;
    options.settings.lines.mode = mode;
    options.aov_dir = dir / "aov";
    options.aov_exr = dir / "exr";
    FrameRenderer renderer;
    Warnings w;
    renderer.render(test_support::scene_frame(scene, 96, 64), dir / "frame.png", options, w);
    return exr_path(*options.aov_exr, dir / "frame.png");
}

}  // namespace

#if TOONRAY_WITH_OPENEXR

namespace {

struct ReadExr {
    int width = 0, height = 0;
    std::map<std::string, Imf::PixelType> types;
    std::map<std::string, std::vector<float>> values;
};

ReadExr read_exr(const fs::path& path) {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i box = file.header().dataWindow();
    ReadExr out;
    out.width = box.max.x - box.min.x + 1;
    out.height = box.max.y - box.min.y + 1;
    Imf::FrameBuffer frame;
    const std::size_t pixels = static_cast<std::size_t>(out.width) * out.height;
    for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it) {
        out.types[it.name()] = it.channel().type;
        std::vector<float>& v = out.values[it.name()];
        v.assign(pixels, 0.0f);
        frame.insert(it.name(), Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(v.data()),
                                           sizeof(float), sizeof(float) * out.width));
    }
    file.setFrameBuffer(frame);
    file.readPixels(box.min.y, box.max.y);
    return out;
}

float linear(std::uint8_t byte) {
    const float c = static_cast<float>(byte) / 255.0f;
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

// Every pixel of an 8-bit black-on-white line PNG against the coverage channel.
void expect_coverage(const ReadExr& exr, const std::string& channel, const fs::path& png) {
    ASSERT_TRUE(exr.values.contains(channel)) << channel;
    const DecodedPng lines = read_png(png);
    const std::vector<float>& v = exr.values.at(channel);
    int lit = 0;
    for (std::size_t i = 0; i < v.size(); ++i) {
        const float expected = 1.0f - static_cast<float>(lines.rgb.data()[i][0]) / 255.0f;
        ASSERT_NEAR(v[i], expected, 1.0f / 255.0f + 1e-3f) << channel << " at " << i;
        lit += v[i] > 0.5f;
    }
    EXPECT_GT(lit, 0) << channel << " has no line";
}

}  // namespace

TEST(FeatureExr, ClassicDistanceAgreesWithTheDepthPng) {
    test_support::TempDir dir("exr_classic");
    const ReadExr exr = read_exr(render_both(dir.path, LineMode::Classic));
    ASSERT_EQ(exr.width, 96);
    ASSERT_EQ(exr.height, 64);
    EXPECT_EQ(exr.types.at("Z"), Imf::FLOAT);
    EXPECT_EQ(exr.types.at("R"), Imf::HALF);
    const std::vector<float>& z = exr.values.at("Z");
    float z_max = 0.0f;
    for (float d : z)
        if (d < kExrBackgroundDepth) z_max = std::max(z_max, d);
    ASSERT_GT(z_max, 0.0f);
    const DecodedPng depth = read_png(dir.path / "aov/frame_depth.png");
    int hits = 0;
    for (std::size_t i = 0; i < z.size(); ++i) {
        const bool hit = z[i] < kExrBackgroundDepth;
        hits += hit;
        const int expected = hit ? static_cast<int>(std::lround(z[i] / z_max * 255.0f)) : 255;
        ASSERT_EQ(depth.rgb.data()[i][0], expected) << "pixel " << i;
        ASSERT_EQ(exr.values.at("A")[i], hit ? 1.0f : 0.0f);
    }
    EXPECT_GT(hits, 500);
    expect_coverage(exr, "lines.depth", dir.path / "aov/frame_edges_depth.png");
    expect_coverage(exr, "lines.normal", dir.path / "aov/frame_edges_normal.png");
    expect_coverage(exr, "lines.all", dir.path / "aov/frame_edges.png");
}

TEST(FeatureExr, RobustLayersAgreeWithThePngFeatureImages) {
    test_support::TempDir dir("exr_robust");
    const ReadExr exr = read_exr(render_both(dir.path, LineMode::Robust));
    const std::vector<float>& depth = exr.values.at("view_depth.Z");
    float z_max = 0.0f;
    for (float d : depth)
        if (d < kExrBackgroundDepth) z_max = std::max(z_max, d);
    const DecodedPng depth_png = read_png(dir.path / "aov/frame_depth.png");
    const DecodedPng object_png = read_png(dir.path / "aov/frame_object_id.png");
    const DecodedPng material_png = read_png(dir.path / "aov/frame_material_id.png");
    const DecodedPng normal_png = read_png(dir.path / "aov/frame_normal.png");
    const DecodedPng cel_png = read_png(dir.path / "aov/frame_cel.png");
    for (std::size_t i = 0; i < depth.size(); ++i) {
        const bool hit = depth[i] < kExrBackgroundDepth;
        const int expected = hit ? static_cast<int>(std::lround(depth[i] / z_max * 255.0f)) : 255;
        ASSERT_EQ(depth_png.rgb.data()[i][0], expected) << "pixel " << i;
        const float object = exr.values.at("object_id.id")[i];
        const float material = exr.values.at("material_id.id")[i];
        ASSERT_EQ(object == kExrBackgroundId, !hit);
        ASSERT_EQ(id_colour(hit ? static_cast<std::uint32_t>(object) : kNoIndex),
                  object_png.rgb.data()[i]);
        ASSERT_EQ(id_colour(hit ? static_cast<std::uint32_t>(material) : kNoIndex),
                  material_png.rgb.data()[i]);
        // Unit normals facing the eye; the PNG holds the geometric normal, the EXR the
        // shading normal, so only their rough direction agrees. Both are of the pixel's first
        // sample, as every layer.
        const float nx = exr.values.at("N.X")[i], ny = exr.values.at("N.Y")[i],
                    nz = exr.values.at("N.Z")[i];
        if (hit) {
            ASSERT_NEAR(nx * nx + ny * ny + nz * nz, 1.0f, 1e-3f);
            const auto& n8 = normal_png.rgb.data()[i];
            const float gx = n8[0] / 127.5f - 1, gy = n8[1] / 127.5f - 1, gz = n8[2] / 127.5f - 1;
            ASSERT_GT(nx * gx + ny * gy + nz * gz, 0.5f) << "pixel " << i;
        }
        for (int c = 0; c < 3; ++c)
            ASSERT_NEAR(exr.values.at(std::string(1, "RGB"[c]))[i],
                        linear(cel_png.rgb.data()[i][c]), 2e-3f);
    }
    expect_coverage(exr, "lines.silhouette", dir.path / "aov/frame_lines_silhouette.png");
    expect_coverage(exr, "lines.all", dir.path / "aov/frame_edges.png");
    EXPECT_TRUE(exr.values.contains("lines.crease"));
    EXPECT_TRUE(exr.values.contains("lines.material"));
}

TEST(FeatureExr, InkLinesAllIsTheCoverageAndTypesAddUp) {
    test_support::TempDir dir("exr_ink");
    const ReadExr exr = read_exr(render_both(dir.path, LineMode::Ink));
    expect_coverage(exr, "lines.all", dir.path / "aov/frame_edges.png");
    // Each type drawn alone covers no more than all lines together, and together as much.
    const std::vector<float>& all = exr.values.at("lines.all");
    for (std::size_t i = 0; i < all.size(); ++i) {
        float most = 0.0f;
        for (const char* type :
             {"silhouette", "border", "crease", "material", "intersection", "polyline"})
            most = std::max(most, exr.values.at(std::string("lines.") + type)[i]);
        ASSERT_NEAR(most, all[i], 2e-3f) << "pixel " << i;
    }
}

TEST(FeatureExr, PolylinesDrawnOverTheFrameHaveTheirChannel) {
    test_support::TempDir dir("exr_polylines");
    Scene scene;
    Warnings w;
    parse_obj(
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\n"
        "v -0.6 0.4 0.5\nv 0.6 0.4 0.5\nl -2 -1\n",
        "lines.obj", scene, w);
    for (LineMode mode : {LineMode::Classic, LineMode::Robust, LineMode::Ink}) {
        FrameOptions options;
        options.settings.width = 80;
        options.settings.height = 60;
        options.settings.lines.mode = mode;
        options.aov_exr = dir.path / "f.exr";
        FrameRenderer renderer;
        renderer.render(
            test_support::scene_frame(scene, CameraSpec{{0, 0, 4}, {0, 0, 0}, {0, 1, 0}}, 80, 60),
            dir.path / "f.png", options, w);
        const ReadExr exr = read_exr(dir.path / "f.exr");
        ASSERT_TRUE(exr.values.contains("lines.polyline")) << static_cast<int>(mode);
        const std::vector<float>& line = exr.values.at("lines.polyline");
        const std::vector<float>& all = exr.values.at("lines.all");
        int covered = 0;
        for (std::size_t i = 0; i < line.size(); ++i) {
            covered += line[i] > 0.05f;  // lines are 2 * 60 / 720 pixels wide here
            ASSERT_GE(all[i] + 2e-3f, line[i]);
        }
        EXPECT_GT(covered, 20) << static_cast<int>(mode);
    }
}

TEST(FeatureExr, TheChannelsAreTheRenderersLayersOfEachPixelsFirstSample) {
    // No second trace: with four samples a pixel, Z, N and the ids are those of the sample the
    // renderer took first in each pixel, exactly.
    test_support::TempDir dir("exr_layers");
    const Scene scene = load("spot.obj");
    FrameOptions options;
    options.settings.width = 64;
    options.settings.height = 48;
    options.aov_exr = dir.path / "f.exr";
    FrameRenderer renderer;
    Warnings w;
    renderer.render(test_support::scene_frame(scene, 64, 48), dir.path / "f.png", options, w);
    const FrameLayers& layers = renderer.renderer().layers();
    const ReadExr exr = read_exr(dir.path / "f.exr");
    int seen = 0;
    for (std::size_t i = 0; i < layers.distance.size(); ++i) {
        const bool hit = layers.object.data()[i] != kNoIndex;
        seen += hit;
        ASSERT_EQ(exr.values.at("Z")[i], hit ? layers.distance.data()[i] : kExrBackgroundDepth);
        ASSERT_EQ(exr.values.at("N.X")[i], layers.normal.data()[i].x);
        ASSERT_EQ(exr.values.at("object_id.id")[i],
                  hit ? static_cast<float>(layers.object.data()[i]) : kExrBackgroundId);
        ASSERT_EQ(exr.values.at("band.index")[i],
                  hit ? static_cast<float>(layers.band.data()[i]) : kExrBackgroundId);
        ASSERT_EQ(exr.values.at("P.Y")[i], layers.position.data()[i].y);
    }
    EXPECT_GT(seen, 300);
}

TEST(FeatureExr, LineTypeChannelsAreDrawnWithTheirStyles) {
    // A line style that widens the silhouettes widens their channel, as it does the picture.
    test_support::TempDir dir("exr_styles");
    const Scene scene = load("spot.obj");
    auto silhouette_coverage = [&](const char* style) {
        FrameOptions options;
        options.settings.width = 96;
        options.settings.height = 64;
        options.settings.lines.ink.styles = ink::parse_line_styles(style, "test.style");
        options.aov_exr = dir.path / "f.exr";
        FrameRenderer renderer;
        Warnings w;
        renderer.render(test_support::scene_frame(scene, 96, 64), dir.path / "f.png", options, w);
        const ReadExr exr = read_exr(dir.path / "f.exr");
        double sum = 0.0;
        for (float c : exr.values.at("lines.silhouette")) sum += c;
        return sum;
    };
    const double plain = silhouette_coverage("");
    const double wide = silhouette_coverage("match type=silhouette width=8\n");
    EXPECT_GT(plain, 10.0);
    EXPECT_GT(wide, 2.0 * plain);
}

TEST(FeatureExr, LayersOfAnotherSizeAreAnError) {
    // A frame rendered without its layers has none to write: an error, not zero channels.
    FrameLayers layers;
    layers.image.reshape(8, 4);
    FeatureLayers out;
    try {
        gather_feature_layers(layers, out);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("layer is 0x0 in a 8x4 frame"), std::string::npos)
            << e.what();
    }
}

TEST(FeatureExr, OiiotoolListsTheChannels) {
    test_support::TempDir dir("exr_oiio");
    const fs::path exr = render_both(dir.path, LineMode::Robust);
    const std::string command = "oiiotool --info -v '" + exr.string() + "' 2>&1";
    FILE* pipe = ::popen(command.c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    std::string text;
    char buffer[4096];
    while (std::size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) text.append(buffer, n);
    ASSERT_EQ(::pclose(pipe), 0) << text;
    EXPECT_NE(text.find("96 x   64"), std::string::npos) << text;
    for (const char* channel :
         {"R (half)", "G (half)", "B (half)", "A (half)", "Z (float)", "view_depth.Z (float)",
          "N.X (float)", "N.Y (float)", "N.Z (float)", "object_id.id (float)",
          "material_id.id (float)", "lines.all (half)", "lines.silhouette (half)"})
        EXPECT_NE(text.find(channel), std::string::npos) << channel << " not in:\n" << text;
}

TEST(FeatureExr, SequenceNeedsADirectory) {
    EXPECT_THROW(check_exr_sequence("frames.exr"), Error);
    EXPECT_NO_THROW(check_exr_sequence("frames"));
    EXPECT_EQ(exr_path("out", "anim/frame_0007.png"), fs::path("out/frame_0007.exr"));
    EXPECT_EQ(exr_path("one.exr", "anim/frame_0007.png"), fs::path("one.exr"));
}

#else

TEST(FeatureExr, WithoutOpenExrTheErrorSaysSo) {
    test_support::TempDir dir("exr_none");
    EXPECT_FALSE(exr_available());
    try {
        render_both(dir.path, LineMode::Robust);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("built without OpenEXR"), std::string::npos);
    }
    EXPECT_FALSE(fs::exists(dir.path / "frame.png"));
}

#endif
