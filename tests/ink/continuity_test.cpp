// Lines that stay whole: creases of mouldings narrower than a pixel are drawn along their
// whole length, and strokes change smoothly while the camera moves.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "ink/ink_orbit.h"
#include "ink/ink_scenes.h"
#include "toonray/ink/ink.h"
#include "toonray/scene/obj_loader.h"

namespace toonray {
namespace {

// A camera at `eye` looking at `gaze`, with an up vector orthogonal to the view direction (the
// view plane takes it as given).
CameraSpec look_at(const Vec3f& eye, const Vec3f& gaze, const Vec3f& world_up) {
    const Vec3f forward = normalize(gaze - eye);
    return {eye, gaze, normalize(world_up - forward * dot(world_up, forward))};
}

// The profile of a raised panel, from the outer edge inward as (inset, height): a chamfer, a
// flat, a bead of three facets, a flat, a chamfer up to the raised field, a flat, and a small
// bevel to the field. Every bend is 45 or 60 degrees, above the 40-degree crease angle.
std::vector<std::pair<float, float>> panel_profile() {
    std::vector<std::pair<float, float>> p{{0.0f, 0.0f}, {0.0006f, 0.0006f}, {0.02f, 0.0006f}};
    const float r = 0.0005f;  // the bead: half a circle of radius r in three facets
    for (int k = 1; k <= 3; ++k) {
        const float a = std::numbers::pi_v<float> * static_cast<float>(k) / 3.0f;
        p.emplace_back(0.02f + r * (1.0f - std::cos(a)), 0.0006f + r * std::sin(a));
    }
    p.insert(p.end(), {{0.05f, 0.0006f}, {0.0508f, 0.0014f}, {0.06f, 0.0014f}, {0.0604f, 0.0018f}});
    return p;
}

// Every crease of a moulded panel whose chamfers and beads project under a pixel is drawn
// along at least 99% of the length of its image where rays against every triangle see it.
TEST(InkMouldings, EveryCreaseIsDrawnAlongItsProjectedLength) {
    Scene scene;
    const auto profile = panel_profile();
    test_support::add_moulded_panel(scene, 0.6f, 0.4f, profile);
    const TriangleAccel accel = test_support::build_accel(scene);
    const int w = 1280, h = 720;
    const CameraSpec camera = look_at(Vec3f(0.12f, -0.25f, 1.8f), Vec3f(0.0f), Vec3f(0, 1, 0));
    const ink::ScreenProjection view(make_view_plane(camera, w, h), w, h);

    // The mouldings are narrower than a pixel on the image (measured across the near side).
    int narrow = 0;
    for (std::size_t k = 0; k + 1 < profile.size(); ++k) {
        const ink::Point2 a =
            view.project(Vec3f(0.0f, -(0.4f - profile[k].first), profile[k].second));
        const ink::Point2 b =
            view.project(Vec3f(0.0f, -(0.4f - profile[k + 1].first), profile[k + 1].second));
        narrow += std::hypot(a.x - b.x, a.y - b.y) < 1.0f;
    }
    EXPECT_GE(narrow, 6);

    ink::InkLines lines;
    ink::draw_ink_lines(scene, accel, camera, w, h, {}, 0, lines);
    const ink::VisibilitySettings visibility;
    int creases = 0;
    double total_length = 0, total_visible = 0, total_drawn = 0;
    for (const ink::FeatureSegment& seg : lines.segments) {
        if (seg.type != ink::EdgeType::Crease) continue;
        ++creases;
        std::vector<std::uint32_t> ignored;
        for (std::uint32_t f : seg.faces)
            if (f != kNoIndex) ignored.push_back(f);
        std::sort(ignored.begin(), ignored.end());
        // Samples every quarter pixel along the image; depth is linear along the segment and
        // its inverse along the image.
        const ink::Point2 s0 = view.project(seg.p0), s1 = view.project(seg.p1);
        const float z0 = view.depth(seg.p0), z1 = view.depth(seg.p1);
        const float length = std::hypot(s1.x - s0.x, s1.y - s0.y);
        const int n = std::max(1, static_cast<int>(std::ceil(length * 4.0f)));
        total_length += length;
        double visible = 0, drawn = 0;
        for (int k = 0; k < n; ++k) {
            const float s = (static_cast<float>(k) + 0.5f) / static_cast<float>(n);
            const float t = s * z0 / ((1.0f - s) * z1 + s * z0);
            const Vec3f p = seg.p0 + (seg.p1 - seg.p0) * t;
            if (test_support::brute_force_occluders(scene, p, view.eye(), ignored, visibility) > 0)
                continue;
            const ink::Point2 q = view.project(p);
            const int x = static_cast<int>(std::floor(q.x)), y = static_cast<int>(std::floor(q.y));
            if (x < 0 || y < 0 || x >= w || y >= h) continue;
            visible += length / n;
            drawn += lines.coverage(x, y) >= 0.5f ? length / n : 0.0;
        }
        EXPECT_GE(drawn, 0.99 * visible)
            << "crease " << creases << " from (" << s0.x << ", " << s0.y << ") to (" << s1.x << ", "
            << s1.y << "): " << drawn << " of " << visible << " px drawn";
        total_visible += visible;
        total_drawn += drawn;
    }
    // Nine bends along four sides, and the four mitres of each of the five sloped rings (the
    // flat rings' mitres join coplanar faces).
    EXPECT_EQ(creases, 56);
    // Seen from nearly straight above, the rays see every crease whole (about 21,000 px).
    EXPECT_GT(total_visible, 0.999 * total_length);
    EXPECT_GT(total_visible, 20000.0);
    EXPECT_GE(total_drawn, 0.99 * total_visible);
}

// A slow orbit around the teapot, half a degree per frame for 24 frames: the total length of
// the visible strokes changes smoothly, no frame more than 2% away from the mean of its
// neighbours. Their number is checked on the piano (tests/anim/ink_piano_test.cpp), where a
// stroke is 0.1% of them: the teapot has about 48, so one stroke is 2.1%, and at 10.5 degrees
// its spout's polygonal outline (the teapot has no normals) runs behind the lip for 3 px, which
// parts one stroke in two for that frame; the visibility is right, not the chaining.
TEST(InkOrbit, StrokeLengthChangesSmoothlyAroundTheTeapot) {
    Scene scene;
    Warnings warnings;
    load_obj(std::string(TOONRAY_TEST_DATA_DIR) + "/teapot.obj", scene, warnings);
    const TriangleAccel accel = test_support::build_accel(scene);
    const int w = 1280, h = 720;
    std::vector<Vec3f> used;
    for (const auto& t : scene.tri_positions)
        for (std::uint32_t v : t) used.push_back(scene.positions[v]);
    const CameraSpec start = auto_camera(used, w, h);
    const auto series = test_support::orbit_strokes(scene, accel, start, w, h, 24, 0.5f);
    EXPECT_GT(series.counts.front(), 20.0);
    EXPECT_GT(series.lengths.front(), 4000.0);
    EXPECT_LE(test_support::worst_deviation(series.lengths), 0.02);
}

}  // namespace
}  // namespace toonray
