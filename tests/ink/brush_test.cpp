// Brush and sketchy strokes: the line-style attributes pressure, calligraphy and nib_angle,
// brush and brush_stretch, sketch, sketch_offset, sketch_period, sketch_seed and boil.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "ink/ink_scenes.h"
#include "ink/svg_compare.h"
#include "support/test_support.h"
#include "toonray/ink/draw.h"
#include "toonray/ink/ink.h"
#include "toonray/ink/line_style.h"
#include "toonray/ink/sketch.h"
#include "toonray/ink/svg.h"

using namespace toonray;
using ink::Point2;
using ink::Stroke;

namespace {

Stroke line(Point2 a, Point2 b) {
    Stroke s;
    s.points = {a, b};
    return s;
}

ink::StrokePen pen_of(const std::string& rule, int height = 720,
                      const ink::BrushSet* brushes = nullptr) {
    const ink::LineStyleSet set = ink::parse_line_styles(rule, "test.style");
    ink::LineStyle base;
    const ink::LineStyle style =
        ink::resolve_line_style(set, base, "o", "m", ink::EdgeType::Silhouette, true);
    return ink::stroke_pen(style, height, 0.0f, brushes);
}

// The coverage summed down column x: the stroke's drawn width there.
double column_width(const ImageF& coverage, int x) {
    double sum = 0.0;
    for (int y = 0; y < coverage.height(); ++y) sum += coverage(x, y);
    return sum;
}

}  // namespace

TEST(BrushStyles, NewAttributesParseAndRoundTrip) {
    const ink::LineStyleSet set = ink::parse_line_styles(
        "match pressure=0.2,1,0.5 calligraphy=0.25 nib_angle=-30 brush=ink/dry.png "
        "brush_stretch=yes sketch=3 sketch_offset=1.5 sketch_period=25 sketch_seed=7 boil=2\n",
        "brush.style");
    ASSERT_EQ(set.rules.size(), 1u);
    const ink::LineStyleRule& rule = set.rules[0];
    EXPECT_EQ(rule.values.pressure, (std::vector<float>{0.2f, 1.0f, 0.5f}));
    EXPECT_EQ(rule.values.calligraphy, 0.25f);
    EXPECT_EQ(rule.values.nib_angle, -30.0f);
    EXPECT_EQ(rule.values.brush, "ink/dry.png");
    EXPECT_TRUE(rule.values.brush_stretch);
    EXPECT_EQ(rule.values.sketch, 3.0f);
    EXPECT_EQ(rule.values.boil, 2.0f);
    const auto entries = ink::line_style_rule_entries(rule);
    EXPECT_EQ(ink::make_line_style_rule(entries, {"x.toml: lines.rule[1]", ".", rule.line}), rule);
    for (const char* bad : {"match pressure=1", "match pressure=1,x", "match pressure=1,20",
                            "match calligraphy=2", "match nib_angle=400", "match sketch=2.5",
                            "match sketch=-1", "match boil=1e9", "match brush="}) {
        EXPECT_THROW(static_cast<void>(ink::parse_line_styles(bad, "bad.style")), Error) << bad;
    }
    // `none` clears a profile and a brush.
    const ink::LineStyleSet none =
        ink::parse_line_styles("match pressure=none brush=none\n", "n.style");
    EXPECT_TRUE(none.rules[0].values.pressure.empty());
    EXPECT_TRUE(none.rules[0].values.brush.empty());
}

TEST(BrushStyles, PressureScalesTheWidthAlongTheStroke) {
    const ink::StrokePen pen = pen_of("match width=8 pressure=0.25,1,0.5\n");
    const std::vector<Stroke> strokes{line({20.5f, 40.0f}, {220.5f, 40.0f})};
    ImageF coverage;
    Image<std::uint16_t> style;
    ink::draw_styled_strokes(strokes, std::vector<ink::StrokePen>{pen}, 240, 80, coverage, style,
                             1);
    // At 1/4, 1/2 and 3/4 of the way: linear between the profile's points.
    for (const auto& [x, factor] :
         {std::pair{70, 0.625}, std::pair{120, 1.0}, std::pair{170, 0.75}})
        EXPECT_NEAR(column_width(coverage, x), 8.0 * factor, 0.1) << x;
}

