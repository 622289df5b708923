#include "toonray/frame/frame_renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>

#include "toonray/frame/feature_images.h"
#include "toonray/io/file.h"
#include "toonray/io/png.h"
#include "toonray/scene/obj_loader.h"
#include "support/test_scenes.h"
#include "support/test_support.h"

using namespace toonray;
namespace fs = std::filesystem;

namespace {

Scene load(const std::string& name) { return test_support::load_test_scene(name); }

// The teapot twisted about y, more with height and with the frame number.
Scene twisted_teapot(const Scene& teapot, int frame) {
    Scene scene = teapot;
    const float angle = 0.05f * static_cast<float>(frame);
    for (Vec3f& p : scene.positions) {
        const float a = angle * p.y;
        p = Vec3f(p.x * std::cos(a) - p.z * std::sin(a), p.y,
                  p.x * std::sin(a) + p.z * std::cos(a));
    }
    return scene;
}

// The scene as a scene source finishes it for a frame of `o`'s size.
SceneFrame frame_of(const Scene& scene, const FrameOptions& o) {
    return test_support::scene_frame(scene, o.settings.width, o.settings.height);
}

bool same_pixels(const fs::path& a, const fs::path& b) {
    const DecodedPng pa = read_png(a), pb = read_png(b);
    return pa.rgb.size() == pb.rgb.size() &&
           std::memcmp(pa.rgb.data(), pb.rgb.data(), pa.rgb.size() * sizeof(Rgb8)) == 0;
}

}  // namespace

TEST(FrameRenderer, WritesTheImageAndAllFeatureImagesNamedAfterTheOutput) {
    test_support::TempDir dir("frame_aov");
    const Scene teapot = load("teapot.obj");
    FrameOptions o;
    o.settings.width = 64;
    o.settings.height = 48;
    for (LineMode mode : {LineMode::Classic, LineMode::Robust, LineMode::Ink}) {
        o.settings.lines.mode = mode;
        FrameRenderer fr;
        Warnings w;
        // Without a feature directory: the image alone, and no feature images computed.
        o.aov_dir.reset();
        fr.render(frame_of(teapot, o), dir.path / "plain.png", o, w);
        EXPECT_EQ(fr.renderer().layers().distance.size(), 0u);
        o.aov_dir = dir.path / "aov";
        fr.render(frame_of(teapot, o), dir.path / "frame.png", o, w);
        EXPECT_TRUE(is_valid_png(dir.path / "frame.png"));
        EXPECT_TRUE(same_pixels(dir.path / "plain.png", dir.path / "frame.png"));
        std::size_t written = 0;
        for (const FeatureImage& f : feature_images()) {
            const fs::path p = dir.path / "aov" / ("frame_" + std::string(f.name) + ".png");
            EXPECT_EQ(is_valid_png(p), f.in(mode)) << p;
            if (!f.in(mode)) continue;
            ++written;
            EXPECT_EQ(read_png(p).width, 64);
            EXPECT_EQ(p, aov_path(dir.path / "aov", dir.path / "frame.png", f.name));
        }
        EXPECT_EQ(written, mode == LineMode::Robust ? 12u : (mode == LineMode::Ink ? 16u : 6u));
        fs::remove_all(dir.path / "aov");
    }
}

TEST(FrameRenderer, WritesTheInkStrokesAsSvg) {
    test_support::TempDir dir("frame_svg");
    const Scene teapot = load("teapot.obj");
    FrameOptions o;
    o.settings.width = 160;
    o.settings.height = 90;
    o.svg = dir.path / "frame.svg";
    FrameRenderer fr;
    Warnings w;
    // Another line mode runs the ink stages for the SVG only: the same drawing as in ink mode.
    fr.render(frame_of(teapot, o), dir.path / "frame.png", o, w);
    const std::string robust = read_file(dir.path / "frame.svg");
    o.settings.lines.mode = LineMode::Ink;
    fr.render(frame_of(teapot, o), dir.path / "frame.png", o, w);
    EXPECT_EQ(read_file(dir.path / "frame.svg"), robust);
    o.settings.lines.mode = LineMode::Ink;
    for (bool hidden : {false, true}) {
        o.svg_hidden = hidden;
        fr.render(frame_of(teapot, o), dir.path / "frame.png", o, w);
        const std::string svg = read_file(dir.path / "frame.svg");
        EXPECT_NE(svg.find("viewBox=\"0 0 160 90\""), std::string::npos);
        EXPECT_NE(svg.find("<g id=\"visible-silhouette\">"), std::string::npos);
        EXPECT_EQ(svg.find("<g id=\"hidden\"") != std::string::npos, hidden);
        EXPECT_NE(svg.find("<path d=\"M"), std::string::npos);
    }
    // With the fill, the cel picture is embedded under the lines.
    o.svg_fill = true;
    fr.render(frame_of(teapot, o), dir.path / "frame.png", o, w);
    const std::string filled = read_file(dir.path / "frame.svg");
    const std::size_t image = filled.find("<image id=\"fill\"");
    ASSERT_NE(image, std::string::npos);
    EXPECT_LT(image, filled.find("<g id=\"visible\""));
    EXPECT_NE(filled.find("xlink:href=\"data:image/png;base64,iVBORw0KGgo"), std::string::npos);
}

