#pragma once
/// Internal to the ink module (feature_edges.cpp): whether the border of a patch of triangles,
/// projected to a plane, is one simple closed polygon (the intersection search skips patches
/// whose border is, when their triangles all face one way).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace toonray::ink {

// The border of a patch projected to a plane, as sides from one welded vertex to the next (in
// the triangles' winding), and whether they make one simple closed polygon.
struct PatchBorder {
    struct Point {
        float x, y;
    };
    struct Side {
        Point from, to;
        std::uint32_t from_vertex, to_vertex;
    };
    std::vector<Side> sides;
    std::vector<std::uint32_t> order, next;
    std::vector<std::pair<std::uint64_t, std::uint32_t>> cells;

    static float cross(Point o, Point a, Point b) {
        return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
    }
    static float dist(Point a, Point b) {
        const float x = b.x - a.x, y = b.y - a.y;
        return std::sqrt(x * x + y * y);
    }

    // Whether the sides make one closed loop (each vertex starts one side, and following them
    // from the first comes back after all of them) that comes within `margin` of itself
    // nowhere but where consecutive sides meet.
    bool simple_loop() {
        const std::size_t m = sides.size();
        if (m < 3) return false;
        order.resize(m);
        for (std::uint32_t i = 0; i < m; ++i) order[i] = i;
        std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
            return sides[a].from_vertex < sides[b].from_vertex;
        });
        for (std::size_t i = 1; i < m; ++i)
            if (sides[order[i]].from_vertex == sides[order[i - 1]].from_vertex) return false;
        next.resize(m);
        for (std::uint32_t i = 0; i < m; ++i) {
            const auto at = std::lower_bound(
                order.begin(), order.end(), sides[i].to_vertex,
                [&](std::uint32_t a, std::uint32_t v) { return sides[a].from_vertex < v; });
            if (at == order.end() || sides[*at].from_vertex != sides[i].to_vertex) return false;
            next[i] = *at;
        }
        std::size_t steps = 0;
        std::uint32_t e = 0;
        do {
            e = next[e];
            ++steps;
        } while (e != 0 && steps <= m);
        if (steps != m) return false;
        // Sides no longer than `longest` can only come near each other when their middles lie
        // in neighbouring cells of that size. The margin is far above the rounding of the
        // projected corners, which grows with their distance from the centre.
        float longest = 0.0f, reach = 0.0f;
        for (const Side& s : sides) {
            longest = std::max(longest, dist(s.from, s.to));
            reach = std::max({reach, std::abs(s.from.x), std::abs(s.from.y)});
        }
        const float margin = std::max(1e-3f * longest, 1e-5f * reach);
        const float cell = 1.01f * longest + 2.0f * margin;
        // (A patch a million of its longest sides across is not tested: its cells' numbers
        // must fit the keys.)
        if (!(longest > 0.0f) || !(reach < 1e6f * cell)) return false;
        cells.resize(m);
        auto cell_of = [&](float v) { return static_cast<std::int64_t>(std::floor(v / cell)); };
        // Ordered as (x, y): the three cells (x, y - 1 .. y + 1) are one range of keys.
        auto key = [](std::int64_t x, std::int64_t y) {
            constexpr std::int64_t kOffset = std::int64_t{1} << 31;
            return static_cast<std::uint64_t>(x + kOffset) << 32 |
                   static_cast<std::uint64_t>(y + kOffset);
        };
        for (std::uint32_t i = 0; i < m; ++i) {
            const Side& s = sides[i];
            cells[i] = {
                key(cell_of((s.from.x + s.to.x) * 0.5f), cell_of((s.from.y + s.to.y) * 0.5f)), i};
        }
        std::sort(cells.begin(), cells.end());
        // Each side against the sides in the columns x - 1, x and x + 1 of rows y - 1 to y + 1,
        // in key order: where each column's range starts only moves forward.
        std::size_t column_start[3] = {0, 0, 0};
        for (const auto& [cell_key, i] : cells) {
            const std::int64_t cx = static_cast<std::int64_t>(cell_key >> 32) -
                                    (std::int64_t{1} << 31),
                               cy = static_cast<std::int64_t>(cell_key & 0xFFFFFFFFu) -
                                    (std::int64_t{1} << 31);
            for (int dx = -1; dx <= 1; ++dx) {
                const std::uint64_t first = key(cx + dx, cy - 1), last = key(cx + dx, cy + 1);
                std::size_t& at = column_start[dx + 1];
                while (at < m && cells[at].first < first) ++at;
                for (std::size_t k = at; k < m && cells[k].first <= last; ++k) {
                    const std::uint32_t j = cells[k].second;
                    if (j > i && !apart(i, j, margin)) return false;
                }
            }
        }
        return true;
    }

    // Whether sides i and j keep at least `margin` apart, or (when consecutive) meet only at
    // their shared corner without folding back along each other.
    [[nodiscard]] bool apart(std::uint32_t i, std::uint32_t j, float margin) const {
        const Side& a = sides[i];
        const Side& b = sides[j];
        const float la = dist(a.from, a.to), lb = dist(b.from, b.to);
        if (!(la > margin) || !(lb > margin)) return false;
        if (next[i] == j || next[j] == i) {
            if (next[i] == j && next[j] == i) return false;
            const Side& first = next[i] == j ? a : b;
            const Side& second = next[i] == j ? b : a;
            const Point u{first.to.x - first.from.x, first.to.y - first.from.y};
            const Point v{second.to.x - second.from.x, second.to.y - second.from.y};
            const float turn = u.x * v.y - u.y * v.x, along = u.x * v.x + u.y * v.y;
            return along >= 0.0f || std::abs(turn) > margin * std::max(la, lb);
        }
        if (std::max(a.from.x, a.to.x) + margin < std::min(b.from.x, b.to.x) ||
            std::max(b.from.x, b.to.x) + margin < std::min(a.from.x, a.to.x) ||
            std::max(a.from.y, a.to.y) + margin < std::min(b.from.y, b.to.y) ||
            std::max(b.from.y, b.to.y) + margin < std::min(a.from.y, a.to.y))
            return true;
        // One side wholly beyond the other's line, by more than the margin.
        const float b0 = cross(a.from, a.to, b.from), b1 = cross(a.from, a.to, b.to);
        if ((b0 > margin * la && b1 > margin * la) || (b0 < -margin * la && b1 < -margin * la))
            return true;
        const float a0 = cross(b.from, b.to, a.from), a1 = cross(b.from, b.to, a.to);
        return (a0 > margin * lb && a1 > margin * lb) || (a0 < -margin * lb && a1 < -margin * lb);
    }
};

}  // namespace toonray::ink
