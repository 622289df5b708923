#pragma once
/// Polylines (OBJ `l` elements) as ink lines: segments of their own type, EdgeType::Polyline,
/// that go through the ink pipeline's visibility, chaining and drawing with the lines found on
/// the geometry; and, for the classic and robust line modes, drawn over a finished frame the
/// same way.

#include <vector>

#include "toonray/accel/triangle_accel.h"
#include "toonray/core/image.h"
#include "toonray/ink/feature_edges.h"
#include "toonray/ink/ink.h"
#include "toonray/scene/camera.h"
#include "toonray/scene/scene.h"

namespace toonray::ink {

/// Appends one segment per pair of consecutive points of every polyline in the scene, in
/// order. Zero-length segments are left out. A segment lies on no face, so every surface in
/// front of it hides it.
void add_polyline_segments(const Scene& scene, std::vector<FeatureSegment>& out);

/// Draws the scene's visible polylines over `image` as ink strokes of settings.width, in
/// `colour`: visibility by rays against `accel` (visibility.h), strokes chained and drawn as in
/// draw_ink_lines. `coverage` gets their coverage (0 to 1, the image's size). Does nothing for a
/// scene without polylines.
void draw_polylines_over(const Scene& scene, const TriangleAccel& accel, const CameraSpec& camera,
                         const InkSettings& settings, const Vec3f& colour, int threads,
                         ImageRgb8& image, ImageF& coverage);

}  // namespace toonray::ink
