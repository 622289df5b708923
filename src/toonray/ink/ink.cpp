#include "toonray/ink/ink.h"

#include <algorithm>
#include <chrono>
#include <map>
#include <tuple>

#include "toonray/core/error.h"

#include "toonray/ink/polylines.h"

namespace toonray::ink {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The style of every segment, visible and hidden, resolved once per (object, material, type).
std::vector<SegmentStyles> resolve_segment_styles(const Scene& scene,
                                                  std::span<const FeatureSegment> segments,
                                                  const InkSettings& settings,
                                                  std::vector<LineStyle>& styles) {
    LineStyle base;
    base.colour = settings.colour;
    base.width = settings.width;
    base.taper = settings.taper;
    base.by_depth = settings.width_by_depth;
    LineStyle hidden = base;
    hidden.draw = false;
    styles = {base, hidden};
    std::vector<SegmentStyles> out(segments.size(), SegmentStyles{0, 1});
    if (settings.styles.empty()) return out;
    auto index_of = [&](const LineStyle& style) {
        for (std::size_t i = 0; i < styles.size(); ++i)
            if (styles[i] == style) return static_cast<std::uint16_t>(i);
        if (styles.size() > 0xffff) throw Error("more than 65536 distinct line styles in a frame");
        styles.push_back(style);
        return static_cast<std::uint16_t>(styles.size() - 1);
    };
    std::map<std::tuple<std::uint32_t, std::uint32_t, EdgeType>, SegmentStyles> known;
    for (std::size_t i = 0; i < segments.size(); ++i) {
        const auto [object, material] = style_source(scene, segments[i]);
        const auto key = std::make_tuple(object, material, segments[i].type);
        auto it = known.find(key);
        if (it == known.end()) {
            SegmentStyles both{};
            for (int v = 0; v < 2; ++v)
                both[v] = index_of(resolve_line_style(settings.styles, base, scene.objects[object],
                                                      scene.materials[material].name,
                                                      segments[i].type, v == 0));
            it = known.emplace(key, both).first;
        }
        out[i] = it->second;
    }
    return out;
}

}  // namespace

std::uint32_t style_source_triangle(const Scene& scene, const FeatureSegment& segment) {
    std::uint32_t best = kNoIndex;
    for (std::uint32_t f : segment.faces) {
        if (f == kNoIndex || f >= scene.triangle_count()) continue;
        if (best == kNoIndex ||
            std::make_pair(scene.tri_object[f], scene.tri_material[f]) <
                std::make_pair(scene.tri_object[best], scene.tri_material[best]))
            best = f;
    }
    return best;
}

std::pair<std::uint32_t, std::uint32_t> style_source(const Scene& scene,
                                                     const FeatureSegment& segment) {
    if (segment.face_instance[0] == kNoIndex && segment.face_instance[1] == kNoIndex) {
        const std::uint32_t tri = style_source_triangle(scene, segment);
        if (tri == kNoIndex) return {0, 0};
        return {scene.tri_object[tri], scene.tri_material[tri]};
    }
    std::pair<std::uint32_t, std::uint32_t> best{kNoIndex, kNoIndex};
    for (int k = 0; k < 2; ++k) {
        const std::uint32_t f = segment.faces[k], instance = segment.face_instance[k];
        if (f == kNoIndex) continue;
        const TriangleMesh& mesh = scene.mesh_of(instance);
        if (f >= mesh.triangle_count()) continue;
        const std::pair<std::uint32_t, std::uint32_t> source{
            instance == kNoIndex ? mesh.tri_object[f] : scene.instances[instance].object,
            mesh.tri_material[f]};
        if (best.first == kNoIndex || source < best) best = source;
    }
    return best.first == kNoIndex ? std::pair<std::uint32_t, std::uint32_t>{0, 0} : best;
}

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
    add_instance_segments(scene, accel, out.mesh, plane, view, settings.visibility.margin, edges,
                          threads, out.instances, out.segments);
    add_polyline_segments(scene, out.segments);
    out.timings.edges = seconds_since(start);

    start = std::chrono::steady_clock::now();
    ChainSettings chain = settings.chain;
    chain.hidden = chain.hidden || settings.styles.draws_hidden();
    // Styles only need hidden from visible; how deep a line is hidden is counted for the SVG's
    // hidden layer (settings.chain.hidden) only.
    VisibilitySettings visibility = settings.visibility;
    if (!settings.chain.hidden)
        visibility.max_invisibility = std::min(visibility.max_invisibility, 1);
    out.pieces = split_by_visibility(
        out.segments, VisibilityContext{scene, out.mesh, accel, view, &out.instances}, visibility,
        threads);
    out.timings.visibility = seconds_since(start);

    start = std::chrono::steady_clock::now();
    const std::vector<SegmentStyles> segment_styles =
        resolve_segment_styles(scene, out.segments, settings, out.styles);
    bool by_depth = false;
    for (const LineStyle& style : out.styles) by_depth = by_depth || style.by_depth;
    if (by_depth) chain.eye = plane.eye;
    out.strokes = chain_pieces(out.pieces, chain, segment_styles);
    out.timings.chaining = seconds_since(start);

    start = std::chrono::steady_clock::now();
    out.pens.clear();
    float depth_reference = 0.0f;
    if (by_depth) {
        const BBox bounds = scene.bounds();
        depth_reference = length((bounds.lo + bounds.hi) * 0.5f - plane.eye);
    }
    for (const LineStyle& style : out.styles)
        out.pens.push_back(stroke_pen(style, height, depth_reference));
    if (settings.drawn_types == (1u << kEdgeTypeCount) - 1) {
        draw_styled_strokes(out.strokes, out.pens, width, height, out.coverage, out.style, threads);
    } else {
        std::vector<Stroke> drawn;
        for (const Stroke& stroke : out.strokes)
            if (settings.drawn_types & (1u << static_cast<unsigned>(stroke.type)))
                drawn.push_back(stroke);
        draw_styled_strokes(drawn, out.pens, width, height, out.coverage, out.style, threads);
    }
    out.timings.drawing = seconds_since(start);
}

}  // namespace toonray::ink
