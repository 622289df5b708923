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

/// Writes the visible strokes as `dir/NAME.svg`, checks that it parses as XML with the visible
/// layer and its subgroups (tests/ink/check_svg.py), draws it with rsvg-convert and expects at
/// least 90% of each image's line pixels within 1.5 px of the other's, and about as many.
inline void expect_rsvg_draws_like_coverage(std::span<const ink::Stroke> strokes,
                                            const ImageF& coverage, float thickness,
                                            const std::filesystem::path& dir,
                                            const std::string& name, long min_pixels) {
    ASSERT_EQ(std::system("rsvg-convert --version > /dev/null 2>&1"), 0)
        << "rsvg-convert (Debian librsvg2-bin) is not installed: bash scripts/install-deps.sh all";
    const int w = coverage.width(), h = coverage.height();
    ink::SvgSettings svg;
    svg.width = w;
    svg.height = h;
    svg.thickness = thickness;
    const std::filesystem::path svg_path = dir / (name + ".svg"), png_path = dir / (name + ".png");
    write_svg(svg_path, strokes, svg);
    const std::string check = std::string("python3 ") + TOONRAY_TESTS_DIR + "/ink/check_svg.py " +
                              svg_path.string() + " " + std::to_string(w) + " " +
                              std::to_string(h) + " 0 10";
    EXPECT_EQ(std::system(check.c_str()), 0) << check;
    const std::string convert =
        "rsvg-convert -b white -o " + png_path.string() + " " + svg_path.string();
    ASSERT_EQ(std::system(convert.c_str()), 0) << convert;
    const DecodedPng png = read_png(png_path);
    ASSERT_EQ(png.width, w);
    ASSERT_EQ(png.height, h);
    std::vector<bool> ours(static_cast<std::size_t>(w) * h), theirs(ours.size());
    long ours_count = 0, theirs_count = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = static_cast<std::size_t>(y) * w + x;
            ours[i] = coverage(x, y) > 0.5f;
            theirs[i] = png.rgb(x, y)[0] < 128;
            ours_count += ours[i];
            theirs_count += theirs[i];
        }
    EXPECT_GT(ours_count, min_pixels);
    EXPECT_NEAR(static_cast<double>(theirs_count) / static_cast<double>(ours_count), 1.0, 0.2);
    EXPECT_GE(line_agreement(ours, theirs, w, h), 0.9);
    EXPECT_GE(line_agreement(theirs, ours, w, h), 0.9);
}

}  // namespace toonray::test_support
