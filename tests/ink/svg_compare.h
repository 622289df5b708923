#pragma once
/// Ink lines drawn by a real SVG renderer (librsvg's rsvg-convert) against toonray's own
/// coverage: how many of each image's line pixels lie near a line pixel of the other.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "toonray/core/image.h"
#include "toonray/ink/svg.h"
#include "toonray/io/file.h"
#include "toonray/io/png.h"

namespace toonray::test_support {

inline void write_svg(const std::filesystem::path& path, std::span<const ink::Stroke> strokes,
                      const ink::SvgSettings& svg) {
    const std::string text = ink::svg_text(strokes, svg);
    write_file_atomic(path,
                      std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

/// Share of the line pixels of `a` within 1.5 px of a line pixel of `b` (its 8 neighbours).
inline double line_agreement(const std::vector<bool>& a, const std::vector<bool>& b, int w, int h) {
    long lines = 0, near = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (!a[static_cast<std::size_t>(y) * w + x]) continue;
            ++lines;
            bool found = false;
            for (int dy = -1; dy <= 1 && !found; ++dy)
                for (int dx = -1; dx <= 1 && !found; ++dx) {
                    const int nx = x + dx, ny = y + dy;
                    found = nx >= 0 && ny >= 0 && nx < w && ny < h &&
                            b[static_cast<std::size_t>(ny) * w + nx];
                }
            near += found;
        }
    return lines ? static_cast<double>(near) / static_cast<double>(lines) : 0.0;
}

/// How alike rsvg-convert's drawing of an SVG and toonray's coverage are: line pixels of each
/// (rsvg's darker than half, ours covered by more than half) and the share of each image's line
/// pixels within 1.5 px of a line pixel of the other.
struct RsvgAgreement {
    long ours = 0, theirs = 0;
    double ours_near_theirs = 0.0, theirs_near_ours = 0.0;
};

/// Writes the strokes as `dir/NAME.svg` with `svg` (whose size must be the coverage's), checks
/// that it parses as XML with the layers and subgroups and at least `min_paths` paths
/// (tests/ink/check_svg.py), draws it with rsvg-convert and measures it against `coverage`.
inline void measure_rsvg(std::span<const ink::Stroke> strokes, const ImageF& coverage,
                         const ink::SvgSettings& svg, const std::filesystem::path& dir,
                         const std::string& name, int min_paths, RsvgAgreement& out) {
    ASSERT_EQ(std::system("rsvg-convert --version > /dev/null 2>&1"), 0)
        << "rsvg-convert (Debian librsvg2-bin) is not installed: bash scripts/install-deps.sh all";
    const int w = coverage.width(), h = coverage.height();
    ASSERT_EQ(svg.width, w);
    ASSERT_EQ(svg.height, h);
    const std::filesystem::path svg_path = dir / (name + ".svg"), png_path = dir / (name + ".png");
    write_svg(svg_path, strokes, svg);
    const std::string check = std::string("python3 ") + TOONRAY_TESTS_DIR + "/ink/check_svg.py " +
                              svg_path.string() + " " + std::to_string(w) + " " +
                              std::to_string(h) + (svg.hidden ? " 1 " : " 0 ") +
                              std::to_string(min_paths);
    EXPECT_EQ(std::system(check.c_str()), 0) << check;
    const std::string convert =
        "rsvg-convert -b white -o " + png_path.string() + " " + svg_path.string();
    ASSERT_EQ(std::system(convert.c_str()), 0) << convert;
    const DecodedPng png = read_png(png_path);
    ASSERT_EQ(png.width, w);
    ASSERT_EQ(png.height, h);
    std::vector<bool> ours(static_cast<std::size_t>(w) * h), theirs(ours.size());
    out = {};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = static_cast<std::size_t>(y) * w + x;
            ours[i] = coverage(x, y) > 0.5f;
            theirs[i] = png.rgb(x, y)[0] < 128;
            out.ours += ours[i];
            out.theirs += theirs[i];
        }
    out.ours_near_theirs = line_agreement(ours, theirs, w, h);
    out.theirs_near_ours = line_agreement(theirs, ours, w, h);
}

/// Writes the visible strokes as `dir/NAME.svg` with group defaults only (one solid pen of
/// `thickness`), and expects rsvg-convert to draw at least 90% of each image's line pixels
/// within 1.5 px of the other's, and about as many (measure_rsvg).
inline void expect_rsvg_draws_like_coverage(std::span<const ink::Stroke> strokes,
                                            const ImageF& coverage, float thickness,
                                            const std::filesystem::path& dir,
                                            const std::string& name, long min_pixels) {
    ink::SvgSettings svg;
    svg.width = coverage.width();
    svg.height = coverage.height();
    svg.thickness = thickness;
    RsvgAgreement a;
    measure_rsvg(strokes, coverage, svg, dir, name, 10, a);
    EXPECT_GT(a.ours, min_pixels);
    EXPECT_NEAR(static_cast<double>(a.theirs) / static_cast<double>(a.ours), 1.0, 0.2);
    EXPECT_GE(a.ours_near_theirs, 0.9);
    EXPECT_GE(a.theirs_near_ours, 0.9);
}

}  // namespace toonray::test_support
