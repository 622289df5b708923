#include "toonray/ink/patch_border.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace toonray::ink {
namespace {

using Point = PatchBorder::Point;

// The border through `points` in turn, closing back to the first, with vertices numbered from
// `first_vertex`.
PatchBorder loop_through(const std::vector<Point>& points, std::uint32_t first_vertex = 0) {
    PatchBorder border;
    const auto n = static_cast<std::uint32_t>(points.size());
    for (std::uint32_t i = 0; i < n; ++i)
        border.sides.push_back(
            {points[i], points[(i + 1) % n], first_vertex + i, first_vertex + (i + 1) % n});
    return border;
}

TEST(PatchBorder, ASimplePolygonIsOneSimpleLoop) {
    EXPECT_TRUE(loop_through({{0, 0}, {2, 0}, {2, 1}, {0, 1}}).simple_loop());
    // A comb: long teeth a little apart, each side near others but not within the margin.
    std::vector<Point> comb{{0, 0}, {10, 0}, {10, 5}};
    for (int k = 9; k >= 0; --k) {
        const float x = static_cast<float>(k);
        comb.push_back({x + 0.6f, 5});
        comb.push_back({x + 0.6f, 1});
        comb.push_back({x + 0.4f, 1});
        comb.push_back({x + 0.4f, 5});
    }
    comb.push_back({0, 5});
    EXPECT_TRUE(loop_through(comb).simple_loop());
}

TEST(PatchBorder, ABorderCrossingItselfIsNotSimple) {
    // Bow tie: the sides from (0, 0) to (2, 2) and from (2, 0) to (0, 2) cross.
    EXPECT_FALSE(loop_through({{0, 0}, {2, 2}, {2, 0}, {0, 2}}).simple_loop());
    // The longest side, (-2, 0) to (2, 0), is crossed near its end by a short one whose middle
    // lies in the neighbouring cell of the grid the sides are compared in (cells as large as
    // the longest side, from the origin).
    EXPECT_FALSE(loop_through({{-2, 0}, {2, 0}, {2, 1}, {-1.9f, 1}, {-1.9f, -0.5f}, {-2.5f, -0.5f}})
                     .simple_loop());
    // Touching itself: a side ending on another's middle.
    EXPECT_FALSE(loop_through({{0, 0}, {4, 0}, {4, 2}, {2, 0}, {1, 2}}).simple_loop());
}

TEST(PatchBorder, SidesThatDoNotCloseOneLoopAreNotOne) {
    // Two squares apart: two loops.
    PatchBorder two = loop_through({{0, 0}, {1, 0}, {1, 1}, {0, 1}});
    const PatchBorder other = loop_through({{3, 0}, {4, 0}, {4, 1}, {3, 1}}, 10);
    two.sides.insert(two.sides.end(), other.sides.begin(), other.sides.end());
    EXPECT_FALSE(two.simple_loop());
    // An open chain.
    PatchBorder open = loop_through({{0, 0}, {1, 0}, {1, 1}, {0, 1}});
    open.sides.pop_back();
    EXPECT_FALSE(open.simple_loop());
    // A vertex that starts two sides (two loops through one vertex).
    PatchBorder figure_eight = loop_through({{0, 0}, {1, 0}, {1, 1}});
    figure_eight.sides.push_back({{0, 0}, {-1, 0}, 0, 20});
    figure_eight.sides.push_back({{-1, 0}, {-1, -1}, 20, 21});
    figure_eight.sides.push_back({{-1, -1}, {0, 0}, 21, 0});
    EXPECT_FALSE(figure_eight.simple_loop());
}

}  // namespace
}  // namespace toonray::ink
