// Tone looks (ink/tone.h): hatching and screentone drawn as ink over every band's full colour.
// The measures of docs/looks.md: the tone's darkness per band, its anchoring under a camera pan,
// the refined share against cel, and the parts they rest on.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "ink/ink_scenes.h"
#include "support/test_scenes.h"
#include "toonray/ink/tone.h"
#include "toonray/render/renderer.h"

using namespace toonray;

namespace {

// A smooth unit sphere at the origin (64 x 128 quads), seen from +z.
Scene lit_sphere() {
    Scene s;
    test_support::add_sphere(s, Vec3f(0.0f), 1.0f, 64, 128);
    return s;
}

const CameraSpec kSphereCamera{{0, 0, 4}, {0, 0, 0}, {0, 1, 0}};
// From the left, a little above and in front: the terminator crosses the sphere's middle, so
// every band of the seed's ramp shows.
const std::vector<Light> kSideLight{{Light::Kind::Directional, {1.0f, -0.3f, -0.4f}, 1.0f}};

struct Frame {
    Renderer renderer;
    TriangleAccel accel;
    const FrameLayers& render(const Scene& s, const CameraSpec& camera,
                              const std::vector<Light>& lights, RenderSettings settings) {
        accel.build(s.positions, s.tri_positions);
        settings.layers = true;
        renderer.render(s, accel, camera, lights, settings);
        return renderer.layers();
    }
};

RenderSettings tone_settings(ink::ToneMode mode, int width, int height) {
    RenderSettings settings;
    settings.width = width;
    settings.height = height;
    settings.tone.mode = mode;
    return settings;
}

// The mean of the tone coverage blurred by a box `side` pixels wide, per band, over the pixels
// whose whole box lies in that band (a box across two bands measures neither); -1 for a band
// with fewer than `min_pixels` such pixels.
std::vector<double> blurred_tone_by_band(const FrameLayers& l, int side, int bands,
                                         long min_pixels) {
    const int w = l.tone.width(), h = l.tone.height();
    // Summed-area tables of the coverage and of each band's pixels.
    auto at = [w](int x, int y) { return static_cast<std::size_t>(y) * (w + 1) + x; };
    std::vector<double> cov(static_cast<std::size_t>(w + 1) * (h + 1), 0.0);
    std::vector<std::vector<int>> in(bands, std::vector<int>(cov.size(), 0));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            cov[at(x + 1, y + 1)] =
                l.tone(x, y) + cov[at(x, y + 1)] + cov[at(x + 1, y)] - cov[at(x, y)];
            for (int b = 0; b < bands; ++b)
                in[b][at(x + 1, y + 1)] = (l.band(x, y) == b ? 1 : 0) + in[b][at(x, y + 1)] +
                                          in[b][at(x + 1, y)] - in[b][at(x, y)];
        }
    std::vector<double> sum(bands, 0.0);
    std::vector<long> count(bands, 0);
    const int r = side / 2;
    for (int y = r; y + side - r <= h; ++y)
        for (int x = r; x + side - r <= w; ++x) {
            const int x0 = x - r, y0 = y - r, x1 = x0 + side, y1 = y0 + side;
            const double box =
                cov[at(x1, y1)] - cov[at(x0, y1)] - cov[at(x1, y0)] + cov[at(x0, y0)];
            for (int b = 0; b < bands; ++b) {
                const int n =
                    in[b][at(x1, y1)] - in[b][at(x0, y1)] - in[b][at(x1, y0)] + in[b][at(x0, y0)];
                if (n != side * side) continue;
                sum[b] += box / (side * side);
                ++count[b];
            }
        }
    std::vector<double> mean(bands, -1.0);
    for (int b = 0; b < bands; ++b)
        if (count[b] >= min_pixels) mean[b] = sum[b] / count[b];
    return mean;
}

