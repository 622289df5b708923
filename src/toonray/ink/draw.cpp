#include "toonray/ink/draw.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

#include "toonray/core/error.h"
#include "toonray/core/parallel.h"
#include "toonray/core/portable_math.h"
#include "toonray/ink/tone.h"

namespace toonray::ink {

namespace {

constexpr int kBandRows = 16;

struct Segment2 {
    Point2 a, b;
    int x0, x1, y0, y1;  // pixels whose centres may be covered, inclusive, clamped to the image
    float reach;         // half the thickness + 0.5: coverage is reach - distance
    float max_reach;     // the largest reach anywhere on the segment (width by depth)
    std::uint16_t style;
    float arc0 = 0;                  // arc length of the stroke at a (dashes, taper)
    const StrokePen* pen = nullptr;  // set for strokes whose coverage is shaped only
    float stroke_length = 0;         // -1 for a closed stroke: no ends to taper
    float total = 0;                 // the stroke's length (pressure, brushes)
    float nib = 1;                   // the broad nib's factor on this segment
    float d0 = 0, d1 = 0;            // depths at a and b (width by depth)
};

constexpr float kMinDepthScale = 0.25f, kMaxDepthScale = 2.0f;

// Every segment of every stroke with the pixels it can reach.
void add_stroke_segments(const Stroke& s, float thickness, std::uint16_t style,
                         const StrokePen* pen, int w, int h, std::vector<Segment2>& out) {
    const float reach = thickness * 0.5f + 0.5f;
    const float total = pen ? polyline_length(s.points) : 0.0f;
    const bool by_depth = pen && scales_by_depth(*pen, s);
    // The largest pressure reaches farthest.
    float most = 1.0f;
    if (pen)
        for (float f : pen->pressure) most = std::max(most, f);
    float arc = 0.0f;
    for (std::size_t i = 0; i + 1 < s.points.size(); ++i) {
        const Point2 a = s.points[i], b = s.points[i + 1];
        const float arc0 = arc;
        const float d0 = by_depth ? s.depth[i] : 0.0f, d1 = by_depth ? s.depth[i + 1] : 0.0f;
        // The widest the segment gets (the scale is monotonic in depth, so at an end).
        const float box_reach =
            (by_depth ? thickness * 0.5f * std::max(depth_scale(*pen, d0), depth_scale(*pen, d1))
                      : thickness * 0.5f) *
                most +
            0.5f;
        if (pen) arc += polyline_length(std::span<const Point2>(&s.points[i], 2));
        // Pixel x has its centre at x + 0.5; it can be covered if within reach of the box.
        const float lx = std::min(a.x, b.x) - box_reach, hx = std::max(a.x, b.x) + box_reach;
        const float ly = std::min(a.y, b.y) - box_reach, hy = std::max(a.y, b.y) + box_reach;
        if (!(hx >= 0.5f && lx <= w - 0.5f && hy >= 0.5f && ly <= h - 0.5f)) continue;  // also NaN
        Segment2 seg{
            a,
            b,
            std::max(0, static_cast<int>(std::ceil(lx - 0.5f))),
            std::min(w - 1, static_cast<int>(std::floor(hx - 0.5f))),
            std::max(0, static_cast<int>(std::ceil(ly - 0.5f))),
            std::min(h - 1, static_cast<int>(std::floor(hy - 0.5f))),
            reach,
            box_reach,
            style,
            arc0,
            pen && (by_depth || !pen->dash.empty() || varies_width(*pen, s)) ? pen : nullptr,
            s.closed ? -1.0f : total,  // closed strokes have no ends to taper
            total,
            pen ? nib_scale(*pen, b.x - a.x, b.y - a.y) : 1.0f,
            d0,
            d1};
        if (seg.x0 <= seg.x1 && seg.y0 <= seg.y1) out.push_back(seg);
    }
}

}  // namespace

bool in_dash(std::span<const float> dash, float s) {
    float period = 0.0f;
    for (float d : dash) period += d;
    float phase = std::fmod(s, period);
    for (std::size_t i = 0; i < dash.size(); ++i) {
        if (phase < dash[i]) return i % 2 == 0;
        phase -= dash[i];
    }
    return false;
}

namespace {

// The pixels of row y (centre y + 0.5) that a segment's capsule (points within max_reach of it)
// can cover, within the segment's box: the capsule is convex, so its section is one interval,
// the hull of the sections of the end discs and of the band along the segment. Widened by a
// pixel on each side, so that rounding never leaves out a pixel the exact test would cover
// (outside the capsule coverage is 0 and nothing is written).
std::pair<int, int> capsule_columns(const Segment2& s, int y) {
    const float r = s.max_reach;
    const float dx = s.b.x - s.a.x, dy = s.b.y - s.a.y;
    const float py = static_cast<float>(y) + 0.5f - s.a.y;
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    auto add = [&](float a, float b) {
        lo = std::min(lo, std::min(a, b));
        hi = std::max(hi, std::max(a, b));
    };
    // The end discs.
    for (const auto& [cx, cy] : {std::pair{0.0f, 0.0f}, std::pair{dx, dy}}) {
        const float q = r * r - (py - cy) * (py - cy);
        if (q >= 0.0f) add(cx - std::sqrt(q), cx + std::sqrt(q));
    }
    // The band: perpendicular distance within r and the projection within the segment.
    const float len = std::sqrt(dx * dx + dy * dy);
    if (len > 0.0f) {
        // |px dy - py dx| <= r len and 0 <= px dx + py dy <= len^2, as intervals of px.
        float b_lo = -std::numeric_limits<float>::infinity(), b_hi = -b_lo;
        auto clip = [&](float coefficient, float low, float high) {  // low <= c px <= high
            if (coefficient == 0.0f) {
                if (low > 0.0f || high < 0.0f) b_hi = -b_lo;  // empty
                return;
            }
            float a = low / coefficient, b = high / coefficient;
            if (a > b) std::swap(a, b);
            b_lo = std::max(b_lo, a);
            b_hi = std::min(b_hi, b);
        };
        clip(dy, py * dx - r * len, py * dx + r * len);
        clip(dx, -py * dy, len * len - py * dy);
        if (b_lo <= b_hi) add(b_lo, b_hi);
    }
    if (!(lo <= hi)) return {1, 0};  // the row misses the capsule (or a NaN)
    const float first = std::floor(s.a.x + lo - 0.5f) - 1.0f;
    const float last = std::ceil(s.a.x + hi - 0.5f) + 1.0f;
    const int x0 = first > static_cast<float>(s.x0) ? static_cast<int>(first) : s.x0;
    const int x1 = last < static_cast<float>(s.x1) ? static_cast<int>(last) : s.x1;
    return {x0, x1};
}

// Rasterises the segments in bands of rows; `style` (optional) gets the style of the largest
// coverage, the lower style on ties.
void rasterise(const std::vector<Segment2>& segments, ImageF& coverage, Image<std::uint16_t>* style,
               int threads) {
    const int h = coverage.height();
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
                const float len = s.pen ? std::sqrt(len2) : 0.0f;  // arc length along it
                for (int y = std::max(s.y0, row0); y <= std::min(s.y1, row1); ++y) {
                    float* row = coverage.row(y);
                    std::uint16_t* style_row = style ? style->row(y) : nullptr;
                    const float py = static_cast<float>(y) + 0.5f - s.a.y;
                    const auto [x0, x1] = capsule_columns(s, y);
                    for (int x = x0; x <= x1; ++x) {
                        const float px = static_cast<float>(x) + 0.5f - s.a.x;
                        // Distance to the segment: to its nearest point, ends included (round caps).
                        const float t = std::clamp((px * dx + py * dy) * inv_len2, 0.0f, 1.0f);
                        const float ex = px - dx * t, ey = py - dy * t;
                        float c;
                        if (s.pen) {
                            const float arc = s.arc0 + t * len;
                            if (!s.pen->dash.empty() && !in_dash(s.pen->dash, arc)) continue;
                            float f = taper_scale(*s.pen, arc, s.stroke_length) *
                                      pressure_scale(*s.pen, arc, s.total) * s.nib;
                            // d0 is set (positive) only where the pen scales by depth.
                            if (s.d0 > 0.0f) f *= depth_scale(*s.pen, s.d0 + (s.d1 - s.d0) * t);
                            const float reach = (s.reach - 0.5f) * f + 0.5f;
                            c = std::min(1.0f, reach - std::sqrt(ex * ex + ey * ey));
                            if (const Brush* brush = s.pen->brush_image) {
                                // Across: the signed distance to the left of the segment (as
                                // seen walking along it on the image, y down) over the width
                                // there: the brush's first row on the left edge.
                                const float half = reach - 0.5f;
                                const float left = len > 0.0f ? (px * dy - py * dx) / len : 0.0f;
                                const float across =
                                    half > 0.0f ? std::clamp(0.5f - 0.5f * left / half, 0.0f, 1.0f)
                                                : 0.5f;
                                c *= brush_ink(*brush, brush_along(*s.pen, arc, s.total), across);
                            }
                        } else {
                            c = std::min(1.0f, s.reach - std::sqrt(ex * ex + ey * ey));
                        }
                        if (c > row[x]) {
                            row[x] = c;
                            if (style_row) style_row[x] = s.style;
                        } else if (style_row && c == row[x] && c > 0.0f && s.style < style_row[x]) {
                            style_row[x] = s.style;
                        }
                    }
                }
            }
        }
    });
}

