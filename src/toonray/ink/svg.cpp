#include "toonray/ink/svg.h"

#include "toonray/ink/plotter.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iterator>
#include <type_traits>
#include <variant>
#include <vector>

namespace toonray::ink {

std::string svg_colour(const Vec3f& c) {
    auto byte = [](float v) {
        return static_cast<int>(std::min(std::max(v, 0.0f), 1.0f) * 255.0f + 0.5f);
    };
    return fmt::format("#{:02x}{:02x}{:02x}", byte(c.x), byte(c.y), byte(c.z));
}

// "-0.000" and "0.000" are the same coordinate; print one.
std::string svg_coordinate(float v) {
    std::string s = fmt::format("{:.3f}", v);
    if (s == "-0.000") s = "0.000";
    return s;
}

namespace {

// An attribute's value as SVG writes it: colours #rrggbb, lengths and fractions with three
// decimals, dash lists comma-separated or `none` (SVG's initial value).
std::string svg_value(const StyleAttribute& a, const LineStyle& style) {
    return std::visit(
        [&](auto field) -> std::string {
            using Value = std::remove_cvref_t<decltype(style.*field)>;
            const Value& v = style.*field;
            if constexpr (std::is_same_v<Value, Vec3f>) {
                return svg_colour(v);
            } else if constexpr (std::is_same_v<Value, float>) {
                return svg_coordinate(v);
            } else if constexpr (std::is_same_v<Value, bool>) {
                return v ? "yes" : "no";
            } else if constexpr (std::is_same_v<Value, std::string>) {
                return v;
            } else {
                if (v.empty()) return "none";
                std::string out;
                for (std::size_t i = 0; i < v.size(); ++i)
                    out += (i ? "," : "") + svg_coordinate(v[i]);
                return out;
            }
        },
        a.field);
}

// The attributes of a stroked path whose pen differs from its group's (`group`: the group's
// colour and width, the other attributes at their defaults).
std::string stroke_attributes(const StrokePen& pen, const LineStyle& group) {
    std::string out;
    for (const StyleAttribute& a : style_attributes()) {
        if (a.svg != SvgMapping::PathAttribute || a.svg_stroke.empty()) continue;
        const std::string value = svg_value(a, pen);
        if (value != svg_value(a, group)) out += fmt::format(" {}=\"{}\"", a.svg_stroke, value);
    }
    return out;
}

// The attributes of a filled outline: no stroke, and the fill attributes of the pen. The
// group's fill is none, so the paint is always written; the others where they differ from the
// group's.
std::string outline_attributes(const StrokePen& pen, const LineStyle& group) {
    std::string out = " stroke=\"none\"";
    for (const StyleAttribute& a : style_attributes()) {
        if (a.svg != SvgMapping::PathAttribute || a.svg_fill.empty()) continue;
        const std::string value = svg_value(a, pen);
        if (a.kind == StyleValueKind::Colour || value != svg_value(a, group))
            out += fmt::format(" {}=\"{}\"", a.svg_fill, value);
    }
    return out;
}

Point2 operator+(Point2 a, Point2 b) { return {a.x + b.x, a.y + b.y}; }
Point2 operator*(Point2 a, float s) { return {a.x * s, a.y * s}; }

// Path data of filled shapes, all traced the same way round (counter-clockwise on the image,
// y down), so that under the nonzero fill rule their union is filled once, however they
// overlap.
class OutlineData {
public:
    explicit OutlineData(std::string& d) : d_(d) {}

    // The points p(t) + n r(t) for t along `ts`, then p(t) - n r(t) back: the band of a
    // segment between two perpendiculars, whose half-width is r.
    void band(Point2 a, Point2 dir, Point2 n, float length, std::span<const float> ts,
              std::span<const float> radii) {
        for (std::size_t i = 0; i < ts.size(); ++i)
            point(i == 0 ? 'M' : 'L', a + dir * (ts[i] * length) + n * radii[i]);
        for (std::size_t i = ts.size(); i-- > 0;)
            point('L', a + dir * (ts[i] * length) + n * -radii[i]);
        d_ += " Z";
    }

    // The half disc of radius r at c on the side `out` points to (n: a unit normal to out),
    // from c + n r round to c - n r.
    void half_disc(Point2 c, Point2 out, Point2 n, float r) {
        point('M', c + n * r);
        arc(r, c + out * r);
        arc(r, c + n * -r);
        d_ += " Z";
    }

