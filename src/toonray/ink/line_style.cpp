#include "toonray/ink/line_style.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>

#include "toonray/core/error.h"
#include "toonray/core/parse.h"

namespace toonray::ink {

namespace {

/// A dash pattern longer than this is a mistake, not a style.
constexpr std::size_t kMaxDashes = 16;

std::vector<std::string_view> split(std::string_view text, char separator) {
    std::vector<std::string_view> parts;
    for (;;) {
        const std::size_t at = text.find(separator);
        parts.push_back(text.substr(0, at));
        if (at == std::string_view::npos) return parts;
        text.remove_prefix(at + 1);
    }
}

struct LineContext {
    std::string_view source;
    int line;
    [[noreturn]] void fail(const std::string& what) const {
        throw Error(fmt::format("{}:{}: {}", source, line, what));
    }
};

float parse_number(std::string_view text, std::string_view key, const LineContext& at) {
    float value = 0.0f;
    const auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (text.empty() || ec != std::errc() || p != text.data() + text.size() ||
        !std::isfinite(value))
        at.fail(fmt::format("{}: expected a number, got '{}'", key, text));
    return value;
}

bool parse_yes_no(std::string_view text, std::string_view key, const LineContext& at) {
    if (text == "yes") return true;
    if (text == "no") return false;
    at.fail(fmt::format("{}: expected yes or no, got '{}'", key, text));
}

unsigned parse_types(std::string_view text, const LineContext& at) {
    if (text == "all") return (1u << kEdgeTypeCount) - 1;
    unsigned types = 0;
    for (std::string_view name : split(text, ',')) {
        int found = -1;
        for (int t = 0; t < kEdgeTypeCount; ++t)
            if (name == edge_type_name(static_cast<EdgeType>(t))) found = t;
        if (found < 0)
            at.fail(
                fmt::format("type: unknown line type '{}' (silhouette, border, crease, "
                            "material, intersection, polyline or all)",
                            name));
        types |= 1u << found;
    }
    return types;
}

std::vector<float> parse_dash(std::string_view text, const LineContext& at) {
    if (text == "none") return {};
    std::vector<float> dash;
    float total = 0.0f;
    for (std::string_view part : split(text, ',')) {
        const float v = parse_number(part, "dash", at);
        if (v < 0.0f || v > 1e4f)
            at.fail(fmt::format("dash: lengths must be in [0, 10000], got '{}'", part));
        dash.push_back(v);
        total += v;
    }
    if (dash.size() > kMaxDashes)
        at.fail(fmt::format("dash: at most {} lengths, got {}", kMaxDashes, dash.size()));
    if (dash.size() % 2 != 0) dash.insert(dash.end(), dash.begin(), dash.end());  // as SVG does
    if (!(total > 0.0f)) at.fail("dash: the lengths must not all be 0");
    return dash;
}

std::vector<std::string> parse_globs(std::string_view text, std::string_view key,
                                     const LineContext& at) {
    std::vector<std::string> globs;
    for (std::string_view g : split(text, ',')) {
        if (g.empty()) at.fail(fmt::format("{}: empty name pattern in '{}'", key, text));
        globs.emplace_back(g);
    }
    return globs;
}

// '#' starts a comment at the start of a line or after a blank, so colours (#808080) are not
// comments.
std::size_t comment_start(std::string_view row) {
    for (std::size_t i = 0; i < row.size(); ++i)
        if (row[i] == '#' && (i == 0 || row[i - 1] == ' ' || row[i - 1] == '\t')) return i;
    return row.size();
}

bool any_glob(const std::vector<std::string>& globs, std::string_view name) {
    for (const std::string& g : globs)
        if (glob_match(g, name)) return true;
    return false;
}

LineStyleRule parse_rule(std::string_view body, const LineContext& at) {
    LineStyleRule rule;
    rule.line = at.line;
    bool first = true;
    std::vector<std::string_view> seen;
    while (!body.empty()) {
        const std::size_t start = body.find_first_not_of(" \t\r");
        if (start == std::string_view::npos) break;
        body.remove_prefix(start);
        const std::size_t end = std::min(body.find_first_of(" \t\r"), body.size());
        const std::string_view word = body.substr(0, end);
        body.remove_prefix(end);
        if (first) {
            if (word != "match") at.fail(fmt::format("expected 'match', got '{}'", word));
            first = false;
            continue;
        }
        const std::size_t eq = word.find('=');
        if (eq == std::string_view::npos)
            at.fail(fmt::format("expected key=value, got '{}'", word));
        const std::string_view key = word.substr(0, eq), value = word.substr(eq + 1);
        for (std::string_view s : seen)
            if (s == key) at.fail(fmt::format("'{}' given twice", key));
        seen.push_back(key);
        if (key == "object") {
            rule.objects = parse_globs(value, key, at);
        } else if (key == "material") {
            rule.materials = parse_globs(value, key, at);
        } else if (key == "type") {
            rule.types = parse_types(value, at);
        } else if (key == "lines") {
            if (value != "visible" && value != "hidden" && value != "all")
                at.fail(fmt::format("lines: expected visible, hidden or all, got '{}'", value));
            rule.match_visible = value != "hidden";
            rule.match_hidden = value != "visible";
        } else if (key == "draw") {
            rule.draw = parse_yes_no(value, key, at);
        } else if (key == "width_by_depth") {
            rule.by_depth = parse_yes_no(value, key, at);
        } else if (key == "color" || key == "colour") {
            try {
                rule.colour = parse_colour(value, key);
            } catch (const Error& e) {
                at.fail(e.what());
            }
        } else if (key == "width") {
            const float w = parse_number(value, key, at);
            if (w < 0.0f || w > 1000.0f)
                at.fail(fmt::format("width: expected pixels in [0, 1000], got '{}'", value));
            rule.width = w;
        } else if (key == "taper") {
            const float t = parse_number(value, key, at);
            if (t < 0.0f || t > 1e4f)
                at.fail(fmt::format("taper: expected pixels in [0, 10000], got '{}'", value));
            rule.taper = t;
        } else if (key == "opacity") {
            const float o = parse_number(value, key, at);
            if (o < 0.0f || o > 1.0f)
                at.fail(fmt::format("opacity: expected a value in [0, 1], got '{}'", value));
            rule.opacity = o;
        } else if (key == "dash") {
            rule.dash = parse_dash(value, at);
        } else {
            at.fail(
                fmt::format("unknown key '{}' (object, material, type, lines, draw, color, "
                            "width, opacity, dash, taper, width_by_depth)",
                            key));
        }
    }
    return rule;
}

}  // namespace

bool glob_match(std::string_view pattern, std::string_view name) {
    // Iterative match with one backtrack point: linear in practice, never exponential.
    std::size_t p = 0, n = 0, star = std::string_view::npos, resume = 0;
    while (n < name.size()) {
        if (p < pattern.size() && (pattern[p] == '?' || pattern[p] == name[n])) {
            ++p;
            ++n;
        } else if (p < pattern.size() && pattern[p] == '*') {
            star = p++;
            resume = n;
        } else if (star != std::string_view::npos) {
            p = star + 1;
            n = ++resume;
        } else {
            return false;
        }
    }
    while (p < pattern.size() && pattern[p] == '*') ++p;
    return p == pattern.size();
}

LineStyleSet parse_line_styles(std::string_view text, std::string_view source) {
    LineStyleSet set;
    int line = 0;
    for (std::string_view row : split(text, '\n')) {
        ++line;
        const LineContext at{source, line};
        if (row.find('\0') != std::string_view::npos) at.fail("NUL byte in the line");
        row = row.substr(0, comment_start(row));
        if (row.find_first_not_of(" \t\r") == std::string_view::npos) continue;
        set.rules.push_back(parse_rule(row, at));
    }
    return set;
}

LineStyle resolve_line_style(const LineStyleSet& set, const LineStyle& base,
                             std::string_view object, std::string_view material, EdgeType type,
                             bool visible) {
    LineStyle style = base;
    if (!visible) style.draw = false;
    for (const LineStyleRule& rule : set.rules) {
        if (!(visible ? rule.match_visible : rule.match_hidden)) continue;
        if ((rule.types & (1u << static_cast<unsigned>(type))) == 0) continue;
        if (!any_glob(rule.objects, object) || !any_glob(rule.materials, material)) continue;
        if (rule.draw) style.draw = *rule.draw;
        if (rule.colour) style.colour = *rule.colour;
        if (rule.width) style.width = *rule.width;
        if (rule.opacity) style.opacity = *rule.opacity;
        if (rule.dash) style.dash = *rule.dash;
        if (rule.taper) style.taper = *rule.taper;
        if (rule.by_depth) style.by_depth = *rule.by_depth;
    }
    return style;
}

}  // namespace toonray::ink
