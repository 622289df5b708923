#include "toonray/ink/draw.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "toonray/core/error.h"

namespace toonray {
namespace {

using ink::Point2;
using ink::Stroke;

Stroke stroke(std::vector<Point2> points) {
    Stroke s;
    s.points = std::move(points);
    return s;
}

TEST(DrawStrokes, CoverageAcrossALineAddsUpToItsThickness) {
    for (float thickness : {1.0f, 2.0f, 2.6667f, 4.5f}) {
        ImageF cov(64, 48, 0.0f);
        const std::vector<Stroke> strokes{stroke({{2.0f, 20.3f}, {62.0f, 20.3f}})};
        ink::draw_strokes(strokes, thickness, cov, 1);
        for (int x = 8; x < 56; ++x) {
            float sum = 0;
            for (int y = 0; y < 48; ++y) sum += cov(x, y);
            EXPECT_NEAR(sum, thickness, 1e-5f) << x;
        }
    }
}

TEST(DrawStrokes, RoundCapsAndNothingBeyondTheReach) {
    ImageF cov(40, 40, 0.0f);
    const std::vector<Stroke> strokes{stroke({{10.5f, 10.5f}, {20.5f, 10.5f}})};
    const float thickness = 3.0f, reach = 2.0f;
    ink::draw_strokes(strokes, thickness, cov, 1);
    for (int y = 0; y < 40; ++y)
        for (int x = 0; x < 40; ++x) {
            // Distance from the pixel centre to the segment, ends included.
            const float px = x + 0.5f, py = y + 0.5f;
            const float cx = std::clamp(px, 10.5f, 20.5f);
            const float d = std::hypot(px - cx, py - 10.5f);
            EXPECT_FLOAT_EQ(cov(x, y), std::clamp(reach - d, 0.0f, 1.0f)) << x << "," << y;
        }
}

TEST(DrawStrokes, SameForAnyStrokeOrderAndThreadCount) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-10.0f, 210.0f);
    std::vector<Stroke> strokes;
    for (int i = 0; i < 60; ++i)
        strokes.push_back(stroke({{u(rng), u(rng)}, {u(rng), u(rng)}, {u(rng), u(rng)}}));
    ImageF a(200, 150, 0.0f), b(200, 150, 0.0f);
    ink::draw_strokes(strokes, 2.5f, a, 1);
    std::reverse(strokes.begin(), strokes.end());
    ink::draw_strokes(strokes, 2.5f, b, 4);
    for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a.data()[i], b.data()[i]);
}

// The rasteriser visits, row by row, only the pixels of a segment's capsule (not its whole
// box): every pixel must still get exactly the coverage of the per-pixel rule, whatever the
// segment's slope, length and thickness.
TEST(DrawStrokes, EveryPixelGetsTheRuleOfItsNearestSegmentAtAnySlope) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> coordinate(-5.0f, 69.0f), width(0.5f, 9.0f);
    for (int trial = 0; trial < 60; ++trial) {
        const float thickness = width(rng);
        std::vector<Stroke> strokes;
        for (int i = 0; i < 3; ++i) {
            Point2 a{coordinate(rng), coordinate(rng)}, b{coordinate(rng), coordinate(rng)};
            if (i == 1) b.y = a.y;           // horizontal
            if (i == 2 && trial % 2) b = a;  // a dot
            strokes.push_back(stroke({a, b}));
        }
        ImageF got(64, 64, 0.0f);
        ink::draw_strokes(strokes, thickness, got, 1);
        const float reach = thickness * 0.5f + 0.5f;
        for (int y = 0; y < 64; ++y)
            for (int x = 0; x < 64; ++x) {
                float want = 0.0f;
                for (const Stroke& s : strokes) {
                    const Point2 a = s.points[0], b = s.points[1];
                    const float dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
                    const float inv_len2 = len2 > 0.0f ? 1.0f / len2 : 0.0f;
                    const float px = static_cast<float>(x) + 0.5f - a.x;
                    const float py = static_cast<float>(y) + 0.5f - a.y;
                    const float t = std::clamp((px * dx + py * dy) * inv_len2, 0.0f, 1.0f);
                    const float ex = px - dx * t, ey = py - dy * t;
                    want = std::max(want, std::min(1.0f, reach - std::sqrt(ex * ex + ey * ey)));
                }
                ASSERT_EQ(got(x, y), want) << "trial " << trial << " pixel " << x << "," << y;
            }
    }
}

