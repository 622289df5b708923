#include "toonray/ink/plotter.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <tuple>

#include "toonray/ink/draw.h"

namespace toonray::ink {

Point2 PlotPath::start() const {
    return radius > 0.0f ? Point2{points[0].x + radius, points[0].y} : points.front();
}

Point2 PlotPath::end() const {
    return radius > 0.0f ? Point2{points[0].x + radius, points[0].y} : points.back();
}

namespace {

double distance(Point2 a, Point2 b) {
    const double dx = static_cast<double>(a.x) - b.x, dy = static_cast<double>(a.y) - b.y;
    return std::sqrt(dx * dx + dy * dy);
}

// A point at the SVG's precision (1/1000 px): ends that print alike touch.
using Key = std::pair<std::int64_t, std::int64_t>;
Key key_of(Point2 p) { return {std::llround(p.x * 1000.0), std::llround(p.y * 1000.0)}; }

bool open_path(const PlotPath& p) {
    return p.radius <= 0.0f && p.points.size() >= 2 && key_of(p.start()) != key_of(p.end());
}

void turn(PlotPath& p) {
    if (p.radius <= 0.0f) std::reverse(p.points.begin(), p.points.end());
}

// Path ends in cells of a uniform grid, for nearest-end queries.
class EndGrid {
public:
    EndGrid(const std::vector<PlotPath>& paths) {
        float lo_x = std::numeric_limits<float>::infinity(), lo_y = lo_x, hi_x = -lo_x,
              hi_y = -lo_x;
        for (const PlotPath& p : paths)
            for (Point2 q : {p.start(), p.end()}) {
                lo_x = std::min(lo_x, q.x);
                lo_y = std::min(lo_y, q.y);
                hi_x = std::max(hi_x, q.x);
                hi_y = std::max(hi_y, q.y);
            }
        if (paths.empty()) lo_x = lo_y = hi_x = hi_y = 0.0f;
        x0_ = lo_x;
        y0_ = lo_y;
        const double area = std::max(1e-6, (static_cast<double>(hi_x) - lo_x) * (hi_y - lo_y));
        cell_ = static_cast<float>(
            std::max(1e-3, std::sqrt(area / std::max<std::size_t>(paths.size(), 1)) * 2.0));
        columns_ = std::max(1, static_cast<int>((hi_x - lo_x) / cell_) + 1);
        rows_ = std::max(1, static_cast<int>((hi_y - lo_y) / cell_) + 1);
        cells_.assign(static_cast<std::size_t>(columns_) * rows_, {});
        for (std::uint32_t i = 0; i < paths.size(); ++i) {
            cells_[cell(paths[i].start())].push_back(2 * i);
            if (paths[i].radius <= 0.0f) cells_[cell(paths[i].end())].push_back(2 * i + 1);
        }
    }

