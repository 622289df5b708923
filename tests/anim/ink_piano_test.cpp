// The ink lines on the demo's piano, posed in memory as `toonray piano` poses it: few specks
// on frames 30 and 150, an SVG that a real SVG renderer draws like the PNG, and strokes that
// change smoothly while the camera orbits.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "ink/ink_orbit.h"
#include "ink/ink_scenes.h"
#include "ink/svg_compare.h"
#include "support/test_support.h"
#include "toonray/anim/piano_movie.h"
#include "toonray/ink/ink.h"
#include "toonray/piano/piano_animation.h"
#include "toonray/piano/piano_model.h"

namespace toonray {
namespace {

// The demo's piano at frame `frame` of `toonray piano` (24 fps from t = 0), with the camera of
// the demo's path; the same scene `toonray piano --export-obj` writes, before the OBJ rounds it.
struct PianoFrame {
    Scene scene;
    CameraSpec camera;
    TriangleAccel accel;

    explicit PianoFrame(int frame) {
        const Score score = load_demo_score();
        const CameraPath path = load_demo_camera_path();
        const PianoPlayback playback(score);
        PianoOptions options;
        options.hole_capacity = std::max<std::uint32_t>(playback.hole_capacity(), 1);
        const PianoModel model = build_piano(options);
        scene = model.scene;
        const double t = (frame - 1) / 24.0;
        pose_piano(model, playback.pose_at(t), &playback.roll(), scene);
        camera = path.camera(t);
        accel.build(scene.positions, scene.tri_positions);
    }
};

int ink_specks(const PianoFrame& piano, int w, int h, ink::InkLines& lines) {
    ink::draw_ink_lines(piano.scene, piano.accel, piano.camera, w, h, {}, 0, lines);
    ImageGray8 gray;
    ink::coverage_to_gray(lines.coverage, gray);
    return test_support::count_specks(gray);
}

// Specks (8-connected groups of at most 12 pixels darker than 8%) in the ink lines of the
// frames where the robust lines show hundreds (575 and 660 in `_edges.png`).
TEST(InkPiano, FewSpecksOnFrames30And150) {
    for (int frame : {30, 150}) {
        const PianoFrame piano(frame);
        ink::InkLines lines;
        EXPECT_LE(ink_specks(piano, 1280, 720, lines), 30) << "frame " << frame;
        EXPECT_GT(lines.strokes.size(), 500u) << "frame " << frame;
    }
}

TEST(InkPiano, RsvgDrawsTheSvgLikeThePng) {
    const PianoFrame piano(30);
    const int w = 1280, h = 720;
    ink::InkLines lines;
    ink::draw_ink_lines(piano.scene, piano.accel, piano.camera, w, h, {}, 0, lines);
    test_support::TempDir dir("ink_piano_rsvg");
    test_support::expect_rsvg_draws_like_coverage(
        lines.strokes, lines.coverage, ink::stroke_thickness(2.0f, h), dir.path, "piano", 20000);
}

// A slow orbit around piano frame 30, half a degree per frame for 24 frames about the vertical
// through the gaze point: the number of visible strokes and their total length change
// smoothly, no frame more than 2% away from the mean of its neighbours.
TEST(InkPiano, StrokesChangeSmoothlyInASlowOrbit) {
    const PianoFrame piano(30);
    const int w = 1280, h = 720;
    const auto series =
        test_support::orbit_strokes(piano.scene, piano.accel, piano.camera, w, h, 24, 0.5f);
    EXPECT_GT(series.counts.front(), 500.0);
    EXPECT_LE(test_support::worst_deviation(series.counts), 0.02);
    EXPECT_LE(test_support::worst_deviation(series.lengths), 0.02);
}

// Intersection lines kept from the previous frame for the triangles that did not move give
// the same segments and the same lines as a frame drawn from scratch, with and without hidden
// lines, after a previous frame seen from another camera.
TEST(InkPiano, IntersectionLinesKeptAcrossFramesAreTheSame) {
    const PianoFrame previous(29), frame(30);
    // The keys moved between the two frames, most of the piano did not.
    std::size_t moved = 0;
    for (std::size_t t = 0; t < frame.scene.triangle_count(); ++t)
        for (int k = 0; k < 3; ++k)
            if (!(frame.scene.positions[frame.scene.tri_positions[t][k]] ==
                  previous.scene.positions[previous.scene.tri_positions[t][k]])) {
                ++moved;
                break;
            }
    EXPECT_GT(moved, 100u);
    EXPECT_LT(moved, frame.scene.triangle_count() / 4);
    for (bool hidden : {false, true}) {
        ink::InkSettings settings;
        settings.chain.hidden = hidden;
        ink::InkLines warm, cold;
        // The previous frame from elsewhere, and with the other choice of hidden lines (which
        // decides the triangles that take part).
        const CameraSpec elsewhere = test_support::orbit_camera(frame.camera, 20.0f);
        ink::InkSettings before = settings;
        before.chain.hidden = !hidden;
        // Twice: the cache keeps the triangles' corners from its second frame on.
        for (int repeat = 0; repeat < 2; ++repeat)
            ink::draw_ink_lines(previous.scene, previous.accel, elsewhere, 640, 360, before, 0,
                                warm);
        ASSERT_EQ(warm.intersections.corners.size(), previous.scene.triangle_count());
        ink::draw_ink_lines(frame.scene, frame.accel, frame.camera, 640, 360, settings, 0, warm);
        ink::draw_ink_lines(frame.scene, frame.accel, frame.camera, 640, 360, settings, 0, cold);
        ASSERT_EQ(warm.segments.size(), cold.segments.size());
        int intersections = 0;
        for (std::size_t i = 0; i < cold.segments.size(); ++i) {
            const ink::FeatureSegment &a = warm.segments[i], &b = cold.segments[i];
            ASSERT_TRUE(a.p0 == b.p0 && a.p1 == b.p1 && a.key0 == b.key0 && a.key1 == b.key1 &&
                        a.type == b.type && a.faces == b.faces && a.smooth == b.smooth &&
                        a.certainly_hidden == b.certainly_hidden)
                << "segment " << i;
            intersections += b.type == ink::EdgeType::Intersection;
        }
        EXPECT_GT(intersections, 500);
        ASSERT_EQ(warm.coverage.size(), cold.coverage.size());
        for (std::size_t i = 0; i < cold.coverage.size(); ++i)
            ASSERT_EQ(warm.coverage.data()[i], cold.coverage.data()[i]);
        EXPECT_EQ(warm.intersections.crossings.size(), cold.intersections.crossings.size());
    }
}

}  // namespace
}  // namespace toonray
