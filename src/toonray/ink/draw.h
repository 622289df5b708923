#pragma once
/// Drawing strokes with exact anti-aliased coverage, and compositing them over a picture.

#include <span>

#include "toonray/core/image.h"
#include "toonray/core/math.h"
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

/// image = image * (1 - coverage) + colour * coverage, per channel, in [0, 1] and rounded to
/// bytes as the renderer does (value * 255 + 0.5, truncated).
void composite_lines(const ImageF& coverage, const Vec3f& colour, ImageRgb8& image);

/// The coverage as a black-on-white 8-bit image (255 = no line), like the `_edges` feature image.
void coverage_to_gray(const ImageF& coverage, ImageGray8& out);

}  // namespace toonray::ink