// Expects the blurred tone of each band shown to be within 0.05 of 1 - L and to grow band by
// band (darker bands first in the seed's ramp); prints the figures.
void expect_tone_reproduced(const FrameLayers& l, const RenderSettings& settings,
                            const char* what) {
    const ToonRamp& ramp = settings.shading.ramp;
    const int spacing =
        static_cast<int>(std::lround(settings.tone.spacing * settings.height / 720.0f));
    const std::vector<double> mean =
        blurred_tone_by_band(l, 2 * spacing, static_cast<int>(ramp.levels.size()), 2000);
    int shown = 0;
    double previous = 2.0;
    for (std::size_t b = 0; b < mean.size(); ++b) {
        const double target = 1.0 - ramp.levels[b];
        std::printf("%s: band %zu (level %.2f): tone %.4f, target %.4f\n", what, b, ramp.levels[b],
                    mean[b], target);
        if (mean[b] < 0.0) continue;
        ++shown;
        EXPECT_NEAR(mean[b], target, 0.05) << what << " band " << b;
        // Bands are listed darkest first: the tone falls band by band.
        EXPECT_LT(mean[b], previous) << what << " band " << b;
        previous = mean[b];
    }
    EXPECT_GE(shown, 2) << what << ": too few bands shown to measure";
}

}  // namespace

TEST(Tone, SharesCoverTheDarknessAndNest) {
    // One family covers width / spacing at most; the next starts where it is full.
    for (float coverage : {0.2f, 1.0f / 3.0f, 0.5f}) {
        std::array<float, ink::kHatchFamilies> before{};
        for (int i = 0; i <= 100; ++i) {
            const float d = static_cast<float>(i) / 100.0f;
            const auto share = ink::hatch_shares(d, coverage, 1.0f);
            double left = 1.0;
            for (float f : share) {
                EXPECT_GE(f, 0.0f);
                EXPECT_LE(f, 1.0f + 1e-6f);
                left *= 1.0 - f * coverage;
            }
            // Four families reach 1 - (1 - coverage)^4.
            EXPECT_NEAR(1.0 - left, std::min<double>(d, 1.0 - std::pow(1.0 - coverage, 4)), 1e-5);
            for (int k = 0; k < ink::kHatchFamilies; ++k) {
                EXPECT_GE(share[k], before[k]) << "darker tones keep the lighter ones' strokes";
                if (k > 0 && share[k] > 0.0f) {
                    EXPECT_FLOAT_EQ(share[k - 1], 1.0f);
                }
            }
            before = share;
        }
    }
    // Opacity: half-opaque ink needs twice the coverage.
    EXPECT_FLOAT_EQ(ink::hatch_shares(0.1f, 0.5f, 0.5f)[0], 0.4f);
}

TEST(Tone, PlaneRanksHalveWithTheirPlanes) {
    // r(2K) = r(K) / 2: the strokes of a family do not depend on its plane spacing.
    for (std::int64_t k : {1, 2, 3, 5, 6, 7, 12, 1001, -1, -6, 123456789}) {
        EXPECT_EQ(ink::plane_rank(2 * k), ink::plane_rank(k) / 2) << k;
        EXPECT_GE(ink::plane_rank(k), 0.0);
        EXPECT_LT(ink::plane_rank(k), 1.0);
    }
    EXPECT_EQ(ink::plane_rank(0), 0.0);
    EXPECT_EQ(ink::plane_rank(1), 0.5);
    EXPECT_EQ(ink::plane_rank(2), 0.25);
    EXPECT_EQ(ink::plane_rank(3), 0.75);
    EXPECT_EQ(ink::plane_rank(-3), 0.75);
}

TEST(Tone, DrawnDiscRadiusCoversItsArea) {
    // Sum the drawing's coverage rule over a fine grid around a disc centred anywhere.
    for (float area : {0.3f, 2.0f, 9.0f, 40.0f}) {
        const float r = ink::drawn_disc_radius(area);
        double total = 0.0;
        const int n = 200;  // samples per pixel side
        for (int y = -12 * n; y < 12 * n; ++y)
            for (int x = -12 * n; x < 12 * n; ++x) {
                const double d = std::hypot((x + 0.5) / n, (y + 0.5) / n);
                total += std::clamp(r + 0.5 - d, 0.0, 1.0) / (n * n);
            }
        EXPECT_NEAR(total, area, area * 0.002 + 0.002) << area;
    }
}