TEST(FrameRenderer, SvgDirectoryNamesFilesLikeThePngAndResumeNeedsBoth) {
    test_support::TempDir dir("frame_svg_dir");
    const Scene teapot = load("teapot.obj");
    FrameOptions o;
    o.settings.width = 96;
    o.settings.height = 54;
    o.settings.lines.mode = LineMode::Classic;
    o.svg_dir = dir.path / "svg";
    EXPECT_EQ(o.svg_path(dir.path / "keys_000030.png"), dir.path / "svg" / "keys_000030.svg");
    FrameRenderer fr;
    Warnings w;
    EXPECT_FALSE(frame_complete(dir.path / "keys_000030.png", o));
    fr.render(frame_of(teapot, o), dir.path / "keys_000030.png", o, w);
    EXPECT_TRUE(frame_complete(dir.path / "keys_000030.png", o));
    fs::remove(dir.path / "svg" / "keys_000030.svg");
    EXPECT_FALSE(frame_complete(dir.path / "keys_000030.png", o));
    dir.write("svg/keys_000030.svg", "<svg>");  // cut short
    EXPECT_FALSE(frame_complete(dir.path / "keys_000030.png", o));
}

TEST(FrameRenderer, ABadCameraWritesNothing) {
    test_support::TempDir dir("frame_camera");
    const Scene teapot = load("teapot.obj");
    FrameOptions o;
    o.settings.width = 32;
    o.settings.height = 24;
    o.aov_dir = dir.path / "aov";
    FrameRenderer fr;
    Warnings w;
    SceneFrame frame;
    frame.scene = teapot;
    frame.camera = CameraSpec{{0, 0, 0}, {0, 0, 0}, {0, 1, 0}};  // gaze at the eye
    frame.lights = {Light{}};
    EXPECT_THROW(fr.render(frame, dir.path / "frame.png", o, w), Error);
    EXPECT_FALSE(fs::exists(dir.path / "frame.png"));
    EXPECT_FALSE(fs::exists(dir.path / "aov"));
}

// Frames with the same triangles refit the previous frame's BVH (kMaxRefitsInARow in a row,
// then a rebuild); the images must be exactly those of a fresh build per frame. The teapot's
// vertices swirl more each frame, so the refitted tree drifts far from a built one.
TEST(FrameRenderer, RefittedFramesEqualRebuiltFrames) {
    test_support::TempDir dir("render_refit");
    const Scene teapot = load("teapot.obj");
    FrameOptions o;
    o.settings.width = 96;
    o.settings.height = 64;
    o.settings.threads = 1;
    const CameraSpec camera = frame_of(teapot, o).camera;
    FrameRenderer reused;
    const int frames = 2 * AnimationAccel::kMaxRefitsInARow + 3;  // refits, a rebuild, more refits
    for (int f = 0; f < frames; ++f) {
        const Scene scene = twisted_teapot(teapot, f);
        for (LineMode mode : {LineMode::Classic, LineMode::Robust}) {
            o.settings.lines.mode = mode;
            Warnings w;
            FrameRenderer fresh;
            const SceneFrame frame = test_support::scene_frame(scene, camera, 96, 64);
            fresh.render(frame, dir.path / "fresh.png", o, w);
            reused.render(frame, dir.path / "reused.png", o, w);
            EXPECT_FALSE(fresh.accel().refitted());
            ASSERT_TRUE(same_pixels(dir.path / "fresh.png", dir.path / "reused.png"))
                << "frame " << f << (mode == LineMode::Classic ? " classic" : " robust");
        }
    }
}

