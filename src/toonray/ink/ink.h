#pragma once
/// `--edges ink`: lines found on the geometry (feature_edges.h), cut at visibility changes
/// with rays against the BVH (visibility.h), chained into strokes (strokes.h) and drawn with
/// exact coverage (draw.h) or written as SVG (svg.h).

#include <vector>

#include "toonray/accel/triangle_accel.h"
#include "toonray/core/image.h"
#include "toonray/ink/draw.h"
#include "toonray/ink/feature_edges.h"
#include "toonray/ink/instance_lines.h"
#include "toonray/ink/line_style.h"
#include "toonray/ink/strokes.h"
#include "toonray/ink/tone.h"
#include "toonray/ink/visibility.h"
#include "toonray/scene/camera.h"
#include "toonray/scene/scene.h"

namespace toonray::ink {

struct InkSettings {
    FeatureEdgeSettings edges;
    VisibilitySettings visibility;
    ChainSettings chain;
    float width = 2.0f;  ///< line width in pixels at 720 lines; scales with the image height
    Vec3f colour{0.0f};  ///< line colour where no style says otherwise
    float taper = 0.0f;  ///< default taper at open stroke ends, pixels at 720 lines (LineStyle)
    /// Default width by depth: full width at the distance from the eye to the centre of the
    /// scene's bounds, scaled by that distance over the point's, within [0.25, 2].
    bool width_by_depth = false;
    /// Line sets: which strokes are drawn and how (line_style.h). Without rules visible lines
    /// are drawn with width and colour, hidden ones are not drawn.
    LineStyleSet styles;
    /// The line types drawn into the line layer (InkLines::coverage), as bits 1 << EdgeType;
    /// the strokes of the others are kept (for SVG) but not drawn. Tone strokes have a layer
    /// of their own (InkLines::tone_coverage).
    unsigned drawn_types = (1u << kEdgeTypeCount) - 1;
    /// The tone look (tone.h): with hatch or screentone, and `tone_shading` set, its strokes or
    /// dots are made, styled as type `tone` (their base pen is `width` and `colour`, nothing
    /// else), and drawn into the tone layer.
    ToneSettings tone;
    const ToneShading* tone_shading = nullptr;
    /// The darkness each band of the ramp asks of the tone (1 - its level, within [0, 1]).
    std::vector<float> band_darkness;
    /// The frame's lights (the tone's light direction, band and shadow lines).
    std::span<const Light> lights;
    /// Band lines (light_lines.h, and along mesh edges: FeatureEdgeSettings::bands) at these
    /// thresholds of the ramp; shadow lines, the boundaries of toon shadows.
    bool bands = false, shadows = false;
    std::vector<float> band_thresholds;
    /// The brushes styles name (LineStyle::brush), read by the frame layer.
    const BrushSet* brushes = nullptr;
    /// The frame's number in its sequence: sketchy strokes' boil (sketch.h).
    int frame = 0;
};

/// Seconds spent in each stage of the last draw_ink_lines.
struct InkTimings {
    double edges = 0, tone = 0, visibility = 0, chaining = 0, drawing = 0;
};

/// Everything one frame's ink lines produce; kept between frames so buffers are reused.
struct InkLines {
    WeldedMesh mesh;
    /// The feature segments (the instances' only where a piece lies on them: a crowd's are
    /// mostly hidden or outside the image) and their pieces, in segment order.
    std::vector<FeatureSegment> segments;
    std::vector<EdgePiece> pieces;
    std::vector<Stroke> strokes;
    /// The distinct styles of this frame's strokes (Stroke::style indexes them): 0 is the
    /// default for visible lines and 1 for hidden ones; the others in order of first use by
    /// the segments. pens are the same in pixels of this image.
    std::vector<LineStyle> styles;
    std::vector<StrokePen> pens;
    ImageF coverage;  ///< drawn strokes, 0 = no line, 1 = covered (the largest per pixel)
    Image<std::uint16_t> style;  ///< per pixel, the style of the stroke that gave the coverage
    /// The tone strokes and dots drawn alike, to go under the lines; empty (0 x 0) without a
    /// tone look.
    ImageF tone_coverage;
    Image<std::uint16_t> tone_style;
    IntersectionCache intersections;  ///< for the next frame's unmoved triangles
    InstanceLineCache instances;      ///< for the next frame's meshes and unmoved instances
    InkTimings timings;
};

/// Where a segment takes its object and material from, for its style: of its faces, the one
/// with the lower object id, then the lower material id (so an intersection line between two
/// objects is styled as the object listed first). kNoIndex without faces.
[[nodiscard]] std::uint32_t style_source_triangle(const Scene& scene,
                                                  const FeatureSegment& segment);

/// The object and material a segment is styled as (style_source_triangle's rule, with an
/// instance's triangles of its object and its mesh's material); (0, 0) without faces.
[[nodiscard]] std::pair<std::uint32_t, std::uint32_t> style_source(const Scene& scene,
                                                                   const FeatureSegment& segment);

/// Runs every stage for one view of the scene. `accel` holds the scene's triangles in their
/// order. Without hidden strokes (settings.chain.hidden false) visibility only tells visible
/// from hidden (max_invisibility 1), which needs one ray query per hidden point. The same
/// result for any thread count.
void draw_ink_lines(const Scene& scene, const TriangleAccel& accel, const CameraSpec& camera,
                    int width, int height, const InkSettings& settings, int threads, InkLines& out);

}  // namespace toonray::ink