// A covered pixel's pen. The style image is drawn with the same pens (draw_styled_strokes), so
// a style without one is a mistake upstream: drawing another pen instead would hide it.
const StrokePen& pen_of_pixel(std::span<const StrokePen> pens, std::uint16_t style, int x, int y) {
    if (style >= pens.size())
        throw Error(fmt::format("ink: the line pixel ({}, {}) has style {} but there are {} pens",
                                x, y, style, pens.size()));
    return pens[style];
}

std::uint8_t to_byte(float v) {
    return static_cast<std::uint8_t>(std::min(std::max(v, 0.0f), 1.0f) * 255.0f + 0.5f);
}

}  // namespace

float stroke_thickness(float width, int height) {
    return width * static_cast<float>(height) / 720.0f;
}

StrokePen stroke_pen(const LineStyle& style, int height, float depth_reference,
                     const BrushSet* brushes) {
    StrokePen pen{scale_line_style(style, height)};
    pen.depth_reference = style.by_depth ? depth_reference : 0.0f;
    const float a = style.nib_angle * std::numbers::pi_v<float> / 180.0f;
    pen.nib = {portable::cos(a), -portable::sin(a)};
    if (!style.brush.empty()) {
        const auto it = brushes ? brushes->find(style.brush) : BrushSet::const_iterator{};
        if (!brushes || it == brushes->end())
            throw Error(
                fmt::format("ink: the brush '{}' of a line style was not read", style.brush));
        pen.brush_image = it->second.get();
    }
    return pen;
}