TEST(AnimationAccel, RefitsTheSameTrianglesAndRebuildsEverySixteenthFrame) {
    const Scene teapot = load("teapot.obj");
    AnimationAccel accel;
    const Bvh::Config config;
    std::vector<bool> refitted;
    for (int f = 0; f < 2 * (AnimationAccel::kMaxRefitsInARow + 1) + 1; ++f) {
        accel.update(twisted_teapot(teapot, f), config);
        refitted.push_back(accel.refitted());
    }
    for (std::size_t f = 0; f < refitted.size(); ++f)
        EXPECT_EQ(refitted[f], f % (AnimationAccel::kMaxRefitsInARow + 1) != 0) << f;
    // Other triangles, or other BVH settings: a build.
    Scene fewer = teapot;
    fewer.tri_positions.pop_back();
    fewer.tri_normals.pop_back();
    fewer.tri_texcoords.pop_back();
    fewer.tri_material.pop_back();
    fewer.tri_object.pop_back();
    accel.update(fewer, config);
    EXPECT_FALSE(accel.refitted());
    Bvh::Config other;
    other.max_leaf_size = config.max_leaf_size + 1;
    accel.update(fewer, other);
    EXPECT_FALSE(accel.refitted());
    accel.update(fewer, other);
    EXPECT_TRUE(accel.refitted());
}

TEST(FrameBytes, CountTheRendererAndTheEncodingWithRoomToSpare) {
    FrameOptions o;
    o.settings.width = 1280;
    o.settings.height = 720;
    const std::uint64_t pixels = 1280ull * 720;
    const std::uint64_t renderer = frame_buffer_bytes(o.render_settings());
    EXPECT_GT(frame_bytes(o), renderer + pixels * 3);
    // Feature images count only when they are written.
    o.aov_dir = "aov";
    EXPECT_TRUE(o.render_settings().layers);
    EXPECT_GT(frame_buffer_bytes(o.render_settings()), renderer);
    // Measured: `toonray render` with robust lines and feature images at 720p peaks at 48 MB,
    // 14 MB of which the program holds before any frame (`toonray --help`): 37 bytes a pixel.
    EXPECT_GT(frame_bytes(o), pixels * 37);
    o.settings.width = o.settings.height = 2147483647;
    EXPECT_EQ(frame_bytes(o), UINT64_MAX);
}

TEST(FrameRenderer, InMemoryFramesAreTheFilesItWrites) {
    // What the Python module and the Blender engine take from render_layers, frame_svg and
    // frame_png_options is what render writes, byte for byte, in every mode.
    test_support::TempDir dir("frame_memory");
    const Scene teapot = load("teapot.obj");
    FrameOptions files;
    files.settings.width = 160;
    files.settings.height = 90;
    files.svg = dir.path / "frame.svg";
    files.svg_hidden = true;
    files.svg_fill = true;
    files.record = {"toonray test", "settings text"};
    FrameOptions memory = files;
    memory.svg.reset();
    memory.keep_layers = true;
    memory.keep_strokes = true;
    for (LineMode mode : {LineMode::Classic, LineMode::Robust, LineMode::Ink}) {
        files.settings.lines.mode = memory.settings.lines.mode = mode;
        const SceneFrame frame = frame_of(teapot, files);
        FrameRenderer writer, keeper;
        Warnings w;
        writer.render(frame, dir.path / "frame.png", files, w);
        const FrameLayers& layers =
            keeper.render_layers(frame.scene, frame.camera, frame.lights, memory, w);
        EXPECT_EQ(frame_svg(layers, memory), read_file(dir.path / "frame.svg"));
        const std::vector<std::uint8_t> png = encode_png(
            layers.image.width(), layers.image.height(), 3,
            reinterpret_cast<const std::uint8_t*>(layers.image.data()), frame_png_options(memory));
        const std::string written = read_file(dir.path / "frame.png");
        ASSERT_EQ(png.size(), written.size()) << line_mode_name(mode);
        EXPECT_EQ(0, std::memcmp(png.data(), written.data(), png.size()));
        // Every layer is kept, and the strokes.
        EXPECT_EQ(layers.distance.size(), layers.image.size());
        EXPECT_FALSE(layers.line_types.empty());
        ASSERT_NE(layers.strokes, nullptr);
        EXPECT_FALSE(layers.strokes->strokes.empty());
    }
    // Without them asked, neither is kept in a mode that does not need them.
    FrameOptions plain;
    plain.settings.width = 160;
    plain.settings.height = 90;
    plain.settings.lines.mode = LineMode::Robust;
    const SceneFrame frame = frame_of(teapot, plain);
    FrameRenderer fr;
    Warnings w;
    const FrameLayers& layers = fr.render_layers(frame.scene, frame.camera, frame.lights, plain, w);
    EXPECT_EQ(layers.distance.size(), 0u);
    EXPECT_EQ(layers.strokes, nullptr);
    EXPECT_THROW((void)frame_svg(layers, plain), Error);
}
