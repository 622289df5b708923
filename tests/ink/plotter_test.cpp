// Plotter-ready SVG (ink/plotter.h): one Inkscape layer per pen, touching paths merged, paths
// ordered to cut pen-up travel (against a greedy nearest neighbour plus 2-opt ordering of the
// same paths written here on its own), and no hidden segment unless hidden lines are asked for.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <regex>
#include <string>
#include <vector>

#include "ink/ink_scenes.h"
#include "support/test_support.h"
#include "toonray/ink/ink.h"
#include "toonray/ink/plotter.h"
#include "toonray/ink/svg.h"

using namespace toonray;
using ink::PlotPath;
using ink::Point2;

namespace {

double dist(Point2 a, Point2 b) { return std::hypot(double{a.x} - b.x, double{a.y} - b.y); }

// A layer of a plotter SVG: its label and its paths' points, in file order (a circle as its
// rightmost point, where the pen lands and lifts).
struct SvgLayer {
    std::string label, colour, width;
    std::vector<std::vector<Point2>> paths;
};

std::vector<SvgLayer> read_layers(const std::string& svg) {
    std::vector<SvgLayer> layers;
    const std::regex layer(
        R"re(<g id="pen-\d+" inkscape:groupmode="layer" inkscape:label="([^"]*)" fill="none" stroke="([^"]*)" stroke-width="([^"]*)")re");
    const std::regex element(
        R"re(<path d="([^"]*)"/>|<circle cx="([^"]*)" cy="([^"]*)" r="([^"]*)"/>)re");
    const std::regex number(R"(-?\d+\.\d+)");
    std::size_t at = 0;
    std::smatch m;
    std::string rest = svg;
    while (std::regex_search(rest, m, layer)) {
        SvgLayer l{m[1], m[2], m[3], {}};
        const std::string after = m.suffix();
        const std::string body = after.substr(0, after.find("</g>"));
        for (auto it = std::sregex_iterator(body.begin(), body.end(), element);
             it != std::sregex_iterator(); ++it) {
            std::vector<Point2> points;
            if ((*it)[1].matched) {
                const std::string d = (*it)[1];
                std::vector<float> v;
                for (auto n = std::sregex_iterator(d.begin(), d.end(), number);
                     n != std::sregex_iterator(); ++n)
                    v.push_back(std::stof(n->str()));
                for (std::size_t i = 0; i + 1 < v.size(); i += 2)
                    points.push_back({v[i], v[i + 1]});
            } else {
                const float cx = std::stof((*it)[2]), cy = std::stof((*it)[3]),
                            r = std::stof((*it)[4]);
                points.push_back({cx + r, cy});
            }
            l.paths.push_back(points);
        }
        layers.push_back(l);
        rest = after;
        ++at;
    }
    return layers;
}

double travel(const std::vector<std::vector<Point2>>& paths) {
    double t = 0.0;
    Point2 at{0, 0};
    for (const auto& p : paths) {
        t += dist(at, p.front());
        at = p.back();
    }
    return t;
}

// The yardstick, written apart from toonray's: greedy nearest neighbour over every path end
// (entering a path at its far end turns it), then 2-opt over every pair of moves (turning the
// run between them) until none shortens the travel.
double greedy_two_opt_travel(std::vector<std::vector<Point2>> paths) {
    const std::size_t n = paths.size();
    std::vector<char> used(n, 0);
    std::vector<std::vector<Point2>> order;
    Point2 at{0, 0};
    for (std::size_t k = 0; k < n; ++k) {
        std::size_t best = 0;
        bool flip = false;
        double best_d = 1e300;
        for (std::size_t i = 0; i < n; ++i) {
            if (used[i]) continue;
            const double ds = dist(at, paths[i].front()), de = dist(at, paths[i].back());
            if (ds < best_d) best_d = ds, best = i, flip = false;
            if (de < best_d) best_d = de, best = i, flip = true;
        }
        used[best] = 1;
        std::vector<Point2> p = paths[best];
        if (flip) std::reverse(p.begin(), p.end());
        at = p.back();
        order.push_back(p);
    }
    for (bool improved = true; improved;) {
        improved = false;
        for (std::size_t i = 0; i < n; ++i)
            for (std::size_t j = i; j < n; ++j) {
                // Turn the run i..j: edges (before i) -> i and j -> (after j).
                const Point2 a = i == 0 ? Point2{0, 0} : order[i - 1].back();
                const Point2 b = order[i].front(), c = order[j].back();
                double before = dist(a, b), after = dist(a, c);
                if (j + 1 < n) {
                    const Point2 d = order[j + 1].front();
                    before += dist(c, d);
                    after += dist(b, d);
                }
                if (after < before - 1e-6) {
                    std::reverse(order.begin() + static_cast<std::ptrdiff_t>(i),
                                 order.begin() + static_cast<std::ptrdiff_t>(j + 1));
                    for (std::size_t k = i; k <= j; ++k)
                        std::reverse(order[k].begin(), order[k].end());
                    improved = true;
                }
            }
    }
    return travel(order);
}

}  // namespace

TEST(Plotter, TouchingPathsMergeAndOthersStayApart) {
    std::vector<PlotPath> paths{
        {{{0, 0}, {10, 0}}, 0.0f},
        {{{20, 5}, {10, 0}}, 0.0f},  // touches the first's end with its own end: turned
        {{{30, 30}, {40, 30}}, 0.0f},
        {{{0, 0}, {0, -10}}, 0.0f},                        // touches the first's start
        {{{5, 5}}, 2.0f},                                  // a circle
        {{{50, 50}, {60, 50}, {60, 60}, {50, 50}}, 0.0f},  // closed
    };
    const auto merged = ink::merge_touching(paths);
    ASSERT_EQ(merged.size(), 4u);
    EXPECT_EQ(merged[0].points, (std::vector<Point2>{{0, -10}, {0, 0}, {10, 0}, {20, 5}}));
    EXPECT_EQ(merged[1].points, (std::vector<Point2>{{30, 30}, {40, 30}}));
    EXPECT_EQ(merged[2].radius, 2.0f);
    EXPECT_EQ(merged[3].points.size(), 4u);
}

TEST(Plotter, OrderingIsWithinATenthOfGreedyPlusTwoOpt) {
    // Random segments, as a hatched frame's strokes are scattered.
    std::vector<PlotPath> paths;
    std::uint32_t state = 12345;
    auto next = [&] {
        state = state * 1664525u + 1013904223u;
        return static_cast<float>(state >> 8) / 16777216.0f;
    };
    for (int i = 0; i < 600; ++i) {
        const Point2 a{next() * 1000.0f, next() * 700.0f};
        paths.push_back({{a, {a.x + next() * 40.0f - 20.0f, a.y + next() * 40.0f - 20.0f}}, 0.0f});
    }
    const auto ordered = ink::order_paths(paths, {0, 0});
    ASSERT_EQ(ordered.size(), paths.size());
    std::vector<std::vector<Point2>> as_points;
    for (const PlotPath& p : ordered) as_points.push_back(p.points);
    const double ours = ink::pen_up_travel(ordered, {0, 0});
    EXPECT_NEAR(ours, travel(as_points), 1e-6 * ours);
    const double reference = greedy_two_opt_travel(as_points);
    double unordered = 0.0;
    {
        Point2 at{0, 0};
        for (const PlotPath& p : paths) unordered += dist(at, p.start()), at = p.end();
    }
    std::printf(
        "random segments: pen-up travel %.0f px, greedy + 2-opt %.0f px (ratio %.3f), in "
        "the given order %.0f px\n",
        ours, reference, ours / reference, unordered);
    EXPECT_LE(ours, 1.10 * reference);
}

TEST(Plotter, AFramesSvgHasALayerPerPenMergedPathsAndShortTravel) {
    const int w = 640, h = 360;
    const test_support::Teapot t(w, h);
    ink::InkSettings settings;
    settings.chain.hidden = true;  // hidden strokes exist; the SVG leaves them out
    settings.styles = ink::parse_line_styles(
        "match type=crease color=#c03020 width=1\nmatch type=material color=#2040c0\n", "p.style");
    ink::InkLines lines;
    ink::draw_ink_lines(t.scene, t.accel, t.camera, w, h, settings, 2, lines);
    ink::SvgSettings svg;
    svg.width = w;
    svg.height = h;
    svg.thickness = ink::stroke_thickness(settings.width, h);
    svg.pens = lines.pens;
    svg.plotter = true;
    const std::string text = ink::svg_text(lines.strokes, svg);
    const std::vector<SvgLayer> layers = read_layers(text);
    ASSERT_GE(layers.size(), 2u);
    std::map<std::pair<std::string, std::string>, int> pens;
    for (const SvgLayer& l : layers) {
        EXPECT_EQ((++pens[{l.colour, l.width}]), 1) << "one layer per pen";
        EXPECT_EQ(l.label.find("hidden"), std::string::npos) << "no hidden lines unless asked";
        // No two paths touch: they would have been merged.
        std::map<std::pair<long, long>, int> ends;
        for (const auto& p : l.paths) {
            if (p.size() < 2 || dist(p.front(), p.back()) < 1e-3) continue;
            for (Point2 q : {p.front(), p.back()})
                ++ends[{std::lround(q.x * 1000), std::lround(q.y * 1000)}];
        }
        for (const auto& [k, count] : ends) EXPECT_EQ(count, 1) << l.label;
        const double ours = travel(l.paths), reference = greedy_two_opt_travel(l.paths);
        std::printf(
            "teapot layer %s: %zu paths, pen-up travel %.0f px, greedy + 2-opt %.0f px, "
            "ratio %.3f\n",
            l.label.c_str(), l.paths.size(), ours, reference, ours / reference);
        EXPECT_LE(ours, 1.10 * reference + 1e-6) << l.label;
    }
    EXPECT_EQ(text.find("hidden"), std::string::npos);
    // Hidden lines asked for: a layer of their own.
    svg.hidden = true;
    const std::vector<SvgLayer> with_hidden = read_layers(ink::svg_text(lines.strokes, svg));
    EXPECT_EQ(with_hidden.size(), layers.size() + 1);
    EXPECT_NE(with_hidden.back().label.find("hidden"), std::string::npos);
}