    // The nearest end (2 path + side) passing `usable`, or kNoIndex; ties to the lower end.
    template <class Usable>
    std::uint32_t nearest(Point2 at, const std::vector<PlotPath>& paths, Usable&& usable) const {
        const int cx = std::clamp(static_cast<int>((at.x - x0_) / cell_), 0, columns_ - 1);
        const int cy = std::clamp(static_cast<int>((at.y - y0_) / cell_), 0, rows_ - 1);
        std::uint32_t best = kNoIndex;
        double best_d = std::numeric_limits<double>::infinity();
        const int most = std::max(columns_, rows_);
        for (int ring = 0; ring <= most; ++ring) {
            // Every end in a cell of this ring is at least (ring - 1) cells away.
            if (best != kNoIndex && (ring - 1) * static_cast<double>(cell_) > best_d) break;
            for (int y = cy - ring; y <= cy + ring; ++y)
                for (int x = cx - ring; x <= cx + ring; ++x) {
                    if (std::max(std::abs(x - cx), std::abs(y - cy)) != ring) continue;
                    if (x < 0 || y < 0 || x >= columns_ || y >= rows_) continue;
                    for (std::uint32_t e : cells_[static_cast<std::size_t>(y) * columns_ + x]) {
                        if (!usable(e / 2)) continue;
                        const PlotPath& p = paths[e / 2];
                        const double d = distance(at, e % 2 ? p.end() : p.start());
                        if (d < best_d || (d == best_d && e < best)) {
                            best_d = d;
                            best = e;
                        }
                    }
                }
        }
        return best;
    }

private:
    std::size_t cell(Point2 p) const {
        const int x = std::clamp(static_cast<int>((p.x - x0_) / cell_), 0, columns_ - 1);
        const int y = std::clamp(static_cast<int>((p.y - y0_) / cell_), 0, rows_ - 1);
        return static_cast<std::size_t>(y) * columns_ + x;
    }
    float x0_ = 0, y0_ = 0, cell_ = 1;
    int columns_ = 1, rows_ = 1;
    std::vector<std::vector<std::uint32_t>> cells_;
};

}  // namespace

std::vector<PlotPath> merge_touching(std::vector<PlotPath> paths) {
    // Open paths' ends by key, in (key, path, side) order.
    std::vector<std::tuple<Key, std::uint32_t, int>> ends;
    for (std::uint32_t i = 0; i < paths.size(); ++i)
        if (open_path(paths[i])) {
            ends.emplace_back(key_of(paths[i].start()), i, 0);
            ends.emplace_back(key_of(paths[i].end()), i, 1);
        }
    std::sort(ends.begin(), ends.end());
    std::vector<char> used(paths.size(), 0);
    // The first unused open path other than `self` with an end at `k`, and which end.
    auto touching = [&](const Key& k, std::uint32_t self, int& side) -> std::uint32_t {
        auto it = std::lower_bound(ends.begin(), ends.end(), std::make_tuple(k, 0u, 0));
        for (; it != ends.end() && std::get<0>(*it) == k; ++it) {
            const std::uint32_t j = std::get<1>(*it);
            if (j == self || used[j]) continue;
            side = std::get<2>(*it);
            return j;
        }
        return kNoIndex;
    };
    std::vector<PlotPath> out;
    for (std::uint32_t i = 0; i < paths.size(); ++i) {
        if (used[i]) continue;
        used[i] = 1;
        PlotPath current = std::move(paths[i]);
        if (open_path(current)) {
            for (int direction = 0; direction < 2; ++direction) {
                if (direction == 1) turn(current);  // grow the start as an end
                for (;;) {
                    if (key_of(current.start()) == key_of(current.end())) break;  // closed
                    int side = 0;
                    const std::uint32_t j = touching(key_of(current.end()), i, side);
                    if (j == kNoIndex) break;
                    used[j] = 1;
                    PlotPath& next = paths[j];
                    if (side == 1) turn(next);
                    current.points.insert(current.points.end(), next.points.begin() + 1,
                                          next.points.end());
                }
                if (direction == 1) turn(current);
            }
        }
        out.push_back(std::move(current));
    }
    return out;
}

double pen_up_travel(std::span<const PlotPath> paths, Point2 home) {
    double travel = 0.0;
    Point2 at = home;
    for (const PlotPath& p : paths) {
        travel += distance(at, p.start());
        at = p.end();
    }
    return travel;
}

std::vector<PlotPath> order_paths(std::vector<PlotPath> paths, Point2 home) {
    const std::size_t n = paths.size();
    if (n < 2) return paths;
    // Greedy nearest neighbour: from where the pen is, the nearest unused end; entered at its
    // end, a path is turned.
    const EndGrid grid(paths);
    std::vector<char> used(n, 0);
    std::vector<std::uint32_t> order;
    std::vector<char> turned;
    order.reserve(n);
    Point2 at = home;
    for (std::size_t k = 0; k < n; ++k) {
        const std::uint32_t e = grid.nearest(at, paths, [&](std::uint32_t p) { return !used[p]; });
        const std::uint32_t p = e / 2;
        used[p] = 1;
        order.push_back(p);
        turned.push_back(e % 2 == 1);
        at = e % 2 ? paths[p].start() : paths[p].end();
    }
    // 2-opt: the edge from position lo to lo + 1 and the one from hi to hi + 1 (lo = -1: from
    // home; hi = n - 1: none after) become lo -> hi and lo + 1 -> hi + 1 by turning the run
    // lo + 1 .. hi around. Candidates: the paths near each end.
    auto start_of = [&](std::size_t k) {
        return turned[k] ? paths[order[k]].end() : paths[order[k]].start();
    };
    auto end_of = [&](std::ptrdiff_t k) {
        if (k < 0) return home;
        const auto u = static_cast<std::size_t>(k);
        return turned[u] ? paths[order[u]].start() : paths[order[u]].end();
    };
    // The nearest paths to each path's ends.
    constexpr int kNeighbours = 8;
    std::vector<std::array<std::uint32_t, 2 * kNeighbours>> near(n);
    for (std::uint32_t p = 0; p < n; ++p) {
        std::vector<std::uint32_t> found;
        for (Point2 q : {paths[p].start(), paths[p].end()})
            for (int k = 0; k < kNeighbours; ++k) {
                const std::uint32_t e = grid.nearest(q, paths, [&](std::uint32_t c) {
                    return c != p && std::find(found.begin(), found.end(), c) == found.end();
                });
                if (e == kNoIndex) break;
                found.push_back(e / 2);
            }
        near[p].fill(kNoIndex);
        std::copy_n(found.begin(), std::min<std::size_t>(found.size(), near[p].size()),
                    near[p].begin());
    }
    std::vector<std::size_t> position(n);
    for (std::size_t k = 0; k < n; ++k) position[order[k]] = k;
    const auto last = static_cast<std::ptrdiff_t>(n) - 1;
    auto gain = [&](std::ptrdiff_t lo, std::ptrdiff_t hi) {
        const Point2 a = end_of(lo), b = start_of(static_cast<std::size_t>(lo + 1)), c = end_of(hi);
        double before = distance(a, b), after = distance(a, c);
        if (hi < last) {
            const Point2 d = start_of(static_cast<std::size_t>(hi + 1));
            before += distance(c, d);
            after += distance(b, d);
        }
        return before - after;
    };
    for (int pass = 0; pass < 100; ++pass) {
        bool improved = false;
        for (std::ptrdiff_t k = -1; k < last; ++k) {
            const std::uint32_t around =
                order[static_cast<std::size_t>(std::max<std::ptrdiff_t>(k, 0))];
            for (std::uint32_t q : near[around]) {
                if (q == kNoIndex) break;
                const auto m = static_cast<std::ptrdiff_t>(position[q]);
                for (std::ptrdiff_t other : {m, m - 1}) {
                    const std::ptrdiff_t lo = std::min(k, other), hi = std::max(k, other);
                    if (lo < -1 || hi <= lo || hi > last) continue;
                    if (gain(lo, hi) <= 1e-6) continue;
                    const auto first = static_cast<std::size_t>(lo + 1),
                               end = static_cast<std::size_t>(hi + 1);
                    std::reverse(order.begin() + static_cast<std::ptrdiff_t>(first),
                                 order.begin() + static_cast<std::ptrdiff_t>(end));
                    std::reverse(turned.begin() + static_cast<std::ptrdiff_t>(first),
                                 turned.begin() + static_cast<std::ptrdiff_t>(end));
                    for (std::size_t i = first; i < end; ++i) {
                        turned[i] = !turned[i];
                        position[order[i]] = i;
                    }
                    improved = true;
                }
            }
        }
        if (!improved) break;
    }
    std::vector<PlotPath> out;
    out.reserve(n);
    for (std::size_t k = 0; k < n; ++k) {
        out.push_back(std::move(paths[order[k]]));
        if (turned[k]) turn(out.back());
    }
    return out;
}

namespace {

struct Layer {
    std::string colour, width;
    bool hidden = false;
    float pen_width = 0.0f;
    std::vector<PlotPath> paths;
};

}  // namespace

std::string plotter_svg_text(std::span<const Stroke> strokes, const SvgSettings& settings) {
    std::vector<Layer> layers;
    auto layer_of = [&](const Vec3f& colour, float width, bool hidden) -> Layer& {
        const std::string c = svg_colour(colour), w = svg_coordinate(width);
        for (Layer& l : layers)
            if (l.colour == c && l.width == w && l.hidden == hidden) return l;
        layers.push_back({c, w, hidden, width, {}});
        return layers.back();
    };
    for (std::size_t i = 0; i < strokes.size(); ++i) {
        const Stroke& s = strokes[i];
        if (s.points.size() < 2 || (!s.visible && !settings.hidden)) continue;
        const StrokePen* pen =
            settings.pens.empty() ? nullptr : &pen_of_stroke(settings.pens, s, i);
        if (s.visible && pen && !pen->draw) continue;
        const bool own = pen && pen->draw;
        const Vec3f colour =
            own ? pen->colour : (s.visible ? settings.colour : settings.hidden_colour);
        const float width =
            own ? pen->width
                : (s.visible ? settings.thickness
                             : settings.thickness * settings.hidden_thickness_scale);
        Layer& layer = layer_of(colour, width, !s.visible);
        if (s.type == EdgeType::Tone && s.points[0] == s.points[1] && s.points.size() == 2) {
            // A dot: rings a pen width apart from its edge inward; smaller than the pen, a touch.
            const float r = 0.5f * width * s.scale;
            if (r <= 0.5f * width) {
                layer.paths.push_back({{s.points[0], s.points[0]}, 0.0f});
                continue;
            }
            for (float ring = r - 0.5f * width; ring > 0.0f; ring -= width)
                layer.paths.push_back({{s.points[0]}, ring});
            continue;
        }
        layer.paths.push_back({s.points, 0.0f});
    }
    std::string out;
    auto it = std::back_inserter(out);
    fmt::format_to(it, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    fmt::format_to(it,
                   "<svg xmlns=\"http://www.w3.org/2000/svg\" "
                   "xmlns:inkscape=\"http://www.inkscape.org/namespaces/inkscape\" version=\"1.1\" "
                   "width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\">\n",
                   settings.width, settings.height);
    if (!settings.metadata.empty() || !settings.software.empty())
        fmt::format_to(it, "<metadata id=\"toonray\" data-software=\"{}\">{}</metadata>\n",
                       xml_escaped(settings.software), xml_escaped(settings.metadata));
    // Hidden pens after the visible ones, each in first-use order.
    std::stable_partition(layers.begin(), layers.end(), [](const Layer& l) { return !l.hidden; });
    int number_of = 0;
    for (Layer& layer : layers) {
        ++number_of;
        const std::vector<PlotPath> paths =
            order_paths(merge_touching(std::move(layer.paths)), {0.0f, 0.0f});
        fmt::format_to(it,
                       "<g id=\"pen-{0}\" inkscape:groupmode=\"layer\" inkscape:label=\"{0} {1}{2} "
                       "{3}px\" fill=\"none\" stroke=\"{2}\" stroke-width=\"{3}\" "
                       "stroke-linecap=\"round\" stroke-linejoin=\"round\">\n",
                       number_of, layer.hidden ? "hidden " : "", layer.colour, layer.width);
        for (const PlotPath& p : paths) {
            if (p.radius > 0.0f) {
                fmt::format_to(it, "<circle cx=\"{}\" cy=\"{}\" r=\"{}\"/>\n",
                               svg_coordinate(p.points[0].x), svg_coordinate(p.points[0].y),
                               svg_coordinate(p.radius));
                continue;
            }
            out += "<path d=\"M";
            for (std::size_t i = 0; i < p.points.size(); ++i)
                fmt::format_to(it, "{}{} {}", i == 1 ? " L " : " ", svg_coordinate(p.points[i].x),
                               svg_coordinate(p.points[i].y));
            if (p.points.size() == 1)
                fmt::format_to(it, " L {} {}", svg_coordinate(p.points[0].x),
                               svg_coordinate(p.points[0].y));
            out += "\"/>\n";
        }
        out += "</g>\n";
    }
    out += "</svg>\n";
    return out;
}

}  // namespace toonray::ink