Brush make_brush(const ImageRgb8& image) {
    Brush brush;
    brush.ink.reshape(image.width(), image.height());
    brush.profile.assign(static_cast<std::size_t>(image.width()), 0.0f);
    for (int y = 0; y < image.height(); ++y)
        for (int x = 0; x < image.width(); ++x) {
            const Rgb8& p = image(x, y);
            // Rec. 709 luma of the bytes as they are.
            const float luma = (0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2]) / 255.0f;
            brush.ink(x, y) = std::clamp(1.0f - luma, 0.0f, 1.0f);
            brush.profile[static_cast<std::size_t>(x)] += brush.ink(x, y);
        }
    for (float& f : brush.profile) f /= static_cast<float>(std::max(image.height(), 1));
    return brush;
}

float pressure_scale(const StrokePen& pen, float arc, float length) {
    const std::vector<float>& p = pen.pressure;
    if (p.empty()) return 1.0f;
    if (p.size() == 1 || !(length > 0.0f)) return p.front();
    const float at = std::clamp(arc / length, 0.0f, 1.0f) * static_cast<float>(p.size() - 1);
    const auto i = std::min(static_cast<std::size_t>(at), p.size() - 2);
    const float f = at - static_cast<float>(i);
    return p[i] + (p[i + 1] - p[i]) * f;
}