    void disc(Point2 c, float r) {
        point('M', c + Point2{r, 0.0f});
        arc(r, c + Point2{0.0f, -r});
        arc(r, c + Point2{-r, 0.0f});
        arc(r, c + Point2{0.0f, r});
        arc(r, c + Point2{r, 0.0f});
        d_ += " Z";
    }

private:
    void point(char command, Point2 p) {
        fmt::format_to(std::back_inserter(d_), "{}{} {} {}", d_.empty() ? "" : " ", command,
                       svg_coordinate(p.x), svg_coordinate(p.y));
    }
    // A quarter circle, counter-clockwise on the image (sweep flag 0, y down).
    void arc(float r, Point2 to) {
        fmt::format_to(std::back_inserter(d_), " A {} {} 0 0 0 {} {}", svg_coordinate(r),
                       svg_coordinate(r), svg_coordinate(to.x), svg_coordinate(to.y));
    }
    std::string& d_;
};

// Radii closer than this (pixels) to linear between two points of a band need no point
// between them.
constexpr float kOutlineTolerance = 0.01f;
// A dash pattern shorter than this (pixels) is finer than the pixels that show it: its
// outline is left whole rather than cut into thousands of slivers.
constexpr float kMinOutlineDashPeriod = 0.5f;

// The outline of a stroke whose width varies: the region the drawing (draw.h) covers by more
// than half, traced as filled shapes. For each segment the drawing takes the thickness at the
// nearest centreline point, so the region is, per segment, the band between the
// perpendiculars at its ends with half-width r(t) (the pen's half-width times the taper and
// depth factors at that point), restricted to "on" dashes, plus the half discs beyond its ends
// of radius r there when those are "on" (round caps and joins). The band is cut where r
// changes slope (the taper's ends and middle) and where dashes start and end, and in between
// points are added until r is within kOutlineTolerance of linear (width by depth).
std::string outline_data(const Stroke& s, const StrokePen& pen) {
    std::string d;
    OutlineData out(d);
    const float total = polyline_length(s.points);
    const float stroke_length = s.closed ? -1.0f : total;
    const bool by_depth = scales_by_depth(pen, s);
    const float half = pen.width * 0.5f;
    float period = 0.0f;
    for (float v : pen.dash) period += v;
    const bool dashed = !pen.dash.empty() && period >= kMinOutlineDashPeriod;
    // Where the radius is not linear between cuts: by depth, a brush, a pressure profile with a
    // taper (a product of linear functions).
    const bool curved =
        by_depth || pen.brush_image != nullptr || (!pen.pressure.empty() && pen.taper > 0.0f);
    float arc = 0.0f;
    std::vector<float> cuts, ts, radii;
    for (std::size_t i = 0; i + 1 < s.points.size(); ++i) {
        const Point2 a = s.points[i], b = s.points[i + 1];
        const float length = polyline_length(std::span<const Point2>(&s.points[i], 2));
        const float arc0 = arc;
        arc += length;
        const float d0 = by_depth ? s.depth[i] : 0.0f, d1 = by_depth ? s.depth[i + 1] : 0.0f;
        const float nib = nib_scale(pen, b.x - a.x, b.y - a.y);
        auto radius = [&](float t) {
            const float at = arc0 + t * length;
            float f = taper_scale(pen, at, stroke_length) * pressure_scale(pen, at, total) * nib;
            if (d0 > 0.0f) f *= depth_scale(pen, d0 + (d1 - d0) * t);
            // A brush: the width of the same ink.
            if (pen.brush_image) f *= brush_width(*pen.brush_image, brush_along(pen, at, total));
            return half * f;
        };
        auto on = [&](float t) { return !dashed || in_dash(pen.dash, arc0 + t * length); };
        if (!(length > 0.0f)) {
            if (on(0.0f) && radius(0.0f) > 0.0f) out.disc(a, radius(0.0f));
            continue;
        }
        const Point2 dir{(b.x - a.x) / length, (b.y - a.y) / length}, n{-dir.y, dir.x};
        cuts = {0.0f, 1.0f};
        auto cut_at = [&](float at_arc) {
            const float t = (at_arc - arc0) / length;
            if (t > 0.0f && t < 1.0f) cuts.push_back(t);
        };
        if (pen.taper > 0.0f && stroke_length >= 0.0f)
            for (float at : {pen.taper, stroke_length - pen.taper, stroke_length * 0.5f})
                cut_at(at);
        // The pressure profile's points.
        for (std::size_t k = 1; k + 1 < pen.pressure.size(); ++k)
            cut_at(total * static_cast<float>(k) / static_cast<float>(pen.pressure.size() - 1));
        if (dashed)  // each period's start and the ends of its dashes (counted, not summed)
            for (double k = std::floor(arc0 / period); k * period <= arc; ++k) {
                double at = k * period;
                cut_at(static_cast<float>(at));
                for (float v : pen.dash) cut_at(static_cast<float>(at += v));
            }
        std::sort(cuts.begin(), cuts.end());
        cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
        // Runs of "on" pieces between cuts, each one band.
        std::function<void(float, float, float, float, int)> refine =
            [&](float t0, float r0, float t1, float r1, int depth) {
                const float tm = 0.5f * (t0 + t1), rm = radius(tm);
                if (depth == 0 || std::abs(rm - 0.5f * (r0 + r1)) <= kOutlineTolerance) return;
                refine(t0, r0, tm, rm, depth - 1);
                ts.push_back(tm);
                radii.push_back(rm);
                refine(tm, rm, t1, r1, depth - 1);
            };
        for (std::size_t k = 0; k + 1 < cuts.size();) {
            if (!on(0.5f * (cuts[k] + cuts[k + 1]))) {
                ++k;
                continue;
            }
            ts = {cuts[k]};
            radii = {radius(cuts[k])};
            for (; k + 1 < cuts.size() && on(0.5f * (cuts[k] + cuts[k + 1])); ++k) {
                const float r1 = radius(cuts[k + 1]);
                refine(cuts[k], radii.back(), cuts[k + 1], r1, curved ? 8 : 0);
                ts.push_back(cuts[k + 1]);
                radii.push_back(r1);
            }
            if (*std::max_element(radii.begin(), radii.end()) > 0.0f)
                out.band(a, dir, n, length, ts, radii);
        }
        if (on(0.0f) && radius(0.0f) > 0.0f) out.half_disc(a, dir * -1.0f, n * -1.0f, radius(0.0f));
        if (on(1.0f) && radius(1.0f) > 0.0f) out.half_disc(b, dir, n, radius(1.0f));
    }
    return d;
}

// Polyline path data: "M x y L x y x y ...", closed strokes ending in Z.
void polyline_data(const Stroke& s, std::string& out) {
    auto it = std::back_inserter(out);
    out += "M";
    for (std::size_t i = 0; i < s.points.size(); ++i) {
        if (s.closed && i + 1 == s.points.size()) {
            out += " Z";
            break;
        }
        fmt::format_to(it, "{}{} {}", i == 1 ? " L " : " ", svg_coordinate(s.points[i].x),
                       svg_coordinate(s.points[i].y));
    }
}

}  // namespace

std::string png_data_uri(std::span<const std::uint8_t> png) {
    static constexpr char kDigits[] =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out = "data:image/png;base64,";
    out.reserve(out.size() + (png.size() + 2) / 3 * 4);
    for (std::size_t i = 0; i < png.size(); i += 3) {
        const std::size_t n = std::min<std::size_t>(3, png.size() - i);
        std::uint32_t v = static_cast<std::uint32_t>(png[i]) << 16;
        if (n > 1) v |= static_cast<std::uint32_t>(png[i + 1]) << 8;
        if (n > 2) v |= png[i + 2];
        for (std::size_t k = 0; k < 4; ++k) out += k <= n ? kDigits[(v >> (18 - 6 * k)) & 63] : '=';
    }
    return out;
}

std::string xml_escaped(std::string_view text) {
    std::string out;
    out.reserve(text.size());
    for (const char c : text) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            default: out += c;
        }
    }
    return out;
}

