#include "toonray/ink/visibility.h"

#include <gtest/gtest.h>

#include "ink/ink_scenes.h"
#include "toonray/ink/strokes.h"

namespace toonray {
namespace {

using test_support::add_quad;
using test_support::build_accel;

struct Frame {
    Scene scene;
    ink::WeldedMesh mesh;
    TriangleAccel accel;
    ink::ScreenProjection view;
    std::vector<ink::FeatureSegment> segments;

    Frame(Scene s, const CameraSpec& camera, int w, int h) : scene(std::move(s)) {
        mesh = ink::weld_vertices(scene);
        accel = build_accel(scene);
        const ViewPlane plane = make_view_plane(camera, w, h);
        view = ink::ScreenProjection(plane, w, h);
        segments = ink::find_feature_edges(scene, mesh, accel.bvh(), plane.eye, {}, 1);
    }
    [[nodiscard]] ink::VisibilityContext context() const { return {scene, mesh, accel, view}; }
};

TEST(ScreenProjection, AgreesWithTheViewPlane) {
    const CameraSpec camera{Vec3f(1, 2, 5), Vec3f(0.8f, 1.9f, 4.0f), normalize(Vec3f(0, 1, -0.1f))};
    const ViewPlane plane =
        make_view_plane(CameraSpec{camera.eye, camera.gaze, Vec3f(0, 1, 0)}, 320, 200);
    const ink::ScreenProjection view(plane, 320, 200);
    // The point seen through pixel (x, y)'s centre projects to (x + 0.5, y + 0.5).
    for (const auto& [x, y] : {std::pair{0, 0}, {319, 199}, {100, 37}}) {
        const Vec3f p = plane.eye + (plane.pixel_point(x + 0.5f, y + 0.5f) - plane.eye) * 3.7f;
        const ink::Point2 q = view.project(p);
        EXPECT_NEAR(q.x, x + 0.5f, 1e-3f);
        EXPECT_NEAR(q.y, y + 0.5f, 1e-3f);
    }
}

TEST(Visibility, OccluderCutsALineWhereItsEdgesProject) {
    // A border line along x at z = 0, and a quad at z = 1 hiding its middle from an eye at z = 5.
    Scene s;
    add_quad(s, Vec3f(-1, 0, 0), Vec3f(1, 0, 0), Vec3f(1, -0.01f, -1), Vec3f(-1, -0.01f, -1));
    add_quad(s, Vec3f(-0.25f, -1, 1), Vec3f(0.25f, -1, 1), Vec3f(0.25f, 1, 1), Vec3f(-0.25f, 1, 1),
             0, 1);
    const Frame f(std::move(s), CameraSpec{Vec3f(0, 0, 5), Vec3f(0, 0, 4), Vec3f(0, 1, 0)}, 640,
                  480);
    const auto pieces = ink::split_by_visibility(f.segments, f.context(), {}, 1);
    std::uint32_t index = 0;
    while (index < f.segments.size() &&
           !(f.segments[index].p0.z == 0 && f.segments[index].p1.z == 0))
        ++index;
    ASSERT_LT(index, f.segments.size());
    std::vector<ink::EdgePiece> line;
    for (const auto& p : pieces)
        if (p.segment == index) line.push_back(p);
    ASSERT_EQ(line.size(), 3u);
    EXPECT_EQ(line[0].invisibility, 0);
    EXPECT_EQ(line[1].invisibility, 1);
    EXPECT_EQ(line[2].invisibility, 0);
    // The occluder's edges at x = +-0.25, depth 4, fall on x = +-0.3125 at depth 5.
    const float cut_a = f.view.project(Vec3f(-0.25f, 0, 1)).x,
                cut_b = f.view.project(Vec3f(0.25f, 0, 1)).x;
    const float x0 = std::min(line[1].s0.x, line[1].s1.x),
                x1 = std::max(line[1].s0.x, line[1].s1.x);
    EXPECT_NEAR(x0, std::min(cut_a, cut_b), 1.0f / 16);
    EXPECT_NEAR(x1, std::max(cut_a, cut_b), 1.0f / 16);
    EXPECT_EQ(line[0].t0 == 0 ? line[0].key0 : line[2].key1,
              line[0].t0 == 0 ? f.segments[index].key0
                              : f.segments[index].key1);  // the uncut end keeps its key
    EXPECT_EQ(line[0].key1.a, kNoIndex);                  // a cut end has none
}

// Rays from the eye to points along every piece agree with the piece's state (checked against
// every triangle, not the accelerator) wherever the true state does not change within 1 px:
// a piece's ends are within 1/16 px of a change point, but an occluder narrower than the
// sampling step (a triangle seen edge-on) can hide a line for less than a pixel unnoticed.
void check_against_brute_force(int max_invisibility) {
    for (unsigned seed : {1u, 2u, 3u}) {
        Scene s = test_support::random_scene(150, seed);
        test_support::add_sphere(s, Vec3f(0.1f, -0.2f, 0.3f), 0.45f, 10, 20, 1);
        const Frame f(std::move(s),
                      CameraSpec{Vec3f(2.5f, 1.5f, 3.5f), Vec3f(1.8f, 1.1f, 2.5f),
                                 normalize(Vec3f(-0.2f, 1.0f, -0.1f))},
                      320, 240);
        ink::VisibilitySettings settings;
        settings.max_invisibility = max_invisibility;
        const auto pieces = ink::split_by_visibility(f.segments, f.context(), settings, 1);
        int checked = 0, hidden = 0, deep = 0, near_change = 0;
        for (const auto& p : pieces) {
            const float len = std::hypot(p.s1.x - p.s0.x, p.s1.y - p.s0.y);
            if (len < 4.0f) continue;
            const auto& seg = f.segments[p.segment];
            const auto ignored = ink::ignored_triangles(seg, f.mesh);
            // The point of the segment whose image is `d` pixels from the piece's start s0, by
            // bisection on the image (independent of the depth interpolation the piece used).
            auto point_at = [&](float d) {
                float lo = p.t0, hi = p.t1;
                for (int k = 0; k < 40; ++k) {
                    const float mid = 0.5f * (lo + hi);
                    const ink::Point2 m = f.view.project(seg.p0 + (seg.p1 - seg.p0) * mid);
                    (std::hypot(m.x - p.s0.x, m.y - p.s0.y) < d ? lo : hi) = mid;
                }
                return seg.p0 + (seg.p1 - seg.p0) * (0.5f * (lo + hi));
            };
            auto truth = [&](float d) {
                return test_support::brute_force_occluders(f.scene, point_at(d), f.view.eye(),
                                                           ignored, settings);
            };
            for (float u : {0.0f, 0.25f, 0.5f, 0.75f, 1.0f}) {
                const float d = 1.5f + (len - 3.0f) * u;  // at least 1.5 px from the piece's ends
                const int expected = truth(d);
                bool steady = true;
                for (int k = -8; k <= 8 && steady; ++k) steady = truth(d + k / 8.0f) == expected;
                if (!steady) {
                    ++near_change;
                    continue;
                }
                EXPECT_EQ(
                    ink::count_occluders(f.accel, point_at(d), f.view.eye(), ignored, settings),
                    expected);
                ASSERT_EQ(p.invisibility == 0, expected == 0)
                    << "seed " << seed << " segment " << p.segment;
                EXPECT_EQ(p.invisibility, expected) << "seed " << seed << " segment " << p.segment;
                ++checked;
                hidden += expected > 0;
                deep += expected > 1;
            }
        }
        EXPECT_GT(checked, 300);
        // Edge-on slivers are common in a random soup: about 8% of these points are near a
        // change within 1 px, most of them flickers narrower than the 1 px sampling step.
        EXPECT_LT(near_change, checked / 5);
        EXPECT_GT(hidden, 50);
        if (max_invisibility > 1) {
            EXPECT_GT(deep, 10);
        }
        EXPECT_GT(checked - hidden, 50);
    }
}

TEST(Visibility, PiecesAgreeWithBruteForceRaysOnRandomScenes) { check_against_brute_force(255); }

// Telling only hidden from visible, the samples are traced as packets from the eye.
TEST(Visibility, HiddenOrNotAgreesWithBruteForceRaysOnRandomScenes) {
    check_against_brute_force(1);
}

// A point behind a stack of parallel quads: the nearer ones are on the ignored list (as the
// rings around a smooth contour are), the farther ones count. However many ignored surfaces
// come first, the count is exact up to max_invisibility, which caps it.
TEST(Visibility, CountsEveryOccluderBehindAnyNumberOfIgnoredSurfaces) {
    constexpr int kIgnoredQuads = 1100, kCountedQuads = 300;
    Scene s;
    for (int i = 0; i < kIgnoredQuads + kCountedQuads; ++i) {
        const float z = 0.5f + 9.0f * static_cast<float>(i) / (kIgnoredQuads + kCountedQuads);
        add_quad(s, Vec3f(-1, -1, z), Vec3f(1, -1, z), Vec3f(1, 1, z), Vec3f(-1, 1, z));
    }
    const TriangleAccel accel = build_accel(s);
    std::vector<std::uint32_t> ignored(2 * kIgnoredQuads);  // both triangles of each quad
    for (std::size_t k = 0; k < ignored.size(); ++k) ignored[k] = static_cast<std::uint32_t>(k);
    // Off the quads' diagonals, so that the ray meets one triangle of each.
    const Vec3f point(0.3f, -0.2f, 0.0f), eye(0.3f, -0.2f, 10.0f);
    for (const auto& [max_invisibility, expected] : {std::pair{1, 1},
                                                     {2, 2},
                                                     {255, 255},
                                                     {kCountedQuads, kCountedQuads},
                                                     {100000, kCountedQuads}}) {
        ink::VisibilitySettings settings;
        settings.max_invisibility = max_invisibility;
        EXPECT_EQ(ink::count_occluders(accel, point, eye, ignored, settings), expected)
            << "at most " << max_invisibility;
        EXPECT_EQ(test_support::brute_force_occluders(s, point, eye, ignored, settings), expected);
    }
}

TEST(Visibility, SameForAnyThreadCount) {
    Scene s = test_support::random_scene(300, 11);
    const Frame f(std::move(s),
                  CameraSpec{Vec3f(2.5f, 1.5f, 3.5f), Vec3f(1.8f, 1.1f, 2.5f),
                             normalize(Vec3f(-0.2f, 1.0f, -0.1f))},
                  320, 240);
    for (int max_invisibility : {255, 1}) {
        ink::VisibilitySettings settings;
        settings.max_invisibility = max_invisibility;
        const auto one = ink::split_by_visibility(f.segments, f.context(), settings, 1);
        const auto many = ink::split_by_visibility(f.segments, f.context(), settings, 4);
        ASSERT_EQ(one.size(), many.size());
        for (std::size_t i = 0; i < one.size(); ++i) {
            EXPECT_EQ(one[i].segment, many[i].segment);
            EXPECT_EQ(one[i].t0, many[i].t0);
            EXPECT_EQ(one[i].t1, many[i].t1);
            EXPECT_EQ(one[i].invisibility, many[i].invisibility);
        }
    }
}

TEST(Visibility, WithoutHiddenPiecesTheVisibleStrokesAreTheSame) {
    // When nothing draws hidden lines, visibility keeps only the pieces chaining would draw:
    // the strokes must not change. Random scenes have sub-pixel pieces between pieces of the
    // other visibility, which chaining's rule settles (checked below, so the rule is exercised).
    int settled_pieces = 0;
    for (std::uint32_t seed : {11u, 12u, 13u}) {
        Scene s = test_support::random_scene(300, seed);
        const Frame f(std::move(s),
                      CameraSpec{Vec3f(2.5f, 1.5f, 3.5f), Vec3f(1.8f, 1.1f, 2.5f),
                                 normalize(Vec3f(-0.2f, 1.0f, -0.1f))},
                      320, 240);
        ink::VisibilitySettings settings;
        settings.max_invisibility = 1;
        const auto all = ink::split_by_visibility(f.segments, f.context(), settings, 2);
        settings.keep_hidden = false;
        const ink::ChainSettings chain;
        settings.min_piece = chain.min_piece;
        const auto drawn = ink::split_by_visibility(f.segments, f.context(), settings, 2);
        EXPECT_LT(drawn.size(), all.size());
        for (const ink::EdgePiece& p : drawn) EXPECT_TRUE(p.visible());
        std::vector<char> visible;
        for (std::size_t i = 0; i < all.size();) {
            std::size_t j = i + 1;
            while (j < all.size() && all[j].segment == all[i].segment) ++j;
            ink::settle_sub_pixel_pieces(std::span(all).subspan(i, j - i), chain.min_piece,
                                         visible);
            for (std::size_t k = 0; k < visible.size(); ++k)
                settled_pieces += static_cast<bool>(visible[k]) != all[i + k].visible();
            i = j;
        }
        const auto a = ink::chain_pieces(all, chain, {});
        const auto b = ink::chain_pieces(drawn, chain, {});
        ASSERT_EQ(a.size(), b.size()) << seed;
        for (std::size_t i = 0; i < a.size(); ++i) {
            EXPECT_EQ(a[i].points, b[i].points) << seed << " stroke " << i;
            EXPECT_EQ(a[i].closed, b[i].closed);
            EXPECT_EQ(a[i].type, b[i].type);
        }
    }
    EXPECT_GT(settled_pieces, 0);
}

TEST(Visibility, SegmentsWithoutPiecesAreDropped) {
    std::vector<ink::FeatureSegment> segments(5);
    for (std::size_t i = 0; i < segments.size(); ++i)
        segments[i].p0 = Vec3f(static_cast<float>(i), 0, 0);
    std::vector<ink::EdgePiece> pieces(4);
    const std::uint32_t on[] = {1, 1, 3, 4};
    for (std::size_t k = 0; k < pieces.size(); ++k) pieces[k].segment = on[k];
    ink::drop_segments_without_pieces(segments, pieces);
    ASSERT_EQ(segments.size(), 3u);
    EXPECT_EQ(segments[0].p0.x, 1.0f);
    EXPECT_EQ(segments[1].p0.x, 3.0f);
    EXPECT_EQ(segments[2].p0.x, 4.0f);
    const std::uint32_t renumbered[] = {0, 0, 1, 2};
    for (std::size_t k = 0; k < pieces.size(); ++k) EXPECT_EQ(pieces[k].segment, renumbered[k]);
    std::vector<ink::EdgePiece> none;
    ink::drop_segments_without_pieces(segments, none);
    EXPECT_TRUE(segments.empty());
}

TEST(Visibility, LinesOnTheFarSideOfClosedSolidsAreHiddenWithoutRays) {
    Scene s;
    test_support::add_box(s, Vec3f(-1.0f), Vec3f(0.0f), 0);
    test_support::add_box(s, Vec3f(0.2f), Vec3f(1.0f), 1);
    test_support::add_box(s, Vec3f(-0.5f, 0.3f, -0.5f), Vec3f(0.6f, 0.5f, 0.4f),
                          2);  // crosses box 1
    // An open box (no top) is not closed: its far edges may be seen from inside.
    Scene open_box;
    test_support::add_box(open_box, Vec3f(-0.5f), Vec3f(0.5f));
    open_box.tri_positions.erase(open_box.tri_positions.begin() + 6,
                                 open_box.tri_positions.begin() + 8);
    open_box.tri_normals.resize(10), open_box.tri_texcoords.resize(10),
        open_box.tri_material.resize(10), open_box.tri_object.resize(10);
    const CameraSpec camera{Vec3f(2.5f, 2.0f, 3.0f), Vec3f(1.8f, 1.4f, 2.2f),
                            normalize(Vec3f(-0.3f, 1.0f, -0.3f))};
    const Frame f(std::move(s), camera, 320, 240);
    int certain = 0;
    for (const auto& seg : f.segments) certain += seg.certainly_hidden;
    EXPECT_GE(certain, 9);  // three far edges of each box at least
    // Traced, every piece of those segments is hidden.
    const auto traced = ink::split_by_visibility(f.segments, f.context(), {}, 1);
    for (const auto& p : traced)
        if (f.segments[p.segment].certainly_hidden) {
            EXPECT_GT(p.invisibility, 0) << p.segment;
        }
    ink::VisibilitySettings binary;
    binary.max_invisibility = 1;
    for (const auto& p : ink::split_by_visibility(f.segments, f.context(), binary, 1))
        if (f.segments[p.segment].certainly_hidden) {
            EXPECT_EQ(p.invisibility, 1);
        }
    const Frame g(std::move(open_box),
                  CameraSpec{Vec3f(0.3f, 3.0f, 0.2f), Vec3f(0.3f, 2.0f, 0.2f), Vec3f(0, 0, -1)},
                  320, 240);
    for (const auto& seg : g.segments) EXPECT_FALSE(seg.certainly_hidden);
}

TEST(Visibility, PartsBehindTheEyeOrOffTheImageAreLeftOut) {
    Scene s;
    // A long border line from behind the eye to far in front, and one far to the side.
    add_quad(s, Vec3f(0, -0.2f, 10), Vec3f(0, -0.2f, -10), Vec3f(0.01f, -0.3f, -10),
             Vec3f(0.01f, -0.3f, 10));
    add_quad(s, Vec3f(50, 0, -2), Vec3f(51, 0, -2), Vec3f(51, 1, -2), Vec3f(50, 1, -2), 0, 1);
    const Frame f(std::move(s), CameraSpec{Vec3f(0, 0, 5), Vec3f(0, 0, 4), Vec3f(0, 1, 0)}, 320,
                  240);
    const auto pieces = ink::split_by_visibility(f.segments, f.context(), {}, 1);
    ASSERT_FALSE(pieces.empty());
    for (const auto& p : pieces) {
        EXPECT_GT(f.view.depth(p.p0), 0.0f);
        EXPECT_GT(f.view.depth(p.p1), 0.0f);
        for (const ink::Point2& q : {p.s0, p.s1}) {
            EXPECT_GE(q.x, -4.01f);
            EXPECT_LE(q.x, 324.01f);
            EXPECT_GE(q.y, -4.01f);
            EXPECT_LE(q.y, 244.01f);
        }
    }
}

}  // namespace
}  // namespace toonray
