#include "toonray/render/line_settings.h"

#include <fmt/format.h>

#include "toonray/core/error.h"

namespace toonray {
namespace {

constexpr std::pair<LineType, std::string_view> kTypeNames[] = {
    {kLineSilhouette, "silhouette"}, {kLineCrease, "crease"},     {kLineDepth, "depth"},
    {kLineObject, "object"},         {kLineMaterial, "material"}, {kLineBand, "band"},
    {kLineShadow, "shadow"},
};

}  // namespace

std::string_view line_mode_name(LineMode mode) {
    switch (mode) {
        case LineMode::Ink: return "ink";
        case LineMode::Robust: return "robust";
        case LineMode::Classic: return "classic";
    }
    return "ink";
}

LineMode parse_line_mode(std::string_view text, std::string_view what) {
    for (LineMode mode : {LineMode::Ink, LineMode::Robust, LineMode::Classic})
        if (text == line_mode_name(mode)) return mode;
    throw Error(fmt::format("{}: unknown line mode '{}' (ink, robust or classic)", what, text));
}

unsigned parse_line_types(const std::string& text) {
    if (text == "all") return kLineAll;
    if (text == "none") return 0;
    unsigned types = 0;
    std::string_view rest = text;
    for (;;) {
        const std::size_t comma = rest.find(',');
        const std::string_view item = rest.substr(0, comma);
        bool known = item == "all";
        if (known) types |= kLineAll;
        for (const auto& [type, name] : kTypeNames)
            if (item == name) {
                types |= type;
                known = true;
            }
        if (!known)
            throw Error(
                fmt::format("unknown line type '{}' (choose from silhouette, crease, depth, "
                            "object, material, band, shadow, all, none)",
                            item));
        if (comma == std::string_view::npos) return types;
        rest.remove_prefix(comma + 1);
    }
}

std::string format_line_types(unsigned types) {
    const bool all = (types & kLineAll) == kLineAll;
    std::string out = all ? "all" : "";
    for (const auto& [type, name] : kTypeNames) {
        if (!(types & type) || (all && (type & kLineAll))) continue;
        out += (out.empty() ? "" : ",") + std::string(name);
    }
    return out.empty() ? "none" : out;
}

void check_line_settings(const LineSettings& lines) {
    if (lines.mode != LineMode::Ink && (lines.types & (kLineBand | kLineShadow)))
        throw Error(fmt::format(
            "band and shadow lines are found on the geometry by the ink mode; the {} mode finds "
            "lines between pixels: use --edges ink (the default)",
            line_mode_name(lines.mode)));
    if (lines.mode == LineMode::Ink && (lines.types & kLineDepth) &&
        (lines.types & kLineAll) != kLineAll)
        throw Error(
            "the ink mode finds no depth lines (a step in depth between samples is a notion of "
            "the robust mode; the ink mode draws the geometry's silhouettes instead): ask for "
            "silhouette, or use --edges robust");
}

}  // namespace toonray
