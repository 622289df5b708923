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

}  // namespace

std::string svg_text(std::span<const Stroke> strokes, const SvgSettings& settings) {
    std::string out;
    auto it = std::back_inserter(out);
    fmt::format_to(it, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    fmt::format_to(
        it,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"{0}\" height=\"{1}\" "
        "viewBox=\"0 0 {0} {1}\">\n",
        settings.width, settings.height);
    for (int layer = 0; layer < (settings.hidden ? 2 : 1); ++layer) {
        const bool visible = layer == 0;
        const char* name = visible ? "visible" : "hidden";
        const float width =
            visible ? settings.thickness : settings.thickness * settings.hidden_thickness_scale;
        fmt::format_to(
            it,
            "<g id=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"{}\" stroke-linecap=\"round\" "
            "stroke-linejoin=\"round\">\n",
            name, hex_colour(visible ? settings.colour : settings.hidden_colour),
            coordinate(width));
        for (int t = 0; t < kEdgeTypeCount; ++t) {
            const auto type = static_cast<EdgeType>(t);
            fmt::format_to(it, "<g id=\"{}-{}\">\n", name, edge_type_name(type));
            for (const Stroke& s : strokes) {
                if (s.visible != visible || s.type != type || s.points.size() < 2) continue;
                out += "<path d=\"M";
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