std::string svg_text(std::span<const Stroke> strokes, const SvgSettings& settings) {
    if (settings.plotter) return plotter_svg_text(strokes, settings);
    // Every stroke's style must have a pen, also of strokes not written (hidden ones without
    // the hidden layer, dots): the same check as the drawing's, whatever the settings.
    if (!settings.pens.empty())
        for (std::size_t i = 0; i < strokes.size(); ++i)
            static_cast<void>(pen_of_stroke(settings.pens, strokes[i], i));
    std::string out;
    auto it = std::back_inserter(out);
    fmt::format_to(it, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    fmt::format_to(
        it,
        "<svg xmlns=\"http://www.w3.org/2000/svg\"{2} version=\"1.1\" width=\"{0}\" "
        "height=\"{1}\" viewBox=\"0 0 {0} {1}\">\n",
        settings.width, settings.height,
        settings.fill_href.empty() ? "" : " xmlns:xlink=\"http://www.w3.org/1999/xlink\"");
    if (!settings.metadata.empty() || !settings.software.empty())
        fmt::format_to(it, "<metadata id=\"toonray\" data-software=\"{}\">{}</metadata>\n",
                       xml_escaped(settings.software), xml_escaped(settings.metadata));
    if (!settings.fill_href.empty())
        fmt::format_to(it,
                       "<image id=\"fill\" x=\"0\" y=\"0\" width=\"{}\" height=\"{}\" "
                       "xlink:href=\"{}\"/>\n",
                       settings.width, settings.height, settings.fill_href);
    // One stroke as a path (or a filled outline), with what its pen sets beyond the group's.
    auto write_path = [&](const Stroke& s, const StrokePen* pen, const LineStyle& group) {
        if (pen && pen->draw && varies_width(*pen, s)) {
            // A stroke with nothing covered by more than half (a tapered dot) has no outline
            // to write.
            const std::string data = outline_data(s, *pen);
            if (!data.empty())
                out += "<path" + outline_attributes(*pen, group) + " d=\"" + data + "\"/>\n";
            return;
        }
        out += "<path";
        if (pen && pen->draw) {
            out += stroke_attributes(*pen, group);
            // The drawing ends dashes square (a pixel is covered from "on" centreline points
            // only); the group's round caps would lengthen each dash by the line's width.
            if (!pen->dash.empty()) out += " stroke-linecap=\"butt\"";
        }
        out += " d=\"";
        polyline_data(s, out);
        out += "\"/>\n";
    };
    auto group_start = [&](const char* name, const LineStyle& group) {
        fmt::format_to(
            it,
            "<g id=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{}\" stroke-linecap=\"round\" "
            "stroke-linejoin=\"round\">\n",
            name, svg_colour(group.colour), svg_coordinate(group.width));
    };
    // The tone first, under the lines: hatch strokes as paths, screentone dots as circles.
    const bool any_tone = std::any_of(strokes.begin(), strokes.end(),
                                      [](const Stroke& s) { return s.type == EdgeType::Tone; });
    if (any_tone) {
        LineStyle group;
        group.colour = settings.colour;
        group.width = settings.thickness;
        group_start("tone", group);
        for (std::size_t index = 0; index < strokes.size(); ++index) {
            const Stroke& s = strokes[index];
            if (s.type != EdgeType::Tone || !s.visible || s.points.size() < 2) continue;
            const StrokePen* pen =
                settings.pens.empty() ? nullptr : &pen_of_stroke(settings.pens, s, index);
            if (pen && !pen->draw) continue;
            if (s.points.size() == 2 && s.points[0] == s.points[1]) {
                const float width = pen ? pen->width : settings.thickness;
                const Vec3f colour = pen ? pen->colour : settings.colour;
                fmt::format_to(it,
                               "<circle cx=\"{}\" cy=\"{}\" r=\"{}\" fill=\"{}\" stroke=\"none\"",
                               svg_coordinate(s.points[0].x), svg_coordinate(s.points[0].y),
                               svg_coordinate(0.5f * width * s.scale), svg_colour(colour));
                if (pen && pen->opacity != 1.0f)
                    fmt::format_to(it, " fill-opacity=\"{}\"", svg_coordinate(pen->opacity));
                out += "/>\n";
                continue;
            }
            write_path(s, pen, group);
        }
        out += "</g>\n";
    }
    for (int layer = 0; layer < (settings.hidden ? 2 : 1); ++layer) {
        const bool visible = layer == 0;
        const char* name = visible ? "visible" : "hidden";
        const float width =
            visible ? settings.thickness : settings.thickness * settings.hidden_thickness_scale;
        const Vec3f colour = visible ? settings.colour : settings.hidden_colour;
        LineStyle group;  // what the group's attributes say, the rest SVG's initial values
        group.colour = colour;
        group.width = width;
        group_start(name, group);
        for (int t = 0; t < kEdgeTypeCount; ++t) {
            const auto type = static_cast<EdgeType>(t);
            if (type == EdgeType::Tone) continue;  // in its own group above
            fmt::format_to(it, "<g id=\"{}-{}\">\n", name, edge_type_name(type));
            for (std::size_t index = 0; index < strokes.size(); ++index) {
                const Stroke& s = strokes[index];
                if (s.visible != visible || s.type != type || s.points.size() < 2) continue;
                const StrokePen* pen =
                    settings.pens.empty() ? nullptr : &pen_of_stroke(settings.pens, s, index);
                if (pen && !pen->draw && visible) continue;  // this line set is off
                write_path(s, pen, group);
            }
            out += "</g>\n";
        }
        out += "</g>\n";
    }
    out += "</svg>\n";
    return out;
}

}  // namespace toonray::ink