TEST(BrushStyles, CalligraphyIsThinAlongTheNibAndWideAcrossIt) {
    const ink::StrokePen pen = pen_of("match width=10 calligraphy=0.2 nib_angle=0\n");
    ImageF coverage;
    Image<std::uint16_t> style;
    // Along the nib (horizontal): 0.2 of the width; across it (vertical): all of it.
    ink::draw_styled_strokes(std::vector<Stroke>{line({20, 30.5f}, {180, 30.5f})},
                             std::vector<ink::StrokePen>{pen}, 200, 200, coverage, style, 1);
    EXPECT_NEAR(column_width(coverage, 100), 2.0, 0.05);
    ink::draw_styled_strokes(std::vector<Stroke>{line({100.5f, 20}, {100.5f, 180})},
                             std::vector<ink::StrokePen>{pen}, 200, 200, coverage, style, 1);
    double across = 0.0;
    for (int x = 0; x < 200; ++x) across += coverage(x, 100);
    EXPECT_NEAR(across, 10.0, 0.05);
}

TEST(BrushStyles, ABrushInksWhereItsImageIsDarkAndTheSvgGetsItsWidth) {
    // A brush inked on its first half of rows only: the left half of the stroke.
    ImageRgb8 image(16, 8);
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 16; ++x) image(x, y) = y < 4 ? Rgb8{0, 0, 0} : Rgb8{255, 255, 255};
    ink::BrushSet brushes;
    brushes.emplace("half.png", std::make_shared<const ink::Brush>(ink::make_brush(image)));
    const ink::StrokePen pen = pen_of("match width=12 brush=half.png\n", 720, &brushes);
    ASSERT_NE(pen.brush_image, nullptr);
    EXPECT_FLOAT_EQ(ink::brush_width(*pen.brush_image, 0.3f), 0.5f);
    // Left of a stroke drawn to the right on the image (y down) is up.
    ImageF coverage;
    Image<std::uint16_t> style;
    ink::draw_styled_strokes(std::vector<Stroke>{line({20.5f, 50.0f}, {180.5f, 50.0f})},
                             std::vector<ink::StrokePen>{pen}, 200, 100, coverage, style, 1);
    double above = 0.0, below = 0.0;
    for (int y = 0; y < 100; ++y) (y < 50 ? above : below) += coverage(100, y);
    EXPECT_GT(above, 4.0);
    EXPECT_LT(below, 1.0);
    // The SVG writes the outline of half the width.
    ink::SvgSettings svg;
    svg.width = 200;
    svg.height = 100;
    svg.pens = std::span<const ink::StrokePen>(&pen, 1);
    const std::string text =
        ink::svg_text(std::vector<Stroke>{line({20.5f, 50.0f}, {180.5f, 50.0f})}, svg);
    EXPECT_NE(text.find("stroke=\"none\""), std::string::npos);
    EXPECT_NE(text.find("M 20.500 53.000"), std::string::npos) << "half of 12 px: a radius of 3";
    // A style naming a brush that was not read is an error, not a plain line.
    EXPECT_THROW(static_cast<void>(pen_of("match brush=other.png\n", 720, &brushes)), Error);
}

TEST(BrushStyles, PressureAndCalligraphyOutlinesDrawLikeThePng) {
    // rsvg-convert's drawing of the outlines against toonray's own coverage.
    std::vector<Stroke> strokes;
    for (int i = 0; i < 6; ++i) {
        Stroke s;
        for (int k = 0; k <= 40; ++k) {
            const float a = 0.15f * static_cast<float>(k) + static_cast<float>(i);
            s.points.push_back({40.0f + 6.0f * k, 40.0f + 35.0f * i + 12.0f * std::sin(a)});
        }
        strokes.push_back(s);
    }
    for (const char* rule :
         {"match width=9 pressure=0.1,1,0.3,0.8\n", "match width=9 calligraphy=0.15 nib_angle=30\n",
          "match width=9 pressure=0.2,1 taper=20 calligraphy=0.3\n"}) {
        const ink::StrokePen pen = pen_of(rule, 360);
        const std::vector<ink::StrokePen> pens{pen};
        ImageF coverage;
        Image<std::uint16_t> style;
        ink::draw_styled_strokes(strokes, pens, 320, 260, coverage, style, 1);
        ink::SvgSettings svg;
        svg.width = 320;
        svg.height = 260;
        svg.pens = pens;
        test_support::TempDir dir("brush_rsvg");
        test_support::RsvgAgreement a;
        test_support::measure_rsvg(strokes, coverage, svg, dir.path, "brush", 6, a);
        std::printf("%s: %.2f%% of ours near rsvg's, %.2f%% of rsvg's near ours\n", rule,
                    100.0 * a.ours_near_theirs, 100.0 * a.theirs_near_ours);
        EXPECT_GE(a.ours_near_theirs, 0.99) << rule;
        EXPECT_GE(a.theirs_near_ours, 0.99) << rule;
    }
}

