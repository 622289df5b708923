#include "toonray/ink/ink.h"

#include <algorithm>
#include <chrono>

#include "toonray/ink/polylines.h"

namespace toonray::ink {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

void draw_ink_lines(const Scene& scene, const TriangleAccel& accel, const CameraSpec& camera,
                    int width, int height, const InkSettings& settings, int threads,
                    InkLines& out) {
    const ViewPlane plane = make_view_plane(camera, width, height);
    const ScreenProjection view(plane, width, height);

    auto start = std::chrono::steady_clock::now();
    out.mesh = weld_vertices(scene);
    FeatureEdgeSettings edges = settings.edges;
    if (!settings.chain.hidden) edges.certainly_hidden = false;  // chaining would drop them
    out.segments = find_feature_edges(scene, out.mesh, accel.bvh(), plane.eye, edges, threads,
                                      &out.intersections);
    add_polyline_segments(scene, out.segments);
    out.timings.edges = seconds_since(start);

    start = std::chrono::steady_clock::now();
    VisibilitySettings visibility = settings.visibility;
    if (!settings.chain.hidden)
        visibility.max_invisibility = std::min(visibility.max_invisibility, 1);
    out.pieces = split_by_visibility(out.segments, VisibilityContext{scene, out.mesh, accel, view},
                                     visibility, threads);
    out.timings.visibility = seconds_since(start);

    start = std::chrono::steady_clock::now();
    out.strokes = chain_pieces(out.pieces, settings.chain);
    out.timings.chaining = seconds_since(start);

    start = std::chrono::steady_clock::now();
    out.coverage.resize(width, height, 0.0f);
    std::vector<Stroke> visible;
    for (const Stroke& s : out.strokes)
        if (s.visible) visible.push_back(s);
    draw_strokes(visible, stroke_thickness(settings.width, height), out.coverage, threads);
    out.timings.drawing = seconds_since(start);
}

}  // namespace toonray::ink
