// The classic pipeline, step by step, against values worked out by hand from the issue's
// definitions.
#include "toonray/render/classic.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <random>
#include <utility>
#include <vector>

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
                EXPECT_EQ(edges(x, y), expect_edge ? 0 : 255)
                    << "step " << step << " at " << x << "," << y;
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

// ---------------------------------------------------------------------------------------------
// The row-based, vectorised stages against the seed's per-pixel definitions, written out plainly
// here (float arithmetic, clamped reads, lroundf), on random images of awkward sizes.

namespace {

int clamp_index(int v, int n) { return v < 0 ? 0 : (v >= n ? n - 1 : v); }

template <typename At>
void reference_sobel_at(const At& at, int x, int y, int w, int h, float& gx, float& gy) {
    int x0 = clamp_index(x - 1, w), x2 = clamp_index(x + 1, w);
    int y0 = clamp_index(y - 1, h), y2 = clamp_index(y + 1, h);
    float a = at(x0, y0), b = at(x, y0), c = at(x2, y0), d = at(x0, y), f = at(x2, y);
    float g = at(x0, y2), hh = at(x, y2), i = at(x2, y2);
    gx = (c + 2 * f + i) - (a + 2 * d + g);
    gy = (g + 2 * hh + i) - (a + 2 * b + c);
}

ImageGray8 reference_sobel(const ImageGray8& in, float threshold) {
    ImageGray8 out(in.width(), in.height());
    auto at = [&](int x, int y) { return static_cast<float>(in(x, y)); };
    for (int y = 0; y < in.height(); ++y)
        for (int x = 0; x < in.width(); ++x) {
            float gx, gy;
            reference_sobel_at(at, x, y, in.width(), in.height(), gx, gy);
            out(x, y) = (threshold < 0.0f || gx * gx + gy * gy > threshold * threshold) ? 0 : 255;
        }
    return out;
}

ImageGray8 reference_sobel(const ImageRgb8& in, float threshold) {
    ImageGray8 out(in.width(), in.height());
    for (int y = 0; y < in.height(); ++y)
        for (int x = 0; x < in.width(); ++x) {
            float sum = 0.0f;
            for (int c = 0; c < 3; ++c) {
                auto at = [&](int xx, int yy) { return static_cast<float>(in(xx, yy)[c]); };
                float gx, gy;
                reference_sobel_at(at, x, y, in.width(), in.height(), gx, gy);
                sum += gx * gx + gy * gy;
            }
            out(x, y) = (threshold < 0.0f || sum > threshold * threshold) ? 0 : 255;
        }
    return out;
}

ImageRgb8 reference_compose(const Image<Vec3f>& colour, const ImageGray8& edges) {
    const int w = colour.width(), h = colour.height();
    ImageRgb8 out(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            int sum = 0;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx)
                    // (2 - |dx|)(2 - |dy|) is 1, 2 or 4: the [1 2 1] x [1 2 1] kernel.
                    sum += (2 - std::abs(dx)) * (2 - std::abs(dy)) *
                           (edges(clamp_index(x + dx, w), clamp_index(y + dy, h)) ? 1 : 0);
            float k = static_cast<float>(sum) / 16.0f;
            const Vec3f& c = colour(x, y);
            out(x, y) = {to_byte(c.x * k), to_byte(c.y * k), to_byte(c.z * k)};
        }
    return out;
}

template <typename T>
bool same(const Image<T>& a, const Image<T>& b) {
    if (a.width() != b.width() || a.height() != b.height()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (!(a.data()[i] == b.data()[i])) return false;
    return true;
}

}  // namespace

TEST(ClassicRounding, RoundHalfAwayIsLroundf) {
    std::vector<float> values;
    for (int k = -600; k <= 600; ++k) {
        float half = static_cast<float>(k) * 0.5f;  // every half and whole number
        values.insert(values.end(),
                      {half, std::nextafter(half, -1e9f), std::nextafter(half, 1e9f)});
    }
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> any(-300.0f, 300.0f);
    for (int i = 0; i < 100000; ++i) values.push_back(any(rng));
    values.insert(values.end(), {0.49999997f, -0.49999997f, -0.0f, 8388607.5f, -8388607.5f});
    for (float v : values) EXPECT_EQ(round_half_away(v), std::lround(v)) << v;
}

TEST(ClassicDepthMap, LargestFiniteIgnoresMissesAndNan) {
    const float inf = std::numeric_limits<float>::infinity();
    ImageF d(7, 1, inf);
    EXPECT_EQ(largest_finite(d), 0.0f);
    d(0, 0) = std::nanf("");
    d(1, 0) = -inf;
    d(2, 0) = 3.0f;
    d(6, 0) = 5.5f;  // in the scalar tail after the four-wide loop
    EXPECT_EQ(largest_finite(d), 5.5f);
}