TEST(Sketch, CopiesAreDeterministicBoundedAndAnchoredOnTheSurface) {
    ink::StrokePen pen = pen_of("match sketch=3 sketch_offset=4 sketch_period=20\n", 720);
    Stroke s;
    for (int k = 0; k <= 50; ++k) {
        s.points.push_back({10.0f + 4.0f * k, 50.0f});
        s.world.push_back(Vec3f(0.1f * k, 0.3f, -2.0f));
    }
    const std::vector<ink::StrokePen> pens{pen};
    const auto a = ink::sketch_strokes({s}, pens, 0.025f, 0);
    ASSERT_EQ(a.size(), 3u);
    const auto again = ink::sketch_strokes({s}, pens, 0.025f, 0);
    for (std::size_t c = 0; c < 3; ++c) EXPECT_EQ(a[c].points, again[c].points);
    // The copies differ from each other and stay within the offset (across 4, along 2).
    EXPECT_NE(a[0].points, a[1].points);
    for (const Stroke& c : a)
        for (std::size_t i = 0; i < c.points.size(); ++i) {
            EXPECT_LE(std::abs(c.points[i].y - 50.0f), 4.0f + 1e-3f);
            EXPECT_LE(std::abs(c.points[i].x - s.points[i].x), 2.0f + 1e-3f);
        }
    // The camera pans: the same surface points, elsewhere on the image. The copies move with
    // them, offsets and all.
    Stroke panned = s;
    for (Point2& p : panned.points) p.x += 37.0f;
    const auto b = ink::sketch_strokes({panned}, pens, 0.025f, 0);
    for (std::size_t c = 0; c < 3; ++c)
        for (std::size_t i = 0; i < s.points.size(); ++i) {
            EXPECT_NEAR(b[c].points[i].x, a[c].points[i].x + 37.0f, 1e-3f);
            EXPECT_NEAR(b[c].points[i].y, a[c].points[i].y, 1e-4f);
        }
    // Without boil every frame is the same; with boil 2 the noise changes every other frame.
    EXPECT_EQ(ink::sketch_strokes({s}, pens, 0.025f, 5)[0].points, a[0].points);
    ink::StrokePen boiling = pen;
    boiling.boil = 2.0f;
    const std::vector<ink::StrokePen> boil{boiling};
    EXPECT_EQ(ink::sketch_strokes({s}, boil, 0.025f, 0)[0].points,
              ink::sketch_strokes({s}, boil, 0.025f, 1)[0].points);
    EXPECT_NE(ink::sketch_strokes({s}, boil, 0.025f, 1)[0].points,
              ink::sketch_strokes({s}, boil, 0.025f, 2)[0].points);
}

TEST(Sketch, AFrameOfSketchyStrokesIsTheSameForEveryThreadCount) {
    const test_support::Teapot t(640, 360);
    ink::InkSettings settings;
    settings.styles = ink::parse_line_styles(
        "match sketch=2 sketch_offset=2 sketch_period=30 pressure=0.3,1,0.6\n", "s.style");
    ink::InkLines one, two;
    ink::draw_ink_lines(t.scene, t.accel, t.camera, 640, 360, settings, 1, one);
    ink::draw_ink_lines(t.scene, t.accel, t.camera, 640, 360, settings, 2, two);
    ASSERT_EQ(one.strokes.size(), two.strokes.size());
    for (std::size_t i = 0; i < one.strokes.size(); ++i)
        EXPECT_EQ(one.strokes[i].points, two.strokes[i].points);
    ASSERT_EQ(one.coverage.size(), two.coverage.size());
    EXPECT_TRUE(std::equal(one.coverage.data(), one.coverage.data() + one.coverage.size(),
                           two.coverage.data()));
    // Every stroke with its places in the world is drawn twice.
    EXPECT_GT(one.strokes.size(), 50u);
}
