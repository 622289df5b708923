#include "toonray/ink/draw.h"

#include <algorithm>
#include <cmath>

#include "toonray/core/parallel.h"

namespace toonray::ink {

namespace {

constexpr int kBandRows = 16;

struct Segment2 {
    Point2 a, b;
    int x0, x1, y0, y1;  // pixels whose centres may be covered, inclusive, clamped to the image
};

std::uint8_t to_byte(float v) {
    return static_cast<std::uint8_t>(std::min(std::max(v, 0.0f), 1.0f) * 255.0f + 0.5f);
}

}  // namespace

float stroke_thickness(float width, int height) {
    return width * static_cast<float>(height) / 720.0f;
}

void draw_strokes(std::span<const Stroke> strokes, float thickness, ImageF& coverage, int threads) {
    const int w = coverage.width(), h = coverage.height();
    if (w <= 0 || h <= 0 || !(thickness > 0.0f)) return;
    const float reach = thickness * 0.5f + 0.5f;
    // Every segment of every stroke with the pixels it can reach, listed per band of rows.
    std::vector<Segment2> segments;
    for (const Stroke& s : strokes)
        for (std::size_t i = 0; i + 1 < s.points.size(); ++i) {
            const Point2 a = s.points[i], b = s.points[i + 1];
            // Pixel x has its centre at x + 0.5; it can be covered if within reach of the box.
            const float lx = std::min(a.x, b.x) - reach, hx = std::max(a.x, b.x) + reach;
            const float ly = std::min(a.y, b.y) - reach, hy = std::max(a.y, b.y) + reach;
            if (!(hx >= 0.5f && lx <= w - 0.5f && hy >= 0.5f && ly <= h - 0.5f))
                continue;  // also NaN
            Segment2 seg{a,
                         b,
                         std::max(0, static_cast<int>(std::ceil(lx - 0.5f))),
                         std::min(w - 1, static_cast<int>(std::floor(hx - 0.5f))),
                         std::max(0, static_cast<int>(std::ceil(ly - 0.5f))),
                         std::min(h - 1, static_cast<int>(std::floor(hy - 0.5f)))};
            if (seg.x0 <= seg.x1 && seg.y0 <= seg.y1) segments.push_back(seg);
        }
    const int bands = (h + kBandRows - 1) / kBandRows;
    std::vector<std::vector<std::uint32_t>> in_band(static_cast<std::size_t>(bands));
    for (std::size_t i = 0; i < segments.size(); ++i)
        for (int b = segments[i].y0 / kBandRows; b <= segments[i].y1 / kBandRows; ++b)
            in_band[static_cast<std::size_t>(b)].push_back(static_cast<std::uint32_t>(i));
    parallel_for(bands, 1, threads, [&](int b0, int b1) {
        for (int band = b0; band < b1; ++band) {
            const int row0 = band * kBandRows, row1 = std::min(h, row0 + kBandRows) - 1;
            for (std::uint32_t index : in_band[static_cast<std::size_t>(band)]) {
                const Segment2& s = segments[index];
                const float dx = s.b.x - s.a.x, dy = s.b.y - s.a.y;
                const float len2 = dx * dx + dy * dy;
                const float inv_len2 = len2 > 0.0f ? 1.0f / len2 : 0.0f;
                for (int y = std::max(s.y0, row0); y <= std::min(s.y1, row1); ++y) {
                    float* row = coverage.row(y);
                    const float py = static_cast<float>(y) + 0.5f - s.a.y;
                    for (int x = s.x0; x <= s.x1; ++x) {
                        const float px = static_cast<float>(x) + 0.5f - s.a.x;
                        // Distance to the segment: to its nearest point, ends included (round caps).
                        const float t = std::clamp((px * dx + py * dy) * inv_len2, 0.0f, 1.0f);
                        const float ex = px - dx * t, ey = py - dy * t;
                        const float c = std::min(1.0f, reach - std::sqrt(ex * ex + ey * ey));
                        if (c > row[x]) row[x] = c;
                    }
                }
            }
        }
    });
}

void composite_lines(const ImageF& coverage, const Vec3f& colour, ImageRgb8& image) {
    for (int y = 0; y < image.height(); ++y) {
        const float* cov = coverage.row(y);
        Rgb8* px = image.row(y);
        for (int x = 0; x < image.width(); ++x) {
            const float a = cov[x];
            if (!(a > 0.0f)) continue;
            for (int c = 0; c < 3; ++c)
                px[x][c] = to_byte(static_cast<float>(px[x][c]) * (1.0f / 255.0f) * (1.0f - a) +
                                   colour[c] * a);
        }
    }
}

void coverage_to_gray(const ImageF& coverage, ImageGray8& out) {
    out.reshape(coverage.width(), coverage.height());
    for (std::size_t i = 0; i < coverage.size(); ++i)
        out.data()[i] = to_byte(1.0f - coverage.data()[i]);
}

}  // namespace toonray::ink