TEST(Tone, ParsesAndFormatsItsSettings) {
    using Kind = ink::HatchDirection::Kind;
    for (auto mode : {ink::ToneMode::Cel, ink::ToneMode::Hatch, ink::ToneMode::Screentone})
        EXPECT_EQ(ink::parse_tone_mode(ink::tone_mode_name(mode)), mode);
    EXPECT_THROW(static_cast<void>(ink::parse_tone_mode("halftone")), Error);
    EXPECT_EQ(ink::parse_tone_anchor("screen"), ink::ToneAnchor::Screen);
    EXPECT_THROW(static_cast<void>(ink::parse_tone_anchor("world")), Error);
    for (const char* text : {"curvature", "light", "screen", "x", "y", "z", "1,2,3", "0,0,-2"}) {
        const ink::HatchDirection d = ink::parse_hatch_direction(text);
        EXPECT_EQ(ink::parse_hatch_direction(ink::format_hatch_direction(d)), d) << text;
    }
    EXPECT_EQ(ink::parse_hatch_direction("0,0,-2").kind, Kind::Axis);
    EXPECT_EQ(ink::parse_hatch_direction("0,0,-2").axis, Vec3f(0, 0, -2));
    EXPECT_THROW(static_cast<void>(ink::parse_hatch_direction("0,0,0")), Error);
    EXPECT_THROW(static_cast<void>(ink::parse_hatch_direction("up")), Error);
    EXPECT_THROW(static_cast<void>(ink::parse_hatch_direction("1,nan,0")), Error);
    // Hatching is object-anchored by default, screentone screen-locked.
    ink::ToneSettings t;
    t.mode = ink::ToneMode::Hatch;
    EXPECT_EQ(t.anchored(), ink::ToneAnchor::Object);
    t.mode = ink::ToneMode::Screentone;
    EXPECT_EQ(t.anchored(), ink::ToneAnchor::Screen);
    t.anchor = ink::ToneAnchor::Object;
    EXPECT_EQ(t.anchored(), ink::ToneAnchor::Object);
}

TEST(Tone, HatchReproducesTheBandsOnALitSphere) {
    const Scene s = lit_sphere();
    for (auto anchor : {ink::ToneAnchor::Object, ink::ToneAnchor::Screen}) {
        RenderSettings settings = tone_settings(ink::ToneMode::Hatch, 960, 540);
        settings.tone.anchor = anchor;
        Frame f;
        const FrameLayers& l = f.render(s, kSphereCamera, kSideLight, settings);
        expect_tone_reproduced(
            l, settings,
            anchor == ink::ToneAnchor::Object ? "hatch sphere" : "hatch sphere, screen");
    }
}

TEST(Tone, ScreentoneReproducesTheBandsOnALitSphere) {
    const Scene s = lit_sphere();
    for (auto anchor : {ink::ToneAnchor::Screen, ink::ToneAnchor::Object}) {
        RenderSettings settings = tone_settings(ink::ToneMode::Screentone, 960, 540);
        settings.tone.anchor = anchor;
        Frame f;
        const FrameLayers& l = f.render(s, kSphereCamera, kSideLight, settings);
        expect_tone_reproduced(
            l, settings,
            anchor == ink::ToneAnchor::Screen ? "screentone sphere" : "screentone sphere, object");
    }
}

TEST(Tone, HatchAndScreentoneReproduceTheBandsOnSpot) {
    const Scene s = test_support::load_test_scene("spot.obj");
    for (auto mode : {ink::ToneMode::Hatch, ink::ToneMode::Screentone}) {
        RenderSettings settings = tone_settings(mode, 960, 540);
        const CameraSpec camera = test_support::framing_camera(s, settings.width, settings.height);
        Frame f;
        const FrameLayers& l = f.render(s, camera, kSideLight, settings);
        expect_tone_reproduced(l, settings,
                               mode == ink::ToneMode::Hatch ? "hatch spot" : "screentone spot");
    }
}

