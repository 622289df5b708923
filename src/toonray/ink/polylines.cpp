#include "toonray/ink/polylines.h"

#include "toonray/ink/draw.h"
#include "toonray/ink/screen.h"
#include "toonray/ink/strokes.h"
#include "toonray/ink/visibility.h"

namespace toonray::ink {

namespace {

// Marks an endpoint key as a polyline point, so that it never equals a mesh vertex's key
// ({welded vertex, kNoIndex, kNoIndex}): strokes chain along a polyline, not onto the mesh.
constexpr std::uint32_t kPolylinePoint = kNoIndex - 1;

}  // namespace

void add_polyline_segments(const Scene& scene, std::vector<FeatureSegment>& out) {
    for (const Polyline& line : scene.polylines)
        for (std::uint32_t i = line.first; i + 1 < line.first + line.count; ++i) {
            const std::uint32_t a = scene.polyline_points[i], b = scene.polyline_points[i + 1];
            const Vec3f& p0 = scene.positions[a];
            const Vec3f& p1 = scene.positions[b];
            if (p0 == p1) continue;
            FeatureSegment s;
            s.p0 = p0;
            s.p1 = p1;
            s.key0 = {a, kPolylinePoint, kPolylinePoint};
            s.key1 = {b, kPolylinePoint, kPolylinePoint};
            s.type = EdgeType::Polyline;
            out.push_back(s);
        }
}

void draw_polylines_over(const Scene& scene, const TriangleAccel& accel, const CameraSpec& camera,
                         const InkSettings& settings, const Vec3f& colour, int threads,
                         ImageRgb8& image, ImageF& coverage) {
    if (scene.polylines.empty()) return;
    const int width = image.width(), height = image.height();
    std::vector<FeatureSegment> segments;
    add_polyline_segments(scene, segments);
    const ViewPlane plane = make_view_plane(camera, width, height);
    const ScreenProjection view(plane, width, height);
    const WeldedMesh no_mesh;  // polyline segments lie on no face: no ring is looked up
    VisibilitySettings visibility = settings.visibility;
    visibility.max_invisibility = 1;
    const std::vector<EdgePiece> pieces = split_by_visibility(
        segments, VisibilityContext{scene, no_mesh, accel, view}, visibility, threads);
    ChainSettings chain = settings.chain;
    chain.hidden = false;
    std::vector<Stroke> strokes = chain_pieces(pieces, chain);
    std::erase_if(strokes, [](const Stroke& s) { return !s.visible; });
    coverage.resize(width, height, 0.0f);
    draw_strokes(strokes, stroke_thickness(settings.width, height), coverage, threads);
    composite_lines(coverage, colour, image);
}

}  // namespace toonray::ink