TEST(OpaqueLines, MarkExactlyWhereThePictureCannotShow) {
    const std::vector<Stroke> strokes{stroke({{4.0f, 20.0f}, {60.0f, 27.0f}})};
    std::vector<ink::StrokePen> pens(2);
    pens[0].width = 4.0f;
    pens[1].width = 4.0f;
    pens[1].opacity = 0.5f;  // a second, see-through pen for the same line
    for (std::uint16_t style : {0, 1}) {
        std::vector<Stroke> styled = strokes;
        styled[0].style = style;
        ImageF coverage;
        Image<std::uint16_t> styles;
        ink::draw_styled_strokes(styled, pens, 64, 48, coverage, styles, 1);
        Image<std::uint8_t> opaque;
        ink::opaque_lines(coverage, styles, pens, opaque);
        ImageRgb8 white(64, 48, Rgb8{255, 255, 255}), red(64, 48, Rgb8{200, 10, 10});
        ink::composite_styled_lines(coverage, styles, pens, white);
        ink::composite_styled_lines(coverage, styles, pens, red);
        int marked = 0;
        for (int y = 0; y < 48; ++y)
            for (int x = 0; x < 64; ++x) {
                // Opaque pixels come out the same over any picture; the others do not.
                EXPECT_EQ(opaque(x, y) != 0, white(x, y) == red(x, y)) << x << "," << y;
                marked += opaque(x, y);
            }
        if (style == 0) EXPECT_GT(marked, 100);
        else EXPECT_EQ(marked, 0);
    }
}

// Styles and pens are made together (ink.h): a style index without a pen is a mistake upstream
// and must say so, not draw the stroke with another pen or leave it out unnoticed.
TEST(StyledStrokes, AStyleWithoutAPenThrows) {
    std::vector<Stroke> strokes{stroke({{4.0f, 20.0f}, {60.0f, 27.0f}}),
                                stroke({{4.0f, 30.0f}, {60.0f, 30.0f}})};
    strokes[1].style = 2;
    const std::vector<ink::StrokePen> pens(2);
    ImageF coverage;
    Image<std::uint16_t> styles;
    auto message = [](auto&& call) {
        try {
            call();
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("(no error)");
    };
    EXPECT_EQ(
        message([&] { ink::draw_styled_strokes(strokes, pens, 64, 48, coverage, styles, 1); }),
        "ink: stroke 1 has style 2 but there are 2 pens");
    // The line layer of a frame drawn with more pens than are given to composite it.
    strokes[1].style = 1;
    ink::draw_styled_strokes(strokes, pens, 64, 48, coverage, styles, 1);
    const std::vector<ink::StrokePen> fewer(1);
    ImageRgb8 image(64, 48, Rgb8{255, 255, 255});
    EXPECT_NE(message([&] {
                  ink::composite_styled_lines(coverage, styles, fewer, image);
              }).find("has style 1 but there are 1 pens"),
              std::string::npos);
    Image<std::uint8_t> opaque;
    EXPECT_NE(message([&] {
                  ink::opaque_lines(coverage, styles, fewer, opaque);
              }).find("has style 1 but there are 1 pens"),
              std::string::npos);
    // With every pen there, nothing throws.
    EXPECT_EQ(message([&] { ink::composite_styled_lines(coverage, styles, pens, image); }),
              "(no error)");
}

TEST(DrawStrokes, ThicknessScalesWithImageHeight) {
    EXPECT_FLOAT_EQ(ink::stroke_thickness(2.0f, 720), 2.0f);
    EXPECT_FLOAT_EQ(ink::stroke_thickness(2.0f, 1080), 3.0f);
    EXPECT_FLOAT_EQ(ink::stroke_thickness(2.0f, 360), 1.0f);
}

TEST(CompositeLines, BlendsTowardTheLineColour) {
    ImageF cov(3, 1, 0.0f);
    cov(1, 0) = 1.0f;
    cov(2, 0) = 0.5f;
    ImageRgb8 img(3, 1, Rgb8{200, 100, 255});
    ink::composite_lines(cov, Vec3f(0.0f), img);
    EXPECT_EQ(img(0, 0), (Rgb8{200, 100, 255}));
    EXPECT_EQ(img(1, 0), (Rgb8{0, 0, 0}));
    EXPECT_EQ(img(2, 0), (Rgb8{100, 50, 128}));
    ImageGray8 gray;
    ink::coverage_to_gray(cov, gray);
    EXPECT_EQ(gray(0, 0), 255);
    EXPECT_EQ(gray(1, 0), 0);
    EXPECT_EQ(gray(2, 0), 128);
}

}  // namespace
}  // namespace toonray