namespace {

// A 2 x 2 square in the plane z = 0 facing +z, lit at a grazing angle from the right: all of
// it in the darkest band of the seed's ramp.
Scene dark_square() {
    Scene s;
    s.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    s.add_triangle({0, 1, 2}, 0, 0);
    s.add_triangle({0, 2, 3}, 0, 0);
    return s;
}
const std::vector<Light> kGrazingLight{{Light::Kind::Directional, {-1.0f, 0.0f, -0.2f}, 1.0f}};

// The shift (pixels, along x) that best maps `a` onto `b` over the columns [x0, x1) and rows
// [y0, y1) of `a`: the peak of their cross-correlation over whole pixels, refined by a parabola
// through it and its neighbours.
double correlation_shift(const ImageF& a, const ImageF& b, int x0, int x1, int y0, int y1,
                         int reach) {
    auto correlation = [&](int s) {
        double sum = 0.0;
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) sum += static_cast<double>(a(x, y)) * b(x + s, y);
        return sum;
    };
    int best = -reach;
    std::vector<double> c(2 * reach + 1);
    for (int s = -reach; s <= reach; ++s) {
        c[s + reach] = correlation(s);
        if (c[s + reach] > c[best + reach]) best = s;
    }
    if (best == -reach || best == reach) return best;
    const double l = c[best + reach - 1], m = c[best + reach], r = c[best + reach + 1];
    const double denominator = l - 2.0 * m + r;
    return best + (denominator != 0.0 ? 0.5 * (l - r) / denominator : 0.0);
}

}  // namespace

TEST(Tone, ScreentoneDotsCoverTheirCellsDarknessWithinThreePercent) {
    // Screen-locked cells 8 pixels wide on the pixel grid: at 720 lines the spacing is in
    // pixels, rows at 0 degrees, and the cells are centred on the image's centre (480, 360).
    const Scene s = lit_sphere();
    RenderSettings settings = tone_settings(ink::ToneMode::Screentone, 960, 720);
    settings.tone.spacing = 8.0f;
    settings.tone.angle = 0.0f;
    Frame f;
    const FrameLayers& l = f.render(s, kSphereCamera, kSideLight, settings);
    const ToonRamp& ramp = settings.shading.ramp;
    const int g = 8, x_first = 480 - g / 2 - g * (480 / g - 1),
              y_first = 360 - g / 2 - g * (360 / g - 1);
    std::vector<int> cells(ramp.levels.size(), 0);
    double worst = 0.0;
    // From the second cell: every cell looked at has its neighbours in the image.
    for (int y0 = y_first + g; y0 + 2 * g <= l.tone.height(); y0 += g)
        for (int x0 = x_first + g; x0 + 2 * g <= l.tone.width(); x0 += g) {
            // A cell whose neighbours are in its band too: the dots that spill into it are as
            // large as its own spills out.
            const int band = l.band(x0, y0);
            bool uniform = l.object(x0, y0) != kNoIndex;
            for (int y = y0 - g; uniform && y < y0 + 2 * g; ++y)
                for (int x = x0 - g; uniform && x < x0 + 2 * g; ++x)
                    uniform = l.band(x, y) == band && l.object(x, y) != kNoIndex;
            if (!uniform) continue;
            double sum = 0.0;
            for (int y = y0; y < y0 + g; ++y)
                for (int x = x0; x < x0 + g; ++x) sum += l.tone(x, y);
            const double darkness = 1.0 - ramp.levels[static_cast<std::size_t>(band)];
            const double error = std::abs(sum / (g * g) - darkness);
            EXPECT_LE(error, 0.03 * std::max(darkness, 0.01))
                << "cell at " << x0 << "," << y0 << " band " << band;
            if (darkness > 0.0) worst = std::max(worst, error / darkness);
            ++cells[static_cast<std::size_t>(band)];
        }
    int bands = 0;
    for (std::size_t b = 0; b < cells.size(); ++b) {
        std::printf("screentone cells: band %zu (darkness %.2f): %d cells\n", b,
                    1.0 - ramp.levels[b], cells[b]);
        bands += cells[b] >= 20 ? 1 : 0;
    }
    std::printf("screentone cells: the worst is %.2f%% from its darkness\n", 100.0 * worst);
    EXPECT_GE(bands, 3) << "too few bands with whole cells to measure";
}

