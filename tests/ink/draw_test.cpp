#include "toonray/ink/draw.h"

#include <gtest/gtest.h>

#include <random>

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