float nib_scale(const StrokePen& pen, float dx, float dy) {
    if (!(pen.calligraphy < 1.0f)) return 1.0f;
    const float len = std::sqrt(dx * dx + dy * dy);
    if (!(len > 0.0f)) return 1.0f;
    const float sine = std::abs(dx * pen.nib.y - dy * pen.nib.x) / len;
    return pen.calligraphy + (1.0f - pen.calligraphy) * sine;
}

float brush_along(const StrokePen& pen, float arc, float length) {
    const Brush* brush = pen.brush_image;
    if (!brush || brush->ink.width() == 0) return 0.0f;
    if (pen.brush_stretch) return length > 0.0f ? std::clamp(arc / length, 0.0f, 1.0f) : 0.5f;
    const float stamp = pen.width * static_cast<float>(brush->ink.width()) /
                        static_cast<float>(std::max(brush->ink.height(), 1));
    if (!(stamp > 0.0f)) return 0.0f;
    const float u = arc / stamp;
    return u - std::floor(u);
}

float brush_ink(const Brush& brush, float along, float across) {
    const int w = brush.ink.width(), h = brush.ink.height();
    if (w == 0 || h == 0) return 1.0f;
    const float x = along * static_cast<float>(w) - 0.5f, y = across * static_cast<float>(h) - 0.5f;
    const float fx = std::floor(x), fy = std::floor(y);
    const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
    const float tx = x - fx, ty = y - fy;
    auto at = [&](int xi, int yi) {
        xi = ((xi % w) + w) % w;  // repeats along
        yi = std::clamp(yi, 0, h - 1);
        return brush.ink(xi, yi);
    };
    return (at(x0, y0) * (1.0f - tx) + at(x0 + 1, y0) * tx) * (1.0f - ty) +
           (at(x0, y0 + 1) * (1.0f - tx) + at(x0 + 1, y0 + 1) * tx) * ty;
}

float brush_width(const Brush& brush, float along) {
    const auto n = static_cast<int>(brush.profile.size());
    if (n == 0) return 1.0f;
    const float x = along * static_cast<float>(n) - 0.5f;
    const float fx = std::floor(x);
    const int x0 = static_cast<int>(fx);
    const float t = x - fx;
    auto at = [&](int i) { return brush.profile[static_cast<std::size_t>(((i % n) + n) % n)]; };
    return at(x0) * (1.0f - t) + at(x0 + 1) * t;
}

const StrokePen& pen_of_stroke(std::span<const StrokePen> pens, const Stroke& stroke,
                               std::size_t index) {
    if (stroke.style >= pens.size())
        throw Error(fmt::format("ink: stroke {} has style {} but there are {} pens", index,
                                stroke.style, pens.size()));
    return pens[stroke.style];
}

bool scales_by_depth(const StrokePen& pen, const Stroke& stroke) {
    return pen.by_depth && pen.depth_reference > 0.0f &&
           stroke.depth.size() == stroke.points.size();
}

bool varies_width(const StrokePen& pen, const Stroke& stroke) {
    return (pen.taper > 0.0f && !stroke.closed) || scales_by_depth(pen, stroke) ||
           !pen.pressure.empty() || pen.calligraphy < 1.0f || pen.brush_image != nullptr;
}

