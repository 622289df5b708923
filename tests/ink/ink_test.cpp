#include "toonray/ink/ink.h"

#include <gtest/gtest.h>

#include <algorithm>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "ink/ink_scenes.h"
#include "ink/svg_compare.h"
#include "support/test_support.h"
#include "toonray/ink/mesh_topology.h"
#include "toonray/ink/svg.h"
#include "toonray/io/file.h"
#include "toonray/io/png.h"

namespace toonray {
namespace {

using test_support::write_svg;

using test_support::Teapot;

TEST(InkLines, TeapotHasLinesOfEveryStageAndIsThreadIndependent) {
    const Teapot t(640, 360);
    ink::InkLines one, many;
    ink::draw_ink_lines(t.scene, t.accel, t.camera, 640, 360, {}, 1, one);
    ink::draw_ink_lines(t.scene, t.accel, t.camera, 640, 360, {}, 4, many);
    EXPECT_GT(one.segments.size(), 100u);
    EXPECT_GT(one.pieces.size(), 100u);
    EXPECT_GT(one.strokes.size(), 5u);
    ASSERT_EQ(one.coverage.size(), many.coverage.size());
    for (std::size_t i = 0; i < one.coverage.size(); ++i)
        ASSERT_EQ(one.coverage.data()[i], many.coverage.data()[i]);
    // The teapot has no vertex normals: its outline is made of polygonal silhouettes, and it
    // covers a good part of the frame's lines.
    int silhouettes = 0;
    for (const auto& s : one.strokes)
        silhouettes += s.type == ink::EdgeType::Silhouette && s.visible;
    EXPECT_GT(silhouettes, 0);
    long covered = 0;
    for (std::size_t i = 0; i < one.coverage.size(); ++i) covered += one.coverage.data()[i] > 0.5f;
    EXPECT_GT(covered, 1000);
}

TEST(InkLines, MeshEdgesAreKeptForTheNextFrameWhileTheWeldsStay) {
    // The cache keeps the last frame's mesh edges with the welded triangles they were found
    // for, which the next frame's drawing moves into it: the same triangles reuse them, and
    // welds that change find them again. A first frame keeps no mesh edges (a still would not
    // read them: they are freed before the frame's peak), only which objects they close; the
    // second finds them again, and keeps them with the objects and usability they are checked
    // against.
    Teapot t(640, 360);
    ink::InkLines lines;
    ink::draw_ink_lines(t.scene, t.accel, t.camera, 640, 360, {}, 1, lines);
    EXPECT_EQ(lines.intersections.topology, nullptr);
    ASSERT_EQ(lines.intersections.open.size(), t.scene.objects.size());
    const std::vector<std::uint8_t> closed_after_one = ink::closed_objects(lines.intersections);
    ink::draw_ink_lines(t.scene, t.accel, t.camera, 640, 360, {}, 1, lines);
    ASSERT_NE(lines.intersections.topology, nullptr);
    EXPECT_EQ(ink::closed_objects(lines.intersections), closed_after_one);
    const auto first = lines.intersections.topology;
    EXPECT_EQ(first->usable.size(), t.scene.triangle_count());
    const std::vector<ink::FeatureSegment> segments = lines.segments;
    ink::draw_ink_lines(t.scene, t.accel, t.camera, 640, 360, {}, 1, lines);
    EXPECT_EQ(lines.intersections.topology, first);
    EXPECT_EQ(lines.intersections.welded, lines.mesh.tri_vertices);
    ASSERT_EQ(lines.segments.size(), segments.size());
    // Two corners of the first triangle at one place: its welds change.
    t.scene.positions[t.scene.tri_positions[0][1]] = t.scene.positions[t.scene.tri_positions[0][0]];
    t.accel.build(t.scene.positions, t.scene.tri_positions);
    ink::draw_ink_lines(t.scene, t.accel, t.camera, 640, 360, {}, 1, lines);
    EXPECT_NE(lines.intersections.topology, first);
    // A fresh drawing of the changed teapot gives the same segments.
    ink::InkLines fresh;
    ink::draw_ink_lines(t.scene, t.accel, t.camera, 640, 360, {}, 1, fresh);
    ASSERT_EQ(lines.segments.size(), fresh.segments.size());
    for (std::size_t i = 0; i < fresh.segments.size(); ++i) {
        EXPECT_EQ(lines.segments[i].p0, fresh.segments[i].p0) << i;
        EXPECT_EQ(lines.segments[i].p1, fresh.segments[i].p1) << i;
        EXPECT_EQ(lines.segments[i].type, fresh.segments[i].type) << i;
    }
}

TEST(InkLines, VertexRingsAreBuiltOnlyForTheLinesThatReadThem) {
    // A sphere's corner normals give smooth contours, whose visibility reads the rings.
    Scene scene;
    test_support::add_sphere(scene, Vec3f(0.0f), 1.0f, 16, 32, 0);
    TriangleAccel accel;
    accel.build(scene.positions, scene.tri_positions);
    const CameraSpec camera = auto_camera(scene.positions, 320, 240);
    auto draw = [&](const ink::InkSettings& settings) {
        ink::InkLines lines;
        ink::draw_ink_lines(scene, accel, camera, 320, 240, settings, 1, lines);
        const bool smooth = std::any_of(lines.segments.begin(), lines.segments.end(),
                                        [](const ink::FeatureSegment& s) { return s.smooth; });
        return std::pair{smooth, lines.mesh.has_rings()};
    };
    EXPECT_EQ(draw({}), std::pair(true, true));
    // Without them no line is smooth, and the rings (12 bytes a triangle) are not built...
    scene.tri_normals.clear();
    EXPECT_EQ(draw({}), std::pair(false, false));
    // ...unless band lines, which read them too, are drawn.
    ink::InkSettings bands;
    bands.bands = true;
    EXPECT_EQ(draw(bands).second, true);
}

TEST(InkSvg, ParsesAsXmlWithTheLayersAndGroups) {
    const Teapot t(640, 360);
    ink::InkSettings settings;
    settings.chain.hidden = true;
    ink::InkLines lines;
    ink::draw_ink_lines(t.scene, t.accel, t.camera, 640, 360, settings, 1, lines);
    test_support::TempDir dir("ink_svg");
    ink::SvgSettings svg;
    svg.width = 640;
    svg.height = 360;
    svg.thickness = ink::stroke_thickness(settings.width, 360);
    svg.hidden = true;
    write_svg(dir / "teapot.svg", lines.strokes, svg);
    const std::string check = std::string("python3 ") + TOONRAY_TESTS_DIR + "/ink/check_svg.py " +
                              (dir / "teapot.svg").string() + " 640 360 1 10";
    EXPECT_EQ(std::system(check.c_str()), 0) << check;
    // Without hidden lines there is only the visible layer.
    svg.hidden = false;
    write_svg(dir / "visible.svg", lines.strokes, svg);
    const std::string check_visible = std::string("python3 ") + TOONRAY_TESTS_DIR +
                                      "/ink/check_svg.py " + (dir / "visible.svg").string() +
                                      " 640 360 0 10";
    EXPECT_EQ(std::system(check_visible.c_str()), 0) << check_visible;
    // The text itself: one path per visible stroke.
    const std::string text = ink::svg_text(lines.strokes, svg);
    std::size_t paths = 0;
    for (std::size_t at = text.find("<path"); at != std::string::npos;
         at = text.find("<path", at + 1))
        ++paths;
    std::size_t visible = 0;
    for (const auto& s : lines.strokes) visible += s.visible;
    EXPECT_EQ(paths, visible);
}

TEST(InkSvg, StylesGoIntoThePathsAndTheDrawing) {
    const Teapot t(640, 360);
    ink::InkSettings settings;
    settings.chain.hidden = true;
    settings.styles = ink::parse_line_styles(
        "match lines=hidden draw=yes color=#808080 width=1 opacity=0.6 dash=4,3\n"
        "match type=crease draw=no\n",
        "teapot.style");
    ink::InkLines lines;
    ink::draw_ink_lines(t.scene, t.accel, t.camera, 640, 360, settings, 2, lines);
    ASSERT_EQ(lines.styles.size(), 3u);  // the defaults, the dashed hidden lines, creases off
    ASSERT_EQ(lines.pens.size(), 3u);
    std::size_t hidden = 0, creases = 0;
    for (const auto& s : lines.strokes) {
        hidden += !s.visible;
        if (s.visible && s.type == ink::EdgeType::Crease) {
            ++creases;
            EXPECT_FALSE(lines.pens[s.style].draw);
        }
        if (!s.visible) {
            EXPECT_EQ(lines.pens[s.style].dash.size(), 2u);
        }
    }
    EXPECT_GT(hidden, 10u);
    EXPECT_GT(creases, 0u);
    // Hidden lines are drawn now: grey pixels where only hidden strokes lie.
    std::size_t grey = 0;
    for (std::size_t i = 0; i < lines.coverage.size(); ++i)
        grey += lines.coverage.data()[i] > 0.0f && lines.pens[lines.style.data()[i]].opacity < 1;
    EXPECT_GT(grey, 100u);
    test_support::TempDir dir("ink_svg_styles");
    ink::SvgSettings svg;
    svg.width = 640;
    svg.height = 360;
    svg.thickness = ink::stroke_thickness(settings.width, 360);
    svg.hidden = true;
    svg.pens = lines.pens;
    write_svg(dir / "styled.svg", lines.strokes, svg);
    const std::string check = std::string("python3 ") + TOONRAY_TESTS_DIR + "/ink/check_svg.py " +
                              (dir / "styled.svg").string() + " 640 360 1 10 10";
    EXPECT_EQ(std::system(check.c_str()), 0) << check;
    // Visible creases are off: no path in the crease group.
    const std::string text = ink::svg_text(lines.strokes, svg);
    const std::size_t group = text.find("<g id=\"visible-crease\">\n");
    ASSERT_NE(group, std::string::npos);
    EXPECT_EQ(text.compare(group + 24, 4, "</g>"), 0);
}

// A real SVG renderer draws the file like toonray's own coverage: at least 90% of each
// image's line pixels lie within 1.5 px of the other's.
TEST(InkSvg, RsvgDrawsWhatToonrayDraws) {
    const int w = 1280, h = 720;
    const Teapot t(w, h);
    ink::InkLines lines;
    ink::draw_ink_lines(t.scene, t.accel, t.camera, w, h, {}, 0, lines);
    test_support::TempDir dir("ink_rsvg");
    test_support::expect_rsvg_draws_like_coverage(
        lines.strokes, lines.coverage, ink::stroke_thickness(2.0f, h), dir.path, "teapot", 2000);
}

}  // namespace
}  // namespace toonray
