#include "toonray/ink/svg.h"

#include <fmt/format.h>

#include <algorithm>
#include <iterator>


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

// The attributes in which a path's pen differs from its group's stroke colour and width.
std::string pen_attributes(const StrokePen& pen, const Vec3f& colour, float width) {
    std::string out;
    auto it = std::back_inserter(out);
    if (hex_colour(pen.colour) != hex_colour(colour))
        fmt::format_to(it, " stroke=\"{}\"", hex_colour(pen.colour));
    if (coordinate(pen.thickness) != coordinate(width))
        fmt::format_to(it, " stroke-width=\"{}\"", coordinate(pen.thickness));
    if (pen.opacity != 1.0f) fmt::format_to(it, " stroke-opacity=\"{}\"", coordinate(pen.opacity));
    if (!pen.dash.empty()) {
        out += " stroke-dasharray=\"";
        for (std::size_t i = 0; i < pen.dash.size(); ++i)
            fmt::format_to(it, "{}{}", i ? "," : "", coordinate(pen.dash[i]));
        out += "\"";
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
        fmt::format_to(
            it,
            "<g id=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{}\" stroke-linecap=\"round\" "
            "stroke-linejoin=\"round\">\n",
            name, hex_colour(colour), coordinate(width));
        for (int t = 0; t < kEdgeTypeCount; ++t) {
            const auto type = static_cast<EdgeType>(t);
            fmt::format_to(it, "<g id=\"{}-{}\">\n", name, edge_type_name(type));
            for (const Stroke& s : strokes) {
                if (s.visible != visible || s.type != type || s.points.size() < 2) continue;
                const StrokePen* pen =
                    s.style < settings.pens.size() ? &settings.pens[s.style] : nullptr;
                if (pen && !pen->draw && visible) continue;  // this line set is off
                const std::string attributes =
                    pen && pen->draw ? pen_attributes(*pen, colour, width) : std::string();
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
