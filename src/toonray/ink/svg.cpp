#include "toonray/ink/svg.h"

#include <fmt/format.h>

#include <algorithm>
#include <iterator>
#include <type_traits>
#include <variant>

namespace toonray::ink {

namespace {

std::string hex_colour(const Vec3f& c) {
    auto byte = [](float v) {
        return static_cast<int>(std::min(std::max(v, 0.0f), 1.0f) * 255.0f + 0.5f);
    };
    return fmt::format("#{:02x}{:02x}{:02x}", byte(c.x), byte(c.y), byte(c.z));
}

// "-0.000" and "0.000" are the same coordinate; print one.
std::string coordinate(float v) {
    std::string s = fmt::format("{:.3f}", v);
    if (s == "-0.000") s = "0.000";
    return s;
}

// An attribute's value as SVG writes it: colours #rrggbb, lengths and fractions with three
// decimals, dash lists comma-separated or `none` (SVG's initial value).
std::string svg_value(const StyleAttribute& a, const LineStyle& style) {
    return std::visit(
        [&](auto field) -> std::string {
            using Value = std::remove_cvref_t<decltype(style.*field)>;
            const Value& v = style.*field;
            if constexpr (std::is_same_v<Value, Vec3f>) {
                return hex_colour(v);
            } else if constexpr (std::is_same_v<Value, float>) {
                return coordinate(v);
            } else if constexpr (std::is_same_v<Value, bool>) {
                return v ? "yes" : "no";
            } else {
                if (v.empty()) return "none";
                std::string out;
                for (std::size_t i = 0; i < v.size(); ++i) out += (i ? "," : "") + coordinate(v[i]);
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

std::string svg_text(std::span<const Stroke> strokes, const SvgSettings& settings) {
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
    if (!settings.fill_href.empty())
        fmt::format_to(it,
                       "<image id=\"fill\" x=\"0\" y=\"0\" width=\"{}\" height=\"{}\" "
                       "xlink:href=\"{}\"/>\n",
                       settings.width, settings.height, settings.fill_href);
    for (int layer = 0; layer < (settings.hidden ? 2 : 1); ++layer) {
        const bool visible = layer == 0;
        const char* name = visible ? "visible" : "hidden";
        const float width =
            visible ? settings.thickness : settings.thickness * settings.hidden_thickness_scale;
        const Vec3f colour = visible ? settings.colour : settings.hidden_colour;
        LineStyle group;  // what the group's attributes say, the rest SVG's initial values
        group.colour = colour;
        group.width = width;
        fmt::format_to(
            it,
            "<g id=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{}\" stroke-linecap=\"round\" "
            "stroke-linejoin=\"round\">\n",
            name, hex_colour(colour), coordinate(width));
        for (int t = 0; t < kEdgeTypeCount; ++t) {
            const auto type = static_cast<EdgeType>(t);
            fmt::format_to(it, "<g id=\"{}-{}\">\n", name, edge_type_name(type));
            for (std::size_t index = 0; index < strokes.size(); ++index) {
                const Stroke& s = strokes[index];
                if (s.visible != visible || s.type != type || s.points.size() < 2) continue;
                const StrokePen* pen =
                    settings.pens.empty() ? nullptr : &pen_of_stroke(settings.pens, s, index);
                if (pen && !pen->draw && visible) continue;  // this line set is off
                const std::string attributes =
                    pen && pen->draw ? stroke_attributes(*pen, group) : std::string();
                out += "<path";
                out += attributes;
                out += " d=\"M";
                for (std::size_t i = 0; i < s.points.size(); ++i) {
                    if (s.closed && i + 1 == s.points.size()) {
                        out += " Z";
                        break;
                    }
                    fmt::format_to(it, "{}{} {}", i == 1 ? " L " : " ", coordinate(s.points[i].x),
                                   coordinate(s.points[i].y));
                }
                out += "\"/>\n";
            }
            out += "</g>\n";
        }
        out += "</g>\n";
    }
    out += "</svg>\n";
    return out;
}

}  // namespace toonray::ink