TEST(ClassicDepthMap, HitsAtDistanceZeroAreBlack) {
    // t_max = 0: every hit maps to 0 and misses stay white.
    ImageF d(2, 1, 0.0f);
    d(1, 0) = std::numeric_limits<float>::infinity();
    ImageGray8 out;
    classic_depth_map(d, out, 1);
    EXPECT_EQ(out(0, 0), 0);
    EXPECT_EQ(out(1, 0), 255);
}

TEST(ClassicSobel, NegativeThresholdMarksEverythingNanNothing) {
    ImageGray8 in(4, 3, 50);
    ImageGray8 edges;
    sobel_edges(in, -1.0f, edges, 1);
    for (std::size_t i = 0; i < edges.size(); ++i) EXPECT_EQ(edges.data()[i], 0);
    in(1, 1) = 255;
    sobel_edges(in, std::nanf(""), edges, 1);
    for (std::size_t i = 0; i < edges.size(); ++i) EXPECT_EQ(edges.data()[i], 255);
}

TEST(ClassicStages, MatchTheSeedsPerPixelDefinitionsOnRandomImages) {
    std::mt19937 rng(11);
    std::uniform_int_distribution<int> byte(0, 255);
    std::uniform_real_distribution<float> unit(-0.2f, 1.2f);
    // Sizes with one-pixel borders, odd widths and lengths around the vector widths.
    for (auto [w, h] : {std::pair{1, 1}, {1, 5}, {6, 1}, {2, 2}, {17, 9}, {33, 16}, {67, 31}}) {
        ImageGray8 gray(w, h);
        ImageRgb8 rgb(w, h);
        Image<Vec3f> colour(w, h);
        ImageGray8 flags(w, h);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                // Smooth-ish values so both sides of the thresholds occur.
                gray(x, y) = static_cast<std::uint8_t>(byte(rng) / 16 + 8 * x);
                rgb(x, y) = {static_cast<std::uint8_t>(byte(rng) / 32),
                             static_cast<std::uint8_t>(4 * y),
                             static_cast<std::uint8_t>(byte(rng))};
                colour(x, y) = {unit(rng), unit(rng), unit(rng)};
                flags(x, y) = byte(rng) < 40 ? 0 : 255;
            }
        for (float threshold : {-1.0f, 0.0f, 4.0f, 8.0f, 8.5f, 100.0f}) {
            for (int threads : {1, 2}) {
                ImageGray8 edges;
                sobel_edges(gray, threshold, edges, threads);
                EXPECT_TRUE(same(edges, reference_sobel(gray, threshold)))
                    << w << "x" << h << " t " << threshold;
                sobel_edges(rgb, threshold, edges, threads);
                EXPECT_TRUE(same(edges, reference_sobel(rgb, threshold)))
                    << w << "x" << h << " t " << threshold;
            }
        }
        ImageRgb8 out, out_with_cel, cel;
        compose_lines(colour, flags, out, 1);
        compose_lines(colour, flags, out_with_cel, 2, &cel);
        EXPECT_TRUE(same(out, reference_compose(colour, flags))) << w << "x" << h;
        EXPECT_TRUE(same(out, out_with_cel));
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const Vec3f& c = colour(x, y);
                EXPECT_EQ(cel(x, y), (Rgb8{to_byte(c.x), to_byte(c.y), to_byte(c.z)}));
            }
    }
}

TEST(ClassicNormalMap, EveryChannelRoundsAsLroundf) {
    // Values whose scaled form lands on and next to halves, in the flat vectorised loop.
    Image<Vec3f> n(40, 1);
    ImageF d(40, 1, 1.0f);
    for (int x = 0; x < 40; ++x) {
        float v = -1.0f + static_cast<float>(x) / 19.5f;
        n(x, 0) = {v, std::nextafter(v, 2.0f), std::nextafter(v, -2.0f)};
    }
    d(5, 0) = std::numeric_limits<float>::infinity();
    ImageRgb8 out;
    classic_normal_map(n, d, out, 1);
    for (int x = 0; x < 40; ++x) {
        if (x == 5) {
            EXPECT_EQ(out(x, 0), (Rgb8{0, 0, 0}));
            continue;
        }
        for (int c = 0; c < 3; ++c)
            EXPECT_EQ(out(x, 0)[c],
                      static_cast<std::uint8_t>(std::lround((n(x, 0)[c] * 0.5f + 0.5f) * 255.0f)))
                << x << " " << c;
    }
}
