#pragma once
/// Drawing strokes with exact anti-aliased coverage, and compositing them over a picture.

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "toonray/core/image.h"
#include "toonray/core/math.h"
#include "toonray/ink/line_style.h"
#include "toonray/ink/strokes.h"

namespace toonray::ink {

/// Line thickness in pixels for `width` (pixels at 720 lines) in an image `height` pixels
/// tall: width * height / 720, the robust lines' rule (render/robust.h, line_thickness).
[[nodiscard]] float stroke_thickness(float width, int height);

/// Draws the strokes into `coverage` (which keeps its size and adds to what it holds, by max).
/// A pixel whose centre is at distance d from a stroke's centreline (its polyline with round
/// caps) is covered by clamp(thickness / 2 + 0.5 - d, 0, 1), the coverage rule of the robust
/// lines, which integrates to `thickness` across a straight line. Overlapping strokes take
/// the larger coverage, so the result does not depend on the order of strokes or on threads.
/// Each segment is rasterised within its own bounding box.
void draw_strokes(std::span<const Stroke> strokes, float thickness, ImageF& coverage, int threads);

/// A decoded brush (LineStyle::brush): its ink per pixel in [0, 1] (1 - luma), rows across the
/// stroke (the first row on the stroke's left, looking along it on the image) and columns along
/// it; and per column the mean ink across, the width of the same ink that the SVG gets.
struct Brush {
    ImageF ink;
    std::vector<float> profile;
};

/// A brush from an image: black ink, white paper.
[[nodiscard]] Brush make_brush(const ImageRgb8& image);

/// Brushes by the file names styles give (LineStyle::brush), as the frame layer reads them.
using BrushSet = std::map<std::string, std::shared_ptr<const Brush>, std::less<>>;

/// How the strokes of one resolved style are drawn: the style in pixels of this image (every
/// attribute that scales, StyleAttribute::scales, times height / 720: `width` is the
/// thickness, `dash` and `taper` are pixels along the stroke), plus what the drawing derives
/// from the scene.
struct StrokePen : LineStyle {
    /// Width by depth: when `by_depth` and > 0 (and strokes have Stroke::depth), the thickness
    /// at a point at distance d from the eye is scaled by clamp(depth_reference / d, 0.25, 2),
    /// d interpolated linearly along each segment on the image.
    float depth_reference = 0.0f;
    /// The nib's direction on the image (calligraphy), a unit vector.
    Point2 nib{1.0f, 0.0f};
    /// The brush `brush` names, decoded; null without one.
    const Brush* brush_image = nullptr;
};

/// The pen of `style` in an image `height` pixels tall (scale_line_style); `depth_reference`
/// is kept when the style has width by depth, else 0. A style's brush is looked up in
/// `brushes`; throws Error naming it when it is not there.
[[nodiscard]] StrokePen stroke_pen(const LineStyle& style, int height, float depth_reference = 0.0f,
                                   const BrushSet* brushes = nullptr);

/// pens[stroke.style]. The pens are made with the strokes' styles (ink.h, InkLines), so a style
/// without a pen is a mistake upstream: throws Error naming the stroke (`index`), its style and
/// the number of pens rather than drawing it with another pen.
[[nodiscard]] const StrokePen& pen_of_stroke(std::span<const StrokePen> pens, const Stroke& stroke,
                                             std::size_t index);

/// Whether the pen scales the stroke's width by depth (it asks for it, has a reference and
/// the stroke has a depth per point).
[[nodiscard]] bool scales_by_depth(const StrokePen& pen, const Stroke& stroke);

/// Whether the stroke's width varies along it: tapered (and open), scaled by depth, with a
/// pressure profile, a broad nib or a brush.
[[nodiscard]] bool varies_width(const StrokePen& pen, const Stroke& stroke);

/// The pressure profile's factor at arc length `arc` of a stroke `length` pixels long.
[[nodiscard]] float pressure_scale(const StrokePen& pen, float arc, float length);

/// The broad nib's factor on a segment along (dx, dy) on the image: calligraphy + (1 -
/// calligraphy) |sin| of its angle to the nib; 1 for a round pen or a segment of no length.
[[nodiscard]] float nib_scale(const StrokePen& pen, float dx, float dy);

/// Where a brush is read along a stroke `length` pixels long at arc length `arc`, as a
/// fraction of the image's width: the whole stroke once (stretched), or stamps of the pen's
/// width times the image's aspect.
[[nodiscard]] float brush_along(const StrokePen& pen, float arc, float length);

/// The brush's ink at (along, across) in [0, 1]^2, bilinear, repeating along.
[[nodiscard]] float brush_ink(const Brush& brush, float along, float across);

/// The brush's width profile (Brush::profile) at `along`, linear between columns, repeating.
[[nodiscard]] float brush_width(const Brush& brush, float along);

/// The taper's factor on the thickness at arc length `arc` of a stroke `length` pixels long:
/// min(1, distance to the nearer end / taper), at least 0; 1 without taper or for a closed
/// stroke (length < 0).
[[nodiscard]] float taper_scale(const StrokePen& pen, float arc, float length);

/// Whether arc length `s` along a stroke lies in an "on" dash of the pattern (on, off, ...
/// lengths, not all 0), which repeats from the stroke's first point.
[[nodiscard]] bool in_dash(std::span<const float> dash, float s);

/// Width by depth's factor on the thickness at distance `depth` from the eye:
/// clamp(depth_reference / depth, 0.25, 2); 2 for a depth that is not positive.
[[nodiscard]] float depth_scale(const StrokePen& pen, float depth);

/// Draws each stroke with pens[stroke.style] (strokes whose pen does not draw are skipped;
/// a stroke whose style has no pen throws Error, as the styles and pens are made together)
/// into the line layer `coverage` and `style` (per pixel, the coverage of the stroke that covers
/// it most and that stroke's style: 4 + 2 bytes a pixel), resized to width x height and cleared
/// first. Coverage is the rule of
/// draw_strokes with the pen's width as thickness; a dashed stroke covers a pixel only from the parts
/// of its centreline in an "on" dash (arc length from the stroke's first point, modulo the
/// pattern), and a tapered one with the thickness at the nearest centreline point. Each pixel
/// keeps the largest coverage and its style, the lower style index on equal coverage: the
/// same for any stroke order and thread count. With a single solid pen the coverage is
/// exactly draw_strokes's.
void draw_styled_strokes(std::span<const Stroke> strokes, std::span<const StrokePen> pens,
                         int width, int height, ImageF& coverage, Image<std::uint16_t>& style,
                         int threads);

/// image = image * (1 - a) + colour * a with a = coverage * opacity of the pixel's pen, per
/// channel, rounded as composite_lines. With opacity 1 this is composite_lines exactly. A
/// covered pixel whose style has no pen throws Error.
void composite_styled_lines(const ImageF& coverage, const Image<std::uint16_t>& style,
                            std::span<const StrokePen> pens, ImageRgb8& image);

/// 1 where composite_styled_lines covers a pixel completely (coverage times the pen's opacity
/// is exactly 1), so that nothing of the picture under it shows; else 0. Sized like coverage.
/// A covered pixel whose style has no pen throws Error.
void opaque_lines(const ImageF& coverage, const Image<std::uint16_t>& style,
                  std::span<const StrokePen> pens, Image<std::uint8_t>& opaque);

/// image = image * (1 - coverage) + colour * coverage, per channel, in [0, 1] and rounded to
/// bytes as the renderer does (value * 255 + 0.5, truncated).
void composite_lines(const ImageF& coverage, const Vec3f& colour, ImageRgb8& image);

/// The coverage as a black-on-white 8-bit image (255 = no line), like the `_edges` feature image.
void coverage_to_gray(const ImageF& coverage, ImageGray8& out);

}  // namespace toonray::ink
