// The classic pipeline, step by step, against values worked out by hand from the issue's
// definitions.
#include "toonray/render/classic.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace toonray;

TEST(ClassicCel, SixteenLevelsOfThreeGreys) {
    EXPECT_EQ(classic_cel_level(-1.0f), 0.5f);
    EXPECT_EQ(classic_cel_level(0.0f), 0.5f);
    EXPECT_EQ(classic_cel_level(0.2499f), 0.5f);   // k = 3
    EXPECT_EQ(classic_cel_level(0.25f), 0.75f);    // k = 4
    EXPECT_EQ(classic_cel_level(0.4999f), 0.75f);  // k = 7
    EXPECT_EQ(classic_cel_level(0.5f), 1.0f);      // k = 8
    EXPECT_EQ(classic_cel_level(1.0f), 1.0f);      // k = 16 clamps to 15
    EXPECT_EQ(classic_cel_level(std::nanf("")), 0.5f);
}

TEST(ClassicDepthMap, NormalisedByTheFarthestHitMissesWhite) {
    const float inf = std::numeric_limits<float>::infinity();
    ImageF d(4, 1);
    d(0, 0) = 1.0f;
    d(1, 0) = 2.0f;
    d(2, 0) = 4.0f;
    d(3, 0) = inf;
    ImageGray8 out;
    classic_depth_map(d, out, 1);
    EXPECT_EQ(out(0, 0), 64);   // round(0.25 * 255) = round(63.75)
    EXPECT_EQ(out(1, 0), 128);  // round(127.5)
    EXPECT_EQ(out(2, 0), 255);
    EXPECT_EQ(out(3, 0), 255);
}

TEST(ClassicNormalMap, HalfOffsetScaledMissesBlack) {
    Image<Vec3f> n(2, 1);
    ImageF d(2, 1, 1.0f);
    n(0, 0) = {0.0f, 1.0f, -1.0f};
    d(1, 0) = std::numeric_limits<float>::infinity();
    ImageRgb8 out;
    classic_normal_map(n, d, out, 1);
    EXPECT_EQ(out(0, 0), (Rgb8{128, 255, 0}));  // round(127.5) = 128
    EXPECT_EQ(out(1, 0), (Rgb8{0, 0, 0}));
}

TEST(ClassicSobel, VerticalStepMarksTwoColumnsAboveThreshold) {
    // A step of s grey levels gives |gx| = 4 s next to it; threshold 8 needs s >= 3.
    for (int step : {2, 3}) {
        ImageGray8 in(8, 5, 100);
        for (int y = 0; y < 5; ++y)
            for (int x = 4; x < 8; ++x) in(x, y) = static_cast<std::uint8_t>(100 + step);
        ImageGray8 edges;
        sobel_edges(in, 8.0f, edges, 1);
        for (int y = 0; y < 5; ++y)
            for (int x = 0; x < 8; ++x) {
                bool expect_edge = step == 3 && (x == 3 || x == 4);
                EXPECT_EQ(edges(x, y), expect_edge ? 0 : 255) << "step " << step << " at " << x << "," << y;
            }
    }
}

TEST(ClassicSobel, BordersAreClampedNotZeroPadded) {
    // A uniform bright image has no edges, including at its borders.
    ImageGray8 in(5, 5, 200);
    ImageGray8 edges;
    sobel_edges(in, 8.0f, edges, 1);
    for (int y = 0; y < 5; ++y)
        for (int x = 0; x < 5; ++x) EXPECT_EQ(edges(x, y), 255);
}

TEST(ClassicSobel, RgbMagnitudeSumsChannels) {
    // A one-level step in one channel: magnitude 4, not > 4. In two channels: sqrt(32) > 4.
    for (int channels : {1, 2}) {
        ImageRgb8 in(6, 3, Rgb8{10, 10, 10});
        for (int y = 0; y < 3; ++y)
            for (int x = 3; x < 6; ++x)
                for (int c = 0; c < channels; ++c) in(x, y)[c] = 11;
        ImageGray8 edges;
        sobel_edges(in, 4.0f, edges, 1);
        EXPECT_EQ(edges(2, 1), channels == 2 ? 0 : 255);
        EXPECT_EQ(edges(0, 1), 255);
    }
}

TEST(ClassicCompose, BinomialBlurOfOneEdgePixel) {
    Image<Vec3f> colour(5, 5, Vec3f(1.0f));
    ImageGray8 edges(5, 5, 255);
    edges(2, 2) = 0;
    ImageRgb8 out;
    compose_lines(colour, edges, out, 1);
    EXPECT_EQ(out(2, 2)[0], to_byte(12.0f / 16.0f));  // centre weight 4 missing
    EXPECT_EQ(out(2, 1)[0], to_byte(14.0f / 16.0f));  // edge-adjacent: weight 2
    EXPECT_EQ(out(1, 1)[0], to_byte(15.0f / 16.0f));  // diagonal: weight 1
    EXPECT_EQ(out(0, 0)[0], 255);
    EXPECT_EQ(to_byte(12.0f / 16.0f), 191);
}

TEST(ClassicCompose, CornerEdgeCountsClampedNeighbours) {
    Image<Vec3f> colour(4, 4, Vec3f(1.0f));
    ImageGray8 edges(4, 4, 255);
    edges(0, 0) = 0;
    ImageRgb8 out;
    compose_lines(colour, edges, out, 1);
    // At (0,0) the clamped reads of (-1,-1), (0,-1), (-1,0) and (0,0) all see the edge: 1+2+2+4.
    EXPECT_EQ(out(0, 0)[0], to_byte(7.0f / 16.0f));
    EXPECT_EQ(out(1, 0)[0], to_byte(13.0f / 16.0f));  // (0,-1) clamps to (0,0): 1 + 2
}

TEST(ClassicCompose, MultipliesTheColourAndRounds) {
    Image<Vec3f> colour(3, 3, Vec3f(0.2f, 0.4f, 0.6f));
    ImageGray8 edges(3, 3, 255);
    ImageRgb8 out;
    compose_lines(colour, edges, out, 1);
    EXPECT_EQ(out(1, 1), (Rgb8{51, 102, 153}));
}

TEST(MergeEdges, EitherImageMakesAnEdge) {
    ImageGray8 a(3, 1, 255), b(3, 1, 255), out;
    a(0, 0) = 0;
    b(2, 0) = 0;
    merge_edges(a, b, out);
    EXPECT_EQ(out(0, 0), 0);
    EXPECT_EQ(out(1, 0), 255);
    EXPECT_EQ(out(2, 0), 0);
}
