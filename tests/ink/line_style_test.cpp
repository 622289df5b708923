#include "toonray/ink/line_style.h"

#include <gtest/gtest.h>

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
    EXPECT_EQ(a.draw, true);
    EXPECT_NEAR(a.colour->x, 128.0f / 255.0f, 1e-6f);
    EXPECT_EQ(a.width, 1.5f);
    EXPECT_EQ(a.opacity, 0.5f);
    EXPECT_EQ(a.dash, (std::vector<float>{4.0f, 2.0f}));
    const ink::LineStyleRule& b = set.rules[1];
    EXPECT_EQ(b.line, 4);
    EXPECT_TRUE(b.match_visible);  // visible lines unless a rule says otherwise
    EXPECT_FALSE(b.match_hidden);
    EXPECT_EQ(b.dash, (std::vector<float>{3.0f, 3.0f}));  // an odd pattern repeats, as in SVG
    EXPECT_EQ(b.taper, 5.0f);
    EXPECT_FALSE(b.width.has_value());
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
        {ink::EdgeType::Crease, true, {{5, 5}, {30, 40}}, false, 0, {}}};
    ImageF plain(64, 48, 0.0f);
    ink::draw_strokes(strokes, 2.5f, plain, 1);
    const std::vector<ink::StrokePen> pens{{true, 2.5f, Vec3f{0.0f}, 1.0f, {}, 0.0f}};
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
    pens[0] = {true, 2.0f, Vec3f{0.0f}, 1.0f, {}, 0.0f};
    pens[1] = {true, 2.0f, Vec3f{1.0f, 0.0f, 0.0f}, 0.5f, {4.0f, 4.0f}, 0.0f};
    pens[2] = {false, 2.0f, Vec3f{0.0f}, 1.0f, {}, 0.0f};
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
        {ink::EdgeType::Crease, true, {{30, 2}, {30, 46}}, false, 1, {}}};
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
    const std::vector<ink::StrokePen> pens{{true, 4.0f, Vec3f{0.0f}, 1.0f, {}, 20.0f}};
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
    ink::StrokePen pen{true, 4.0f, Vec3f{0.0f}, 1.0f, {}, 0.0f};
    pen.depth_reference = 10.0f;
    ink::Stroke s = line(24.0f, 0);
    s.depth = {10.0f, 20.0f};  // full width at the start, half at the end
    ImageF coverage;
    Image<std::uint16_t> style;
    ink::draw_styled_strokes(std::vector<ink::Stroke>{s}, std::vector<ink::StrokePen>{pen}, 64, 48,
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