TEST(Tone, ObjectAnchoredHatchingMovesWithTheGeometryAndScreenAnchoredStaysPut) {
    // The camera pans along x by `pan` world units: the square, all at one depth, moves on the
    // image by the same number of pixels everywhere, which its projection gives exactly.
    const Scene s = dark_square();
    const int w = 640, h = 480;
    const float pan = 0.03f;
    const CameraSpec before{{0, 0, 3}, {0, 0, 0}, {0, 1, 0}};
    const CameraSpec after{{pan, 0, 3}, {pan, 0, 0}, {0, 1, 0}};
    const ink::ScreenProjection p0(make_view_plane(before, w, h), w, h),
        p1(make_view_plane(after, w, h), w, h);
    const double geometry = p1.project({0, 0, 0}).x - p0.project({0, 0, 0}).x;
    ASSERT_LT(geometry, -5.0);  // a shift of several pixels to the left
    for (auto mode : {ink::ToneMode::Hatch, ink::ToneMode::Screentone})
        for (auto anchor : {ink::ToneAnchor::Object, ink::ToneAnchor::Screen}) {
            RenderSettings settings = tone_settings(mode, w, h);
            settings.tone.anchor = anchor;
            // Diagonal strokes: a shift along x moves them across themselves.
            settings.tone.direction = ink::parse_hatch_direction("1,1,0");
            settings.tone.angle = 30.0f;
            Frame f0, f1;
            const ImageF a = f0.render(s, before, kGrazingLight, settings).tone;
            const ImageF b = f1.render(s, after, kGrazingLight, settings).tone;
            // The middle of the square in the first frame, clear of its edges in both.
            const auto lo = p0.project({-0.6f, 0.6f, 0.0f}), hi = p0.project({0.6f, -0.6f, 0.0f});
            const double shift =
                correlation_shift(a, b, static_cast<int>(lo.x), static_cast<int>(hi.x),
                                  static_cast<int>(lo.y), static_cast<int>(hi.y), 16);
            const double expected = anchor == ink::ToneAnchor::Object ? geometry : 0.0;
            std::printf("%s, %s anchor: tone shifts %.3f px, geometry %.3f px\n",
                        std::string(ink::tone_mode_name(mode)).c_str(),
                        std::string(ink::tone_anchor_name(anchor)).c_str(), shift, geometry);
            EXPECT_NEAR(shift, expected, 0.5)
                << ink::tone_mode_name(mode) << " " << ink::tone_anchor_name(anchor);
        }
}

TEST(Tone, AdaptiveSamplingRefinesNoMoreThanCel) {
    // The tone is ink over colours that do not change between bands: refinement sees the same
    // surfaces as cel does and no pattern.
    const Scene s = lit_sphere();
    double cel_share = 0.0;
    for (auto mode : {ink::ToneMode::Cel, ink::ToneMode::Hatch, ink::ToneMode::Screentone}) {
        RenderSettings settings = tone_settings(mode, 960, 540);
        Renderer r;
        TriangleAccel accel;
        accel.build(s.positions, s.tri_positions);
        r.render(s, accel, kSphereCamera, kSideLight, settings);
        const double share = static_cast<double>(r.refined_pixels()) /
                             (static_cast<double>(settings.width) * settings.height);
        std::printf("%s: %.3f%% of pixels refined\n",
                    std::string(ink::tone_mode_name(mode)).c_str(), 100.0 * share);
        if (mode == ink::ToneMode::Cel) {
            cel_share = share;
        } else {
            EXPECT_LE(share, cel_share * 1.05 + 1e-4) << ink::tone_mode_name(mode);
        }
        EXPECT_LT(share, 0.05);
    }
}

TEST(Tone, CelFramesDoNotChangeWithToneSettingsTheyDoNotUse) {
    // The tone's own settings do nothing under the cel look.
    const Scene s = lit_sphere();
    RenderSettings a = tone_settings(ink::ToneMode::Cel, 320, 180), b = a;
    b.tone.spacing = 3.0f;
    b.tone.angle = 10.0f;
    b.tone.anchor = ink::ToneAnchor::Screen;
    Frame fa, fb;
    const ImageRgb8 ia = fa.render(s, kSphereCamera, kSideLight, a).image;
    const ImageRgb8 ib = fb.render(s, kSphereCamera, kSideLight, b).image;
    ASSERT_EQ(ia.size(), ib.size());
    EXPECT_TRUE(std::equal(ia.data(), ia.data() + ia.size(), ib.data()));
}
