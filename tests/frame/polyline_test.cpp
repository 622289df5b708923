// Polylines (OBJ `l`) drawn as ink strokes in every line mode, hidden behind surfaces.

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "toonray/frame/frame_renderer.h"
#include "toonray/ink/polylines.h"
#include "toonray/io/png.h"
#include "toonray/scene/obj_loader.h"
#include "support/test_scenes.h"
#include "support/test_support.h"

using namespace toonray;
namespace fs = std::filesystem;

namespace {

// A square at z = 0 facing the camera, and polylines in front of it (z = 0.5) or behind it.
const char* kSquare = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\n";
const char* kFront = "v -0.6 0.4 0.5\nv 0 0.2 0.5\nv 0.6 0.4 0.5\nl -3 -2 -1\n";
const char* kBehind = "v -0.6 -0.4 -0.5\nv 0.6 -0.4 -0.5\nl -2 -1\n";

ImageRgb8 render(const std::string& obj, LineMode mode, const fs::path& dir) {
    Scene scene;
    Warnings w;
    parse_obj(obj, "lines.obj", scene, w);
    FrameOptions options;
    options.settings.width = 80;
    options.settings.height = 60;
    options.settings.lines.mode = mode;
    FrameRenderer renderer;
    renderer.render(test_support::scene_frame(scene, CameraSpec{{0, 0, 4}, {0, 0, 0}, {0, 1, 0}}),
                    dir / "frame.png", options, w);
    return read_png(dir / "frame.png").rgb;
}

int differing_pixels(const ImageRgb8& a, const ImageRgb8& b) {
    int n = 0;
    for (std::size_t i = 0; i < a.size(); ++i) n += a.data()[i] != b.data()[i];
    return n;
}

}  // namespace

TEST(Polylines, DrawnInEveryModeAndHiddenBehindSurfaces) {
    test_support::TempDir dir("polylines");
    for (LineMode mode : {LineMode::Classic, LineMode::Robust, LineMode::Ink}) {
        const ImageRgb8 square = render(kSquare, mode, dir.path);
        const ImageRgb8 front = render(std::string(kSquare) + kFront, mode, dir.path);
        const ImageRgb8 behind = render(std::string(kSquare) + kBehind, mode, dir.path);
        // Two strokes of 0.6 * 2 units across a square that fills part of the frame.
        EXPECT_GT(differing_pixels(square, front), 20) << "mode " << static_cast<int>(mode);
        EXPECT_EQ(differing_pixels(square, behind), 0) << "mode " << static_cast<int>(mode);
    }
}

TEST(Polylines, SegmentsFollowThePointsAndSkipZeroLength) {
    Scene scene;
    Warnings w;
    parse_obj("o wire\nv 0 0 0\nv 1 0 0\nv 1 1 0\nl 1 2 2 3\nl 3/1 1/1\n", "lines.obj", scene, w);
    ASSERT_EQ(scene.polylines.size(), 2u);
    EXPECT_EQ(scene.polylines[0].count, 4u);
    EXPECT_EQ(scene.objects[scene.polylines[0].object], "wire");
    std::vector<ink::FeatureSegment> segments;
    ink::add_polyline_segments(scene, segments);
    ASSERT_EQ(segments.size(), 3u);  // 1-2, 2-3 (2-2 has no length), 3-1
    EXPECT_EQ(segments[1].p0, Vec3f(1, 0, 0));
    EXPECT_EQ(segments[1].p1, Vec3f(1, 1, 0));
    EXPECT_EQ(segments[0].key1, segments[1].key0);  // chained through point 2
    for (const ink::FeatureSegment& s : segments) EXPECT_EQ(s.type, ink::EdgeType::Polyline);
}
