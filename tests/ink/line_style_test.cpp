#include "toonray/ink/line_style.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <type_traits>
#include <variant>

#include "toonray/core/error.h"
#include "toonray/ink/draw.h"

namespace toonray {
namespace {

using ink::EdgeType;

std::string parse_error(const std::string& text) {
    try {
        (void)ink::parse_line_styles(text, "keys.style");
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(LineStyle, GlobsMatchNames) {
    EXPECT_TRUE(ink::glob_match("*", ""));
    EXPECT_TRUE(ink::glob_match("w*", "w12"));
    EXPECT_FALSE(ink::glob_match("w*", "b12"));
    EXPECT_TRUE(ink::glob_match("?1*", "b12"));
    EXPECT_TRUE(ink::glob_match("*_l", "cheek_l"));
    EXPECT_FALSE(ink::glob_match("*_l", "cheek_r"));
    EXPECT_TRUE(ink::glob_match("a*b*c", "axxbyyc"));
    EXPECT_FALSE(ink::glob_match("a*b*c", "axxbyy"));
    EXPECT_FALSE(ink::glob_match("ab", "abc"));
}

TEST(LineStyle, ParsesRulesCommentsAndColours) {
    const ink::LineStyleSet set = ink::parse_line_styles(
        "# the keys\n"
        "\n"
        "match object=w*,b* material=ivory,ebony type=crease,silhouette lines=hidden draw=yes "
        "color=#808080 width=1.5 opacity=0.5 dash=4,2  # dashed grey\n"
        "  match colour=1,0,0 dash=3 taper=5\r\n",
        "keys.style");
    ASSERT_EQ(set.rules.size(), 2u);
    const ink::LineStyleRule& a = set.rules[0];
    EXPECT_EQ(a.line, 3);
    EXPECT_EQ(a.objects, (std::vector<std::string>{"w*", "b*"}));
    EXPECT_EQ(a.materials, (std::vector<std::string>{"ivory", "ebony"}));
    EXPECT_EQ(a.types, (1u << static_cast<int>(EdgeType::Crease)) |
                           (1u << static_cast<int>(EdgeType::Silhouette)));
    EXPECT_FALSE(a.match_visible);
    EXPECT_TRUE(a.match_hidden);
    EXPECT_TRUE(a.sets_field(&ink::LineStyle::draw));
    EXPECT_TRUE(a.values.draw);
    EXPECT_NEAR(a.values.colour.x, 128.0f / 255.0f, 1e-6f);
    EXPECT_EQ(a.values.width, 1.5f);
    EXPECT_EQ(a.values.opacity, 0.5f);
    EXPECT_EQ(a.values.dash, (std::vector<float>{4.0f, 2.0f}));
    EXPECT_FALSE(a.sets_field(&ink::LineStyle::taper));
    const ink::LineStyleRule& b = set.rules[1];
    EXPECT_EQ(b.line, 4);
    EXPECT_TRUE(b.match_visible);  // visible lines unless a rule says otherwise
    EXPECT_FALSE(b.match_hidden);
    // An odd pattern repeats, as in SVG.
    EXPECT_EQ(b.values.dash, (std::vector<float>{3.0f, 3.0f}));
    EXPECT_EQ(b.values.taper, 5.0f);
    EXPECT_EQ(b.values.colour, (Vec3f{1.0f, 0.0f, 0.0f}));
    EXPECT_FALSE(b.sets_field(&ink::LineStyle::width));
    EXPECT_EQ(b.values.width, ink::LineStyle{}.width);  // what it does not set keeps the default
}

TEST(LineStyle, ErrorsNameTheFileLineAndWhatWasWrong) {
    EXPECT_EQ(parse_error("\nmatch width=-1\n"),
              "keys.style:2: width: expected pixels in [0, 1000], got '-1'");
    EXPECT_EQ(parse_error("draw=yes\n"), "keys.style:1: expected 'match', got 'draw=yes'");
    EXPECT_EQ(parse_error("match colr=#000000\n").substr(0, 32),
              "keys.style:1: unknown key 'colr'");
    EXPECT_EQ(parse_error("match type=edge\n").substr(0, 44),
              "keys.style:1: type: unknown line type 'edge'");
    EXPECT_EQ(parse_error("# ok\nmatch dash=0,0\n"),
              "keys.style:2: dash: the lengths must not all be 0");
    EXPECT_EQ(parse_error("match opacity=2\n"),
              "keys.style:1: opacity: expected a value in [0, 1], got '2'");
    EXPECT_EQ(parse_error("match draw=maybe\n"),
              "keys.style:1: draw: expected yes or no, got 'maybe'");
    EXPECT_EQ(parse_error("match lines=some\n"),
              "keys.style:1: lines: expected visible, hidden or all, got 'some'");
    EXPECT_EQ(parse_error("match width=1 width=2\n"), "keys.style:1: 'width' given twice");
    EXPECT_EQ(parse_error("match object=a,,b\n"),
              "keys.style:1: object: empty name pattern in 'a,,b'");
    EXPECT_EQ(parse_error("match width\n"), "keys.style:1: expected key=value, got 'width'");
    EXPECT_NE(parse_error("match color=#12345\n").find("keys.style:1: color: expected #rrggbb"),
              std::string::npos);
    EXPECT_EQ(parse_error("match width=nan\n"),
              "keys.style:1: width: expected a number, got 'nan'");
}

TEST(LineStyle, LaterRulesOverrideTheAttributesTheySet) {
    const ink::LineStyleSet set = ink::parse_line_styles(
        "match color=#ff0000 width=3\n"
        "match object=w* width=1 dash=2,2\n"
        "match object=w* lines=hidden draw=yes color=#808080\n"
        "match material=ebony type=crease draw=no\n",
        "s");
    ink::LineStyle base;
    base.width = 2.0f;
    // A visible white-key crease: colour from the first rule, width and dash from the second.
    ink::LineStyle s = ink::resolve_line_style(set, base, "w3", "ivory", EdgeType::Crease, true);
    EXPECT_TRUE(s.draw);
    EXPECT_EQ(s.colour, (Vec3f{1.0f, 0.0f, 0.0f}));
    EXPECT_EQ(s.width, 1.0f);
    EXPECT_EQ(s.dash, (std::vector<float>{2.0f, 2.0f}));
    // Hidden lines start off; only the third rule matches them.
    s = ink::resolve_line_style(set, base, "w3", "ivory", EdgeType::Crease, false);
    EXPECT_TRUE(s.draw);
    EXPECT_NEAR(s.colour.x, 128.0f / 255.0f, 1e-6f);
    EXPECT_EQ(s.width, 2.0f);
    EXPECT_TRUE(s.dash.empty());
    EXPECT_FALSE(ink::resolve_line_style(set, base, "case", "wood", EdgeType::Crease, false).draw);
    // Off by the last rule, for creases on ebony only.
    EXPECT_FALSE(ink::resolve_line_style(set, base, "b3", "ebony", EdgeType::Crease, true).draw);
    EXPECT_TRUE(ink::resolve_line_style(set, base, "b3", "ebony", EdgeType::Silhouette, true).draw);
    EXPECT_TRUE(set.draws_hidden());
}

TEST(LineStyle, TheKeysAreTheMatchersThenTheTablesAttributes) {
    const std::vector<std::string_view> keys = ink::line_rule_keys();
    EXPECT_EQ(keys, (std::vector<std::string_view>{
                        "object",        "material",    "type",          "lines",
                        "draw",          "color",       "colour",        "width",
                        "opacity",       "dash",        "taper",         "width_by_depth",
                        "pressure",      "calligraphy", "nib_angle",     "brush",
                        "brush_stretch", "sketch",      "sketch_offset", "sketch_period",
                        "sketch_seed",   "boil"}));
    for (const ink::StyleAttribute& a : ink::style_attributes()) {
        EXPECT_FALSE(a.help.empty()) << a.name;
        EXPECT_TRUE(a.named(a.name));
        // Lengths in pixels at 720 lines scale with the image; nothing else does.
        EXPECT_EQ(a.scales(), a.name == "width" || a.name == "taper" || a.name == "dash" ||
                                  a.name == "sketch_offset" || a.name == "sketch_period")
            << a.name;
    }
    for (const ink::RuleMatcher& m : ink::rule_matchers()) EXPECT_FALSE(m.help.empty()) << m.name;
}

ink::LineStyleRule rule_from(std::vector<ink::RuleEntry> entries) {
    return ink::make_line_style_rule(entries, {"settings.toml: lines.rule[2]", ".", 0});
}

std::string rule_error(std::vector<ink::RuleEntry> entries) {
    try {
        (void)rule_from(std::move(entries));
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

// A settings document's rule tables use the keys of a `match` line; their errors name the
// table and key as the document spells them.
TEST(LineStyle, RulesFromEntriesNameTheirPlaceInErrors) {
    EXPECT_EQ(rule_error({{"width", "x"}}),
              "settings.toml: lines.rule[2].width: expected a number, got 'x'");
    EXPECT_EQ(rule_error({{"colour", "#12"}}),
              "settings.toml: lines.rule[2].colour: expected #rrggbb, got '#12'");
    EXPECT_EQ(rule_error({{"type", "edge"}}).substr(0, 61),
              "settings.toml: lines.rule[2].type: unknown line type 'edge' (");
    EXPECT_EQ(rule_error({{"dash", "0,0"}}),
              "settings.toml: lines.rule[2].dash: the lengths must not all be 0");
    EXPECT_EQ(rule_error({{"draw", "yes"}, {"colr", "#000000"}}),
              "settings.toml: lines.rule[2]: unknown key 'colr' (object, material, type, lines, "
              "draw, color, width, opacity, dash, taper, width_by_depth, pressure, calligraphy, "
              "nib_angle, brush, brush_stretch, sketch, sketch_offset, sketch_period, sketch_seed, "
              "boil)");
    EXPECT_EQ(rule_error({{"width", "1"}, {"width", "2"}}),
              "settings.toml: lines.rule[2]: 'width' given twice");
    // Entries and a .style line are read by the same code.
    const ink::LineStyleSet set = ink::parse_line_styles(
        "match object=w*,b* lines=all type=crease colour=#ff8000 dash=3 width_by_depth=yes\n",
        "keys.style");
    ASSERT_EQ(set.rules.size(), 1u);
    ink::LineStyleRule rule = rule_from({{"object", "w*,b*"},
                                         {"lines", "all"},
                                         {"type", "crease"},
                                         {"colour", "#ff8000"},
                                         {"dash", "3"},
                                         {"width_by_depth", "yes"}});
    rule.line = 1;
    EXPECT_EQ(rule, set.rules[0]);
}

void expect_round_trip(const ink::LineStyleRule& rule) {
    const std::vector<ink::RuleEntry> entries = ink::line_style_rule_entries(rule);
    std::string text;
    for (const auto& [key, value] : entries) text += " " + key + "=" + value;
    ink::LineStyleRule back = ink::make_line_style_rule(entries, {"again", ": ", rule.line});
    EXPECT_EQ(back, rule) << text;
    // The values bit for bit, not only equal (-0 and 0 compare equal).
    for (const ink::StyleAttribute& a : ink::style_attributes())
        EXPECT_EQ(ink::format_style_value(a, back.values), ink::format_style_value(a, rule.values))
            << a.name << " in" << text;
    // And as a .style line, when no value has a blank (a settings document's globs can).
    bool blanks = false;
    for (const auto& [key, value] : entries)
        blanks = blanks || value.find_first_of(" \t") != std::string::npos;
    if (!blanks) {
        const ink::LineStyleSet set = ink::parse_line_styles("match" + text + "\n", "r.style");
        ASSERT_EQ(set.rules.size(), 1u) << text;
        back = set.rules[0];
        back.line = rule.line;
        EXPECT_EQ(back, rule) << text;
    }
}

TEST(LineStyle, RulesRoundTripThroughEntries) {
    const ink::LineStyleSet set = ink::parse_line_styles(
        "match\n"
        "match object=w*,b?,cheek_l material=ivory type=crease,silhouette lines=hidden draw=yes "
        "color=#808080 width=1.5 opacity=0.5 dash=4,2 taper=6 width_by_depth=no\n"
        "match lines=all type=all draw=no colour=0.1,0.2,0.30000001 width=0 opacity=0 dash=none "
        "taper=0 width_by_depth=yes\n"
        "match type=border,material,intersection,polyline colour=1,0,0 width=1000 opacity=1 "
        "taper=10000 dash=1,2,3,4,5,6,7,8,9,10,11,12,13,14,15\n"
        "match object=*,* material=a,b,c dash=0,1e-3 width=3.14159274 color=0.0039215689,1,0\n"
        "match lines=visible width=-0 dash=0.5,0,0.25 opacity=1e-7\n"
        "match type=band,shadow,tone pressure=0.2,1,0.30000001 calligraphy=0.25 nib_angle=-45.5 "
        "brush=ink/dry.png brush_stretch=yes sketch=3 sketch_offset=1.5 sketch_period=25 "
        "sketch_seed=16777216 boil=12\n"
        "match pressure=none brush=none sketch=0 calligraphy=1 nib_angle=360\n",
        "round.style");
    ASSERT_EQ(set.rules.size(), 8u);
    for (const ink::LineStyleRule& rule : set.rules) expect_round_trip(rule);
    // Every matcher and every attribute was written back by some rule above.
    std::vector<std::string> written;
    for (const ink::LineStyleRule& rule : set.rules)
        for (const auto& [key, value] : ink::line_style_rule_entries(rule)) written.push_back(key);
    for (const ink::RuleMatcher& m : ink::rule_matchers())
        EXPECT_NE(std::find(written.begin(), written.end(), m.name), written.end()) << m.name;
    for (const ink::StyleAttribute& a : ink::style_attributes())
        EXPECT_NE(std::find(written.begin(), written.end(), a.name), written.end()) << a.name;
    // A glob with a blank (a settings document can hold one).
    expect_round_trip(rule_from({{"object", "my key,b *"}, {"width", "2"}}));
    // Values drawn at random over each attribute's range.
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    for (int trial = 0; trial < 200; ++trial) {
        ink::LineStyleRule rule;
        for (std::size_t i = 0; i < ink::style_attributes().size(); ++i) {
            const ink::StyleAttribute& a = ink::style_attributes()[i];
            if (rng() % 2) continue;
            rule.sets |= 1u << i;
            std::visit(
                [&](auto field) {
                    using Value = std::remove_cvref_t<decltype(rule.values.*field)>;
                    if constexpr (std::is_same_v<Value, bool>) {
                        rule.values.*field = rng() % 2 == 0;
                    } else if constexpr (std::is_same_v<Value, Vec3f>) {
                        rule.values.*field = {unit(rng), unit(rng), unit(rng)};
                    } else if constexpr (std::is_same_v<Value, float>) {
                        float v = unit(rng);
                        if (a.kind == ink::StyleValueKind::Length) v *= a.max;
                        if (a.kind == ink::StyleValueKind::Degrees) v = (2.0f * v - 1.0f) * a.max;
                        if (a.kind == ink::StyleValueKind::Count)
                            v = std::floor(v * std::min(a.max, 1000.0f));
                        rule.values.*field = v;
                    } else if constexpr (std::is_same_v<Value, std::string>) {
                        rule.values.*field = "brushes/b" + std::to_string(rng() % 100) + ".png";
                    } else if (a.kind == ink::StyleValueKind::Profile) {
                        std::vector<float> profile(2 + rng() % 15);
                        for (float& f : profile) f = unit(rng) * a.max;
                        rule.values.*field = profile;
                    } else {
                        std::vector<float> dash(2 * (1 + rng() % 8));
                        for (float& d : dash) d = unit(rng) * 50.0f;
                        rule.values.*field = dash;
                    }
                },
                a.field);
        }
        expect_round_trip(rule);
    }
}

TEST(LineStyle, PensAreTheStyleInPixelsOfTheImage) {
    ink::LineStyle style;
    style.colour = {0.2f, 0.4f, 0.6f};
    style.width = 3.0f;
    style.opacity = 0.7f;
    style.dash = {4.0f, 2.0f};
    style.taper = 10.0f;
    const ink::StrokePen pen = ink::stroke_pen(style, 1080, 12.0f);
    // Every length that scales is times 1080 / 720, the rest as they were.
    EXPECT_EQ(pen.width, ink::stroke_thickness(3.0f, 1080));
    EXPECT_EQ(pen.taper, 15.0f);
    EXPECT_EQ(pen.dash, (std::vector<float>{6.0f, 3.0f}));
    EXPECT_EQ(pen.colour, style.colour);
    EXPECT_EQ(pen.opacity, 0.7f);
    EXPECT_EQ(pen.depth_reference, 0.0f);  // this style does not scale by depth
    style.by_depth = true;
    EXPECT_EQ(ink::stroke_pen(style, 1080, 12.0f).depth_reference, 12.0f);
    EXPECT_EQ(static_cast<const ink::LineStyle&>(ink::stroke_pen(style, 720)), style);
}

ink::StrokePen pen(float width, Vec3f colour = Vec3f{0.0f}, float opacity = 1.0f,
                   std::vector<float> dash = {}, float taper = 0.0f) {
    ink::StrokePen p;
    p.width = width;
    p.colour = colour;
    p.opacity = opacity;
    p.dash = std::move(dash);
    p.taper = taper;
    return p;
}

ink::Stroke line(float y, std::uint16_t style) {
    ink::Stroke s;
    s.points = {{4.0f, y}, {60.0f, y}};
    s.style = style;
    return s;
}

TEST(StyledStrokes, OneSolidPenDrawsExactlyLikeDrawStrokes) {
    const std::vector<ink::Stroke> strokes{
        line(10.3f, 0),
        line(12.0f, 0),
        {ink::EdgeType::Crease, true, {{5, 5}, {30, 40}}, false, 0, {}, {}, 1.0f}};
    ImageF plain(64, 48, 0.0f);
    ink::draw_strokes(strokes, 2.5f, plain, 1);
    const std::vector<ink::StrokePen> pens{pen(2.5f)};
    ImageF coverage;
    Image<std::uint16_t> style;
    ink::draw_styled_strokes(strokes, pens, 64, 48, coverage, style, 3);
    for (std::size_t i = 0; i < plain.size(); ++i) ASSERT_EQ(plain.data()[i], coverage.data()[i]);
    // And compositing with opacity 1 is composite_lines.
    ImageRgb8 a(64, 48, Rgb8{200, 100, 50}), b = a;
    ink::composite_lines(plain, Vec3f{0.0f}, a);
    ink::composite_styled_lines(coverage, style, pens, b);
    for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a.data()[i], b.data()[i]);
}

TEST(StyledStrokes, DashesOpacityAndTheStrongestStrokeWins) {
    std::vector<ink::StrokePen> pens(3);
    pens[0] = pen(2.0f);
    pens[1] = pen(2.0f, Vec3f{1.0f, 0.0f, 0.0f}, 0.5f, {4.0f, 4.0f});
    pens[2] = pen(2.0f);
    pens[2].draw = false;
    ImageF coverage;
    Image<std::uint16_t> style;
    // A dashed line at y = 20, an undrawn one at y = 30.
    const std::vector<ink::Stroke> strokes{line(20.0f, 1), line(30.0f, 2)};
    ink::draw_styled_strokes(strokes, pens, 64, 48, coverage, style, 1);
    for (int x = 6; x < 58; ++x) {
        // The centreline from x = 4: on over [4, 8), off over [8, 12), ...
        const float arc = x + 0.5f - 4.0f;
        const bool on = static_cast<int>(arc / 4.0f) % 2 == 0;
        EXPECT_EQ(coverage(x, 19) == 1.0f, on) << x;
        if (on) {
            EXPECT_EQ(style(x, 19), 1);
        }
        EXPECT_EQ(coverage(x, 29), 0.0f) << x;
    }
    ImageRgb8 image(64, 48, Rgb8{255, 255, 255});
    ink::composite_styled_lines(coverage, style, pens, image);
    EXPECT_EQ(image(5, 19), (Rgb8{255, 128, 128}));  // red at half opacity over white
    // Overlapping strokes: each pixel keeps the larger coverage, ties the lower style, in any
    // stroke order and thread count.
    std::vector<ink::Stroke> crossing{
        line(20.0f, 1),
        line(20.4f, 0),
        {ink::EdgeType::Crease, true, {{30, 2}, {30, 46}}, false, 1, {}, {}, 1.0f}};
    ImageF c1, c2;
    Image<std::uint16_t> s1, s2;
    ink::draw_styled_strokes(crossing, pens, 64, 48, c1, s1, 1);
    std::reverse(crossing.begin(), crossing.end());
    ink::draw_styled_strokes(crossing, pens, 64, 48, c2, s2, 4);
    for (std::size_t i = 0; i < c1.size(); ++i) {
        ASSERT_EQ(c1.data()[i], c2.data()[i]);
        ASSERT_EQ(s1.data()[i], s2.data()[i]);
    }
    EXPECT_EQ(s1(30, 20), 0);     // all three cover it fully: the lower style
    EXPECT_EQ(c1(30, 35), 1.0f);  // only the vertical line, in an "on" dash
    EXPECT_EQ(s1(30, 35), 1);
}

TEST(StyledStrokes, TaperThinsOpenStrokesToTheirEnds) {
    const std::vector<ink::StrokePen> pens{pen(4.0f, Vec3f{0.0f}, 1.0f, {}, 20.0f)};
    ImageF coverage;
    Image<std::uint16_t> style;
    ink::draw_styled_strokes(std::vector<ink::Stroke>{line(24.0f, 0)}, pens, 64, 48, coverage,
                             style, 1);
    auto across = [&](int x) {
        float sum = 0;
        for (int y = 0; y < 48; ++y) sum += coverage(x, y);
        return sum;
    };
    EXPECT_NEAR(across(32), 4.0f, 1e-5f);  // the middle: full thickness
    EXPECT_LT(across(9), across(16));      // thinner toward the ends
    EXPECT_LT(across(16), across(32));
    EXPECT_NEAR(across(59), across(4), 0.25f);  // symmetric
}

}  // namespace
}  // namespace toonray

namespace toonray {
namespace {

TEST(StyledStrokes, WidthByDepthThinsFartherPoints) {
    ink::StrokePen deep = pen(4.0f);
    deep.by_depth = true;
    deep.depth_reference = 10.0f;
    ink::Stroke s = line(24.0f, 0);
    s.depth = {10.0f, 20.0f};  // full width at the start, half at the end
    ImageF coverage;
    Image<std::uint16_t> style;
    ink::draw_styled_strokes(std::vector<ink::Stroke>{s}, std::vector<ink::StrokePen>{deep}, 64, 48,
                             coverage, style, 1);
    auto across = [&](int x) {
        float sum = 0;
        for (int y = 0; y < 48; ++y) sum += coverage(x, y);
        return sum;
    };
    // The nearest centreline point of pixel x is at t = (x + 0.5 - 4) / 56 along the line.
    for (int x : {8, 20, 32, 44, 56}) {
        const float t = (x + 0.5f - 4.0f) / 56.0f;
        const float depth = 10.0f + 10.0f * t;
        EXPECT_NEAR(across(x), 4.0f * 10.0f / depth, 0.02f) << x;
    }
    const ink::LineStyleSet set = ink::parse_line_styles("match width_by_depth=yes\n", "s");
    EXPECT_TRUE(
        ink::resolve_line_style(set, ink::LineStyle{}, "a", "b", EdgeType::Crease, true).by_depth);
}

}  // namespace
}  // namespace toonray