float taper_scale(const StrokePen& pen, float arc, float length) {
    if (!(pen.taper > 0.0f) || length < 0.0f) return 1.0f;
    const float end = std::min(arc, length - arc);
    return std::clamp(end / pen.taper, 0.0f, 1.0f);
}

float depth_scale(const StrokePen& pen, float depth) {
    return depth > 0.0f ? std::clamp(pen.depth_reference / depth, kMinDepthScale, kMaxDepthScale)
                        : kMaxDepthScale;
}

void draw_strokes(std::span<const Stroke> strokes, float thickness, ImageF& coverage, int threads) {
    const int w = coverage.width(), h = coverage.height();
    if (w <= 0 || h <= 0 || !(thickness > 0.0f)) return;
    std::vector<Segment2> segments;
    for (const Stroke& s : strokes) add_stroke_segments(s, thickness, 0, nullptr, w, h, segments);
    rasterise(segments, coverage, nullptr, threads);
}

void draw_styled_strokes(std::span<const Stroke> strokes, std::span<const StrokePen> pens,
                         int width, int height, ImageF& coverage, Image<std::uint16_t>& style,
                         int threads) {
    coverage.resize(width, height, 0.0f);
    style.resize(width, height, 0);
    if (width <= 0 || height <= 0) return;
    std::vector<Segment2> segments;
    for (std::size_t i = 0; i < strokes.size(); ++i) {
        const Stroke& s = strokes[i];
        const StrokePen& pen = pen_of_stroke(pens, s, i);
        if (!pen.draw || !(pen.width > 0.0f) || !(pen.opacity > 0.0f)) continue;
        const bool shaped = !pen.dash.empty() || varies_width(pen, s);
        float thickness = pen.width * s.scale;
        // A screentone dot covers its area exactly: a disc's coverage sums to a little more
        // than its area (tone.h, drawn_disc_radius).
        if (s.type == EdgeType::Tone && s.points.size() == 2 && s.points[0] == s.points[1]) {
            const float r = thickness * 0.5f;
            thickness = 2.0f * drawn_disc_radius(std::numbers::pi_v<float> * r * r);
        }
        add_stroke_segments(s, thickness, s.style, shaped ? &pen : nullptr, width, height,
                            segments);
    }
    rasterise(segments, coverage, &style, threads);
}

void composite_styled_lines(const ImageF& coverage, const Image<std::uint16_t>& styles,
                            std::span<const StrokePen> pens, ImageRgb8& image) {
    for (int y = 0; y < image.height(); ++y) {
        const float* cov = coverage.row(y);
        const std::uint16_t* style = styles.row(y);
        Rgb8* px = image.row(y);
        for (int x = 0; x < image.width(); ++x) {
            if (!(cov[x] > 0.0f)) continue;
            const StrokePen& pen = pen_of_pixel(pens, style[x], x, y);
            const float a = cov[x] * pen.opacity;
            for (int c = 0; c < 3; ++c)
                px[x][c] = to_byte(static_cast<float>(px[x][c]) * (1.0f / 255.0f) * (1.0f - a) +
                                   pen.colour[c] * a);
        }
    }
}

void opaque_lines(const ImageF& coverage, const Image<std::uint16_t>& styles,
                  std::span<const StrokePen> pens, Image<std::uint8_t>& opaque) {
    opaque.reshape(coverage.width(), coverage.height());
    for (int y = 0; y < coverage.height(); ++y) {
        const float* cov = coverage.row(y);
        const std::uint16_t* style = styles.row(y);
        std::uint8_t* out = opaque.row(y);
        for (int x = 0; x < coverage.width(); ++x)
            // composite_styled_lines's a: with a = 1 the picture's value is multiplied by 0.
            out[x] = cov[x] > 0.0f && cov[x] * pen_of_pixel(pens, style[x], x, y).opacity == 1.0f;
    }
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
