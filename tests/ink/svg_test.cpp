#include "toonray/ink/svg.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "ink/ink_scenes.h"
#include "ink/svg_compare.h"
#include "support/test_support.h"
#include "toonray/core/error.h"
#include "toonray/ink/draw.h"
#include "toonray/ink/ink.h"

namespace toonray {
namespace {

using ink::Point2;
using ink::Stroke;

Stroke polyline(std::vector<Point2> points, std::uint16_t style = 0) {
    Stroke s;
    s.points = std::move(points);
    s.style = style;
    return s;
}

// Points along an arc of a circle, `turns` of a full turn from `start` radians.
std::vector<Point2> circle_arc(Point2 centre, float radius, float start, float turns, int n) {
    std::vector<Point2> points;
    for (int i = 0; i <= n; ++i) {
        const float a = start + 6.2831853f * turns * static_cast<float>(i) / n;
        points.push_back({centre.x + radius * std::cos(a), centre.y + radius * std::sin(a)});
    }
    return points;
}

// Strokes of every shape the outline must follow: straight, gently curved, sharp corners
// (joins on both sides), a closed loop, a short stroke, a dot.
std::vector<Stroke> test_strokes() {
    std::vector<Stroke> strokes;
    strokes.push_back(polyline({{20.5f, 20.25f}, {300.0f, 30.0f}}));
    strokes.push_back(polyline(circle_arc({90.0f, 120.0f}, 60.0f, 0.3f, 0.7f, 40)));
    strokes.push_back(polyline(
        {{170.0f, 70.0f}, {210.0f, 160.0f}, {240.0f, 75.0f}, {270.0f, 170.0f}, {300.0f, 90.0f}}));
    Stroke loop = polyline(circle_arc({250.0f, 200.0f}, 25.0f, 0.0f, 1.0f, 24));
    loop.points.back() = loop.points.front();
    loop.closed = true;
    strokes.push_back(loop);
    strokes.push_back(polyline({{30.0f, 215.0f}, {52.0f, 205.0f}}));
    strokes.push_back(polyline({{120.0f, 220.0f}, {120.0f, 220.0f}}));
    return strokes;
}

// The depth at each point: from near (twice the width) to far (a quarter of it) and back,
// so that every stroke's width changes along it.
void add_depths(std::vector<Stroke>& strokes) {
    for (Stroke& s : strokes) {
        s.depth.clear();
        for (std::size_t i = 0; i < s.points.size(); ++i)
            s.depth.push_back(4.0f + 40.0f * std::abs(std::sin(0.15f * s.points[i].x)));
    }
}

ink::StrokePen black_pen(float width) {
    ink::StrokePen pen;
    pen.width = width;
    return pen;
}

// At least 99% of each image's line pixels within 1.5 px of the other's, about as many of
// them, and more than `min_pixels`; the figures are printed for docs/ink.md.
void expect_close(const test_support::RsvgAgreement& a, const std::string& name, long min_pixels) {
    std::cout << name << ": " << a.ours << " line pixels drawn, " << a.theirs << " by rsvg; "
              << 100.0 * a.ours_near_theirs << "% of ours near rsvg's, "
              << 100.0 * a.theirs_near_ours << "% of rsvg's near ours\n";
    EXPECT_GT(a.ours, min_pixels) << name;
    EXPECT_NEAR(static_cast<double>(a.theirs) / static_cast<double>(a.ours), 1.0, 0.05) << name;
    EXPECT_GE(a.ours_near_theirs, 0.99) << name;
    EXPECT_GE(a.theirs_near_ours, 0.99) << name;
}

// rsvg-convert draws the SVG as toonray draws the strokes (expect_close). `outlines`: whether the
// strokes whose width varies are there as filled outlines.
void expect_rsvg_agrees(const std::vector<Stroke>& strokes, std::span<const ink::StrokePen> pens,
                        int w, int h, const std::string& name, bool outlines = true) {
    ImageF coverage;
    Image<std::uint16_t> style;
    ink::draw_styled_strokes(strokes, pens, w, h, coverage, style, 2);
    ink::SvgSettings svg;
    svg.width = w;
    svg.height = h;
    svg.thickness = pens[0].width;
    svg.pens = pens;
    const std::string text = ink::svg_text(strokes, svg);
    EXPECT_EQ(text.find("stroke=\"none\" fill=\"#000000\"") != std::string::npos, outlines) << name;
    EXPECT_EQ(text.find("fill=\"#000000\" d=\"\""), std::string::npos) << name;
    test_support::TempDir dir("ink_svg_" + name);
    test_support::RsvgAgreement a;
    test_support::measure_rsvg(strokes, coverage, svg, dir.path, name, 1, a);
    expect_close(a, name, 500);
}

TEST(InkSvg, TaperedStrokesAreOutlinesDrawnLikeThePng) {
    ink::StrokePen pen = black_pen(7.0f);
    pen.taper = 40.0f;
    expect_rsvg_agrees(test_strokes(), std::vector<ink::StrokePen>{pen}, 320, 240, "taper");
}

TEST(InkSvg, WidthByDepthStrokesAreOutlinesDrawnLikeThePng) {
    ink::StrokePen pen = black_pen(5.0f);
    pen.by_depth = true;
    pen.depth_reference = 10.0f;
    std::vector<Stroke> strokes = test_strokes();
    add_depths(strokes);
    expect_rsvg_agrees(strokes, std::vector<ink::StrokePen>{pen}, 320, 240, "by_depth");
}

TEST(InkSvg, DashedTaperedStrokesAreOutlinesDrawnLikeThePng) {
    ink::StrokePen pen = black_pen(6.0f);
    pen.taper = 30.0f;
    pen.dash = {14.0f, 6.0f, 4.0f, 6.0f};
    std::vector<Stroke> strokes = test_strokes();
    expect_rsvg_agrees(strokes, std::vector<ink::StrokePen>{pen}, 320, 240, "dash_taper");
    // Dashes, taper and depth together.
    pen.by_depth = true;
    pen.depth_reference = 10.0f;
    add_depths(strokes);
    expect_rsvg_agrees(strokes, std::vector<ink::StrokePen>{pen}, 320, 240, "dash_taper_by_depth");
}

// Dashes of constant width stay stroked paths with stroke-dasharray, with square ends like the
// drawing's dashes. The drawing rounds the ends of the stroke (and bulges where a dash ends at a
// corner), the path does not: for lines up to 3 px wide that stays within the comparison's
// 1.5 px.
TEST(InkSvg, DashedStrokesAreDrawnLikeThePng) {
    ink::StrokePen pen = black_pen(3.0f);
    pen.dash = {14.0f, 6.0f, 4.0f, 6.0f};
    expect_rsvg_agrees(test_strokes(), std::vector<ink::StrokePen>{pen}, 320, 240, "dash", false);
}

using test_support::Teapot;

// A whole frame's strokes, styled by a style file, in SVG and PNG.
TEST(InkSvg, StyledTeapotOutlinesDrawLikeThePng) {
    const int w = 960, h = 540;
    const Teapot t(w, h);
    for (const auto& [name, style] :
         {std::pair{"teapot_taper", "match width=4 taper=30\n"},
          std::pair{"teapot_by_depth", "match width=4 width_by_depth=yes\n"},
          std::pair{"teapot_dash_taper", "match width=4 taper=20 dash=16,6\n"}}) {
        ink::InkSettings settings;
        settings.styles = ink::parse_line_styles(style, "teapot.style");
        ink::InkLines lines;
        ink::draw_ink_lines(t.scene, t.accel, t.camera, w, h, settings, 2, lines);
        ink::SvgSettings svg;
        svg.width = w;
        svg.height = h;
        svg.thickness = ink::stroke_thickness(settings.width, h);
        svg.pens = lines.pens;
        test_support::TempDir dir(name);
        test_support::RsvgAgreement a;
        test_support::measure_rsvg(lines.strokes, lines.coverage, svg, dir.path, name, 10, a);
        expect_close(a, name, 3000);
    }
}

// Strokes whose width does not vary stay stroked polylines, written as before styles had
// outlines: group defaults, or the attributes in which their pen differs.
TEST(InkSvg, SolidAndDashedStrokesStayStrokedPaths) {
    std::vector<ink::StrokePen> pens(3, black_pen(2.0f));
    pens[1].colour = {1.0f, 0.0f, 0.0f};
    pens[1].opacity = 0.5f;
    pens[1].dash = {1.5f, 1.0f};
    pens[2].taper = 5.0f;  // a closed stroke has no ends to taper
    std::vector<Stroke> strokes{
        polyline({{1.0f, 2.0f}, {3.5f, 4.0f}, {-0.0001f, 6.0f}}, 0),
        polyline({{1.0f, 2.0f}, {3.0f, 4.0f}}, 1),
        polyline({{1.0f, 1.0f}, {5.0f, 1.0f}, {5.0f, 5.0f}, {1.0f, 1.0f}}, 2)};
    strokes[2].closed = true;
    ink::SvgSettings svg;
    svg.width = 8;
    svg.height = 8;
    svg.thickness = 2.0f;
    svg.pens = pens;
    const std::string text = ink::svg_text(strokes, svg);
    EXPECT_NE(text.find("<g id=\"visible-silhouette\">\n"
                        "<path d=\"M 1.000 2.000 L 3.500 4.000 0.000 6.000\"/>\n"
                        "<path stroke=\"#ff0000\" stroke-opacity=\"0.500\" "
                        "stroke-dasharray=\"1.500,1.000\" stroke-linecap=\"butt\" "
                        "d=\"M 1.000 2.000 L 3.000 4.000\"/>\n"
                        "<path d=\"M 1.000 1.000 L 5.000 1.000 5.000 5.000 Z\"/>\n"
                        "</g>\n"),
              std::string::npos)
        << text;
}

TEST(InkSvg, AStyleWithoutAPenThrows) {
    std::vector<Stroke> strokes{polyline({{1.0f, 2.0f}, {3.0f, 4.0f}}, 0),
                                polyline({{1.0f, 2.0f}, {3.0f, 4.0f}}, 3)};
    strokes[1].visible = false;  // not even written: the hidden layer is off
    const std::vector<ink::StrokePen> pens(2);
    ink::SvgSettings svg;
    svg.pens = pens;
    try {
        (void)ink::svg_text(strokes, svg);
        ADD_FAILURE() << "no error";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), "ink: stroke 1 has style 3 but there are 2 pens");
    }
    // Without pens every stroke has the group's defaults.
    svg.pens = {};
    EXPECT_NE(ink::svg_text(strokes, svg).find("<path d="), std::string::npos);
}

}  // namespace
}  // namespace toonray
