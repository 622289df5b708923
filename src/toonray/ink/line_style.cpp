#include "toonray/ink/line_style.h"

#include <fmt/format.h>

#include <array>
#include <charconv>
#include <cmath>

#include "toonray/core/error.h"
#include "toonray/core/parse.h"
#include "toonray/ink/draw.h"

namespace toonray::ink {

namespace {

/// A dash pattern longer than this is a mistake, not a style.
constexpr std::size_t kMaxDashes = 16;

constexpr std::string_view kColourAliases[] = {"colour"};

// The table. Its order is LineStyle's, the order in which the SVG writes path attributes and
// the order of the keys in messages.
constexpr std::array kAttributes{
    StyleAttribute{"draw",
                   {},
                   StyleValueKind::YesNo,
                   &LineStyle::draw,
                   0.0f,
                   "whether the matched strokes are drawn (hidden lines start with no)",
                   SvgMapping::LeaveOut,
                   "",
                   ""},
    StyleAttribute{"color", kColourAliases, StyleValueKind::Colour, &LineStyle::colour, 0.0f,
                   "line colour", SvgMapping::PathAttribute, "stroke", "fill"},
    StyleAttribute{"width",
                   {},
                   StyleValueKind::Length,
                   &LineStyle::width,
                   1000.0f,
                   "line width, like --line-width",
                   SvgMapping::PathAttribute,
                   "stroke-width",
                   ""},
    StyleAttribute{"opacity",
                   {},
                   StyleValueKind::Fraction,
                   &LineStyle::opacity,
                   0.0f,
                   "how much the line hides what is under it",
                   SvgMapping::PathAttribute,
                   "stroke-opacity",
                   "fill-opacity"},
    StyleAttribute{"dash",
                   {},
                   StyleValueKind::Dash,
                   &LineStyle::dash,
                   1e4f,
                   "on,off,... lengths along the stroke from its first point (an odd list "
                   "repeats, as in SVG), or none",
                   SvgMapping::PathAttribute,
                   "stroke-dasharray",
                   ""},
    StyleAttribute{"taper",
                   {},
                   StyleValueKind::Length,
                   &LineStyle::taper,
                   1e4f,
                   "length over which an open stroke thins to nothing at each end; 0 = none",
                   SvgMapping::Outline,
                   "",
                   ""},
    StyleAttribute{"width_by_depth",
                   {},
                   StyleValueKind::YesNo,
                   &LineStyle::by_depth,
                   0.0f,
                   "lines thinner farther from the eye: width times clamp(D / d, 0.25, 2)",
                   SvgMapping::Outline,
                   "",
                   ""},
    StyleAttribute{"pressure",
                   {},
                   StyleValueKind::Profile,
                   &LineStyle::pressure,
                   10.0f,
                   "thickness along the stroke: factors on the width at evenly spaced points "
                   "from its first point to its last (e.g. 0.2,1,0.4), or none",
                   SvgMapping::Outline,
                   "",
                   "",
                   2.0f},
    StyleAttribute{"calligraphy",
                   {},
                   StyleValueKind::Fraction,
                   &LineStyle::calligraphy,
                   0.0f,
                   "a broad nib: the width of strokes drawn along it, as a fraction of the width "
                   "(across it the whole width); 1 = a round pen",
                   SvgMapping::Outline,
                   "",
                   ""},
    StyleAttribute{"nib_angle",
                   {},
                   StyleValueKind::Degrees,
                   &LineStyle::nib_angle,
                   360.0f,
                   "the nib's angle, degrees counter-clockwise on the image",
                   SvgMapping::Outline,
                   "",
                   ""},
    StyleAttribute{"brush",
                   {},
                   StyleValueKind::Path,
                   &LineStyle::brush,
                   0.0f,
                   "a PNG brush: its darkness is the ink across (rows) and along (columns) the "
                   "stroke; the SVG gets the width profile of the same ink; or none",
                   SvgMapping::Outline,
                   "",
                   ""},
    StyleAttribute{"brush_stretch",
                   {},
                   StyleValueKind::YesNo,
                   &LineStyle::brush_stretch,
                   0.0f,
                   "the brush stretched once along the whole stroke (no: stamped, repeating "
                   "every width times the image's aspect)",
                   SvgMapping::Outline,
                   "",
                   ""},
    StyleAttribute{"sketch",
                   {},
                   StyleValueKind::Count,
                   &LineStyle::sketch,
                   16.0f,
                   "sketchy strokes: this many overdrawn copies moved across the stroke by a "
                   "noise anchored on the surface (0 or 1: the stroke itself)",
                   SvgMapping::LeaveOut,
                   "",
                   ""},
    StyleAttribute{"sketch_offset",
                   {},
                   StyleValueKind::Length,
                   &LineStyle::sketch_offset,
                   100.0f,
                   "the largest offset of a sketchy copy",
                   SvgMapping::LeaveOut,
                   "",
                   ""},
    StyleAttribute{"sketch_period",
                   {},
                   StyleValueKind::Length,
                   &LineStyle::sketch_period,
                   1e4f,
                   "the sketch noise's wavelength on the surface, as seen at the distance of the "
                   "scene's centre",
                   SvgMapping::LeaveOut,
                   "",
                   ""},
    StyleAttribute{"sketch_seed",
                   {},
                   StyleValueKind::Count,
                   &LineStyle::sketch_seed,
                   16777216.0f,
                   "the sketch noise's seed: other seeds, other copies",
                   SvgMapping::LeaveOut,
                   "",
                   ""},
    StyleAttribute{"boil",
                   {},
                   StyleValueKind::Count,
                   &LineStyle::boil,
                   1e6f,
                   "the sketch noise changes every this many frames (0: never; a still camera "
                   "and scene then give the same frames)",
                   SvgMapping::LeaveOut,
                   "",
                   ""},
};

// Each row's field holds the type its kind reads (parse_style_value relies on it), and a rule's
// mask has a bit for each.
constexpr bool fields_match_kinds() {
    for (const StyleAttribute& a : kAttributes) {
        const std::size_t want =
            a.kind == StyleValueKind::YesNo                                       ? 0
            : a.kind == StyleValueKind::Colour                                    ? 1
            : a.kind == StyleValueKind::Dash || a.kind == StyleValueKind::Profile ? 3
            : a.kind == StyleValueKind::Path                                      ? 4
                                                                                  : 2;
        if (a.field.index() != want) return false;
    }
    return true;
}
static_assert(fields_match_kinds());
static_assert(kAttributes.size() <= 32);

std::vector<std::string_view> split(std::string_view text, char separator) {
    std::vector<std::string_view> parts;
    for (;;) {
        const std::size_t at = text.find(separator);
        parts.push_back(text.substr(0, at));
        if (at == std::string_view::npos) return parts;
        text.remove_prefix(at + 1);
    }
}

// Value parsers throw Error with what was wrong only; the rule builder adds key and place.
float parse_number(std::string_view text) {
    float value = 0.0f;
    const auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (text.empty() || ec != std::errc() || p != text.data() + text.size() ||
        !std::isfinite(value))
        throw Error(fmt::format("expected a number, got '{}'", text));
    return value;
}

bool parse_yes_no(std::string_view text) {
    if (text == "yes") return true;
    if (text == "no") return false;
    throw Error(fmt::format("expected yes or no, got '{}'", text));
}

std::vector<float> parse_dash(std::string_view text, float max) {
    if (text == "none") return {};
    std::vector<float> dash;
    float total = 0.0f;
    for (std::string_view part : split(text, ',')) {
        const float v = parse_number(part);
        if (v < 0.0f || v > max)
            throw Error(fmt::format("lengths must be in [0, {}], got '{}'", max, part));
        dash.push_back(v);
        total += v;
    }
    if (dash.size() > kMaxDashes)
        throw Error(fmt::format("at most {} lengths, got {}", kMaxDashes, dash.size()));
    if (dash.size() % 2 != 0) dash.insert(dash.end(), dash.begin(), dash.end());  // as SVG does
    if (!(total > 0.0f)) throw Error("the lengths must not all be 0");
    return dash;
}

std::vector<float> parse_profile(std::string_view text, float max, std::size_t min_values) {
    if (text == "none") return {};
    std::vector<float> values;
    for (std::string_view part : split(text, ',')) {
        const float v = parse_number(part);
        if (v < 0.0f || v > max)
            throw Error(fmt::format("factors must be in [0, {}], got '{}'", max, part));
        values.push_back(v);
    }
    if (values.size() < min_values || values.size() > kMaxDashes)
        throw Error(fmt::format("{} to {} factors, or none; got {}", min_values, kMaxDashes,
                                values.size()));
    return values;
}

std::string format_dash(const std::vector<float>& dash) {
    if (dash.empty()) return "none";
    // An odd list was repeated when read (parse_dash); written again whole it could exceed
    // kMaxDashes, so it is written as read.
    std::size_t count = dash.size();
    const std::size_t half = count / 2;
    if (half % 2 == 1 && std::equal(dash.begin(), dash.begin() + half, dash.begin() + half))
        count = half;
    return fmt::format("{}", fmt::join(dash.begin(), dash.begin() + count, ","));
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

std::vector<std::string> parse_globs(std::string_view text) {
    std::vector<std::string> globs;
    for (std::string_view g : split(text, ',')) {
        if (g.empty()) throw Error(fmt::format("empty name pattern in '{}'", text));
        globs.emplace_back(g);
    }
    return globs;
}

std::string format_globs(const std::vector<std::string>& globs) {
    return globs == std::vector<std::string>{"*"} ? std::string()
                                                  : fmt::format("{}", fmt::join(globs, ","));
}

constexpr unsigned kAllTypes = (1u << kEdgeTypeCount) - 1;

unsigned parse_types(std::string_view text) {
    if (text == "all") return kAllTypes;
    unsigned types = 0;
    for (std::string_view name : split(text, ',')) {
        int found = -1;
        std::string known;
        for (int t = 0; t < kEdgeTypeCount; ++t) {
            const std::string_view type_name = edge_type_name(static_cast<EdgeType>(t));
            if (name == type_name) found = t;
            known += fmt::format("{}{}", t ? ", " : "", type_name);
        }
        if (found < 0) throw Error(fmt::format("unknown line type '{}' ({} or all)", name, known));
        types |= 1u << found;
    }
    return types;
}

std::string format_types(unsigned types) {
    if (types == kAllTypes) return {};
    std::string out;
    for (int t = 0; t < kEdgeTypeCount; ++t)
        if (types & (1u << t))
            out += fmt::format("{}{}", out.empty() ? "" : ",",
                               edge_type_name(static_cast<EdgeType>(t)));
    return out;
}

// The matchers: how each is read into a rule and written back ("" when it is the default,
// which matches whatever).
struct MatcherRow {
    RuleMatcher info;
    void (*parse)(std::string_view text, LineStyleRule& rule);
    std::string (*format)(const LineStyleRule& rule);
};

constexpr std::array<MatcherRow, 4> kMatchers{{
    {{"object", "comma-separated globs (* any run, ? one character) on the object name"},
     [](std::string_view text, LineStyleRule& r) { r.objects = parse_globs(text); },
     [](const LineStyleRule& r) { return format_globs(r.objects); }},
    {{"material", "globs on the material name"},
     [](std::string_view text, LineStyleRule& r) { r.materials = parse_globs(text); },
     [](const LineStyleRule& r) { return format_globs(r.materials); }},
    {{"type",
      "silhouette, border, crease, material, intersection, polyline, band, shadow, tone, "
      "comma-separated, or all"},
     [](std::string_view text, LineStyleRule& r) { r.types = parse_types(text); },
     [](const LineStyleRule& r) { return format_types(r.types); }},
    {{"lines", "visible, hidden or all (visible when not given)"},
     [](std::string_view text, LineStyleRule& r) {
         if (text != "visible" && text != "hidden" && text != "all")
             throw Error(fmt::format("expected visible, hidden or all, got '{}'", text));
         r.match_visible = text != "hidden";
         r.match_hidden = text != "visible";
     },
     [](const LineStyleRule& r) {
         return std::string(r.match_hidden ? (r.match_visible ? "all" : "hidden") : "");
     }},
}};

constexpr std::array<RuleMatcher, 4> kMatcherInfo{kMatchers[0].info, kMatchers[1].info,
                                                  kMatchers[2].info, kMatchers[3].info};

// A rule built key by key, in the order written, so that the first mistake is the one named.
class RuleBuilder {
public:
    explicit RuleBuilder(const RuleLocation& at) : at_(at) { rule_.line = at.line; }

    void add(std::string_view key, std::string_view value) {
        for (const std::string& s : seen_)
            if (s == key) fail(fmt::format("'{}' given twice", key));
        seen_.emplace_back(key);
        for (const MatcherRow& m : kMatchers)
            if (m.info.name == key) return read(key, [&] { m.parse(value, rule_); });
        for (std::size_t i = 0; i < kAttributes.size(); ++i)
            if (kAttributes[i].named(key)) {
                read(key, [&] { parse_style_value(kAttributes[i], value, rule_.values); });
                rule_.sets |= 1u << i;
                return;
            }
        std::string keys;
        for (const MatcherRow& m : kMatchers) keys += fmt::format("{}, ", m.info.name);
        for (const StyleAttribute& a : kAttributes) keys += fmt::format("{}, ", a.name);
        keys.resize(keys.size() - 2);
        fail(fmt::format("unknown key '{}' ({})", key, keys));
    }

    [[noreturn]] void fail(const std::string& what) const {
        throw Error(fmt::format("{}: {}", at_.where, what));
    }

    LineStyleRule take() { return std::move(rule_); }

private:
    template <class Read>
    void read(std::string_view key, Read&& read_value) {
        try {
            read_value();
        } catch (const Error& e) {
            throw Error(fmt::format("{}{}{}: {}", at_.where, at_.key_separator, key, e.what()));
        }
    }

    const RuleLocation& at_;
    LineStyleRule rule_;
    std::vector<std::string> seen_;
};

LineStyleRule parse_rule(std::string_view body, const RuleLocation& at) {
    RuleBuilder builder(at);
    bool first = true;
    while (!body.empty()) {
        const std::size_t start = body.find_first_not_of(" \t\r");
        if (start == std::string_view::npos) break;
        body.remove_prefix(start);
        const std::size_t end = std::min(body.find_first_of(" \t\r"), body.size());
        const std::string_view word = body.substr(0, end);
        body.remove_prefix(end);
        if (first) {
            if (word != "match") builder.fail(fmt::format("expected 'match', got '{}'", word));
            first = false;
            continue;
        }
        const std::size_t eq = word.find('=');
        if (eq == std::string_view::npos)
            builder.fail(fmt::format("expected key=value, got '{}'", word));
        builder.add(word.substr(0, eq), word.substr(eq + 1));
    }
    return builder.take();
}

}  // namespace

bool StyleAttribute::named(std::string_view key) const {
    if (key == name) return true;
    for (std::string_view alias : aliases)
        if (key == alias) return true;
    return false;
}

std::span<const StyleAttribute> style_attributes() { return kAttributes; }

std::span<const RuleMatcher> rule_matchers() { return kMatcherInfo; }

std::vector<std::string_view> line_rule_keys() {
    std::vector<std::string_view> keys;
    for (const MatcherRow& m : kMatchers) keys.push_back(m.info.name);
    for (const StyleAttribute& a : kAttributes) {
        keys.push_back(a.name);
        keys.insert(keys.end(), a.aliases.begin(), a.aliases.end());
    }
    return keys;
}

void parse_style_value(const StyleAttribute& a, std::string_view text, LineStyle& style) {
    switch (a.kind) {
        case StyleValueKind::YesNo:
            style.*std::get<bool LineStyle::*>(a.field) = parse_yes_no(text);
            return;
        case StyleValueKind::Colour:
            try {
                style.*std::get<Vec3f LineStyle::*>(a.field) = parse_colour(text, a.name);
            } catch (const Error& e) {
                // parse_colour names the option it was given; the rule builder names the key.
                std::string_view what = e.what();
                what.remove_prefix(std::min(what.size(), a.name.size() + 2));
                throw Error(std::string(what));
            }
            return;
        case StyleValueKind::Length: {
            const float v = parse_number(text);
            if (v < 0.0f || v > a.max)
                throw Error(fmt::format("expected pixels in [0, {}], got '{}'", a.max, text));
            style.*std::get<float LineStyle::*>(a.field) = v;
            return;
        }
        case StyleValueKind::Fraction: {
            const float v = parse_number(text);
            if (v < 0.0f || v > 1.0f)
                throw Error(fmt::format("expected a value in [0, 1], got '{}'", text));
            style.*std::get<float LineStyle::*>(a.field) = v;
            return;
        }
        case StyleValueKind::Dash:
            style.*std::get<std::vector<float> LineStyle::*>(a.field) = parse_dash(text, a.max);
            return;
        case StyleValueKind::Profile:
            style.*std::get<std::vector<float> LineStyle::*>(a.field) =
                parse_profile(text, a.max, static_cast<std::size_t>(a.min));
            return;
        case StyleValueKind::Degrees: {
            const float v = parse_number(text);
            if (v < -a.max || v > a.max)
                throw Error(fmt::format("expected degrees in [-{0}, {0}], got '{1}'", a.max, text));
            style.*std::get<float LineStyle::*>(a.field) = v;
            return;
        }
        case StyleValueKind::Count: {
            const float v = parse_number(text);
            if (v < 0.0f || v > a.max || v != std::floor(v))
                throw Error(
                    fmt::format("expected a whole number in [0, {}], got '{}'", a.max, text));
            style.*std::get<float LineStyle::*>(a.field) = v;
            return;
        }
        case StyleValueKind::Path:
            if (text.empty() || text.find_first_of(" \t\r\n") != std::string_view::npos ||
                text.find('\0') != std::string_view::npos)
                throw Error(
                    fmt::format("expected a file name without blanks, or none; got '{}'", text));
            style.*std::get<std::string LineStyle::*>(a.field) = text == "none" ? "" : text;
            return;
    }
}

std::string format_style_value(const StyleAttribute& a, const LineStyle& style) {
    switch (a.kind) {
        case StyleValueKind::YesNo:
            return style.*std::get<bool LineStyle::*>(a.field) ? "yes" : "no";
        case StyleValueKind::Colour:
            return format_colour(style.*std::get<Vec3f LineStyle::*>(a.field));
        case StyleValueKind::Length:
        case StyleValueKind::Fraction:
        case StyleValueKind::Degrees:
        case StyleValueKind::Count:
            // The shortest text that reads back to the same float.
            return fmt::format("{}", style.*std::get<float LineStyle::*>(a.field));
        case StyleValueKind::Dash:
            return format_dash(style.*std::get<std::vector<float> LineStyle::*>(a.field));
        case StyleValueKind::Profile: {
            const auto& values = style.*std::get<std::vector<float> LineStyle::*>(a.field);
            return values.empty() ? "none" : fmt::format("{}", fmt::join(values, ","));
        }
        case StyleValueKind::Path: {
            const std::string& path = style.*std::get<std::string LineStyle::*>(a.field);
            return path.empty() ? "none" : path;
        }
    }
    return {};
}

LineStyle scale_line_style(const LineStyle& style, int height) {
    LineStyle out = style;
    for (const StyleAttribute& a : kAttributes) {
        if (a.kind == StyleValueKind::Length) {
            float& v = out.*std::get<float LineStyle::*>(a.field);
            v = stroke_thickness(v, height);
        } else if (a.kind == StyleValueKind::Dash) {
            for (float& v : out.*std::get<std::vector<float> LineStyle::*>(a.field))
                v = stroke_thickness(v, height);
        }
    }
    return out;
}

bool LineStyleRule::sets_field(const StyleField& field) const {
    for (std::size_t i = 0; i < kAttributes.size(); ++i)
        if (kAttributes[i].field == field) return (sets >> i & 1u) != 0;
    return false;
}

LineStyleRule make_line_style_rule(std::span<const RuleEntry> entries, const RuleLocation& at) {
    RuleBuilder builder(at);
    for (const auto& [key, value] : entries) builder.add(key, value);
    return builder.take();
}

std::vector<RuleEntry> line_style_rule_entries(const LineStyleRule& rule) {
    std::vector<RuleEntry> entries;
    for (const MatcherRow& m : kMatchers) {
        std::string text = m.format(rule);
        if (!text.empty()) entries.emplace_back(m.info.name, std::move(text));
    }
    for (std::size_t i = 0; i < kAttributes.size(); ++i)
        if (rule.sets >> i & 1u)
            entries.emplace_back(kAttributes[i].name,
                                 format_style_value(kAttributes[i], rule.values));
    return entries;
}

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
        const RuleLocation at{fmt::format("{}:{}", source, line), ": ", line};
        if (row.find('\0') != std::string_view::npos)
            throw Error(fmt::format("{}: NUL byte in the line", at.where));
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
        for (std::size_t i = 0; i < kAttributes.size(); ++i)
            if (rule.sets >> i & 1u)
                std::visit([&](auto field) { style.*field = rule.values.*field; },
                           kAttributes[i].field);
    }
    return style;
}

}  // namespace toonray::ink
