#pragma once
/// `--edges ink`: lines found on the geometry (feature_edges.h), cut at visibility changes
/// with rays against the BVH (visibility.h), chained into strokes (strokes.h) and drawn with
/// exact coverage (draw.h) or written as SVG (svg.h).

#include <vector>

#include "toonray/accel/triangle_accel.h"
#include "toonray/core/image.h"
#include "toonray/ink/draw.h"
#include "toonray/ink/feature_edges.h"
#include "toonray/ink/strokes.h"
#include "toonray/ink/visibility.h"
#include "toonray/scene/camera.h"
#include "toonray/scene/scene.h"

namespace toonray::ink {

struct InkSettings {
    FeatureEdgeSettings edges;
    VisibilitySettings visibility;
    ChainSettings chain;
    float width = 2.0f;  ///< line width in pixels at 720 lines; scales with the image height
};

/// Seconds spent in each stage of the last draw_ink_lines.
struct InkTimings {
    double edges = 0, visibility = 0, chaining = 0, drawing = 0;
};

/// Everything one frame's ink lines produce; kept between frames so buffers are reused.
struct InkLines {
    WeldedMesh mesh;
    std::vector<FeatureSegment> segments;
    std::vector<EdgePiece> pieces;
    std::vector<Stroke> strokes;
    ImageF coverage;                  ///< visible strokes, 0 = no line, 1 = covered
    IntersectionCache intersections;  ///< for the next frame's unmoved triangles
    InkTimings timings;
};

/// Runs every stage for one view of the scene. `accel` holds the scene's triangles in their
/// order. Without hidden strokes (settings.chain.hidden false) visibility only tells visible
/// from hidden (max_invisibility 1), which needs one ray query per hidden point. The same
/// result for any thread count.
void draw_ink_lines(const Scene& scene, const TriangleAccel& accel, const CameraSpec& camera,
                    int width, int height, const InkSettings& settings, int threads, InkLines& out);

}  // namespace toonray::ink
