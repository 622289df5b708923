#include "toonray/ink/ink.h"

#include <algorithm>
#include <chrono>
#include <map>
#include <tuple>

#include "toonray/core/error.h"
#include "toonray/ink/chunks.h"
#include "toonray/ink/light_lines.h"
#include "toonray/ink/polylines.h"
#include "toonray/ink/sketch.h"

namespace toonray::ink {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Styles resolved once per (object, material, type, visibility), indexed in order of first use
// after the two defaults (0 for visible lines, 1 for hidden ones).
class StyleResolver {
public:
    StyleResolver(const Scene& scene, const InkSettings& settings, std::vector<LineStyle>& styles)
        : scene_(scene), settings_(settings), styles_(styles) {
        base_.colour = settings.colour;
        base_.width = settings.width;
        base_.taper = settings.taper;
        base_.by_depth = settings.width_by_depth;
        LineStyle hidden = base_;
        hidden.draw = false;
        styles_ = {base_, hidden};
        // Tone strokes start from the lines' colour and width only: a taper or width by depth
        // would take from their tone.
        tone_base_.colour = settings.colour;
        tone_base_.width = settings.width;
    }

    /// Whether every style of type `type` is a default one (no rules, not tone).
    [[nodiscard]] bool plain(EdgeType type) const {
        return settings_.styles.empty() && type != EdgeType::Tone;
    }

    /// The index of the style of type `type` on triangle `tri`'s object and material.
    std::uint16_t index(std::uint32_t tri, EdgeType type, bool visible) {
        if (tri == kNoIndex)
            return index(std::pair<std::uint32_t, std::uint32_t>{0, 0}, type, visible);
        return index(std::pair{scene_.tri_object[tri], scene_.tri_material[tri]}, type, visible);
    }

    /// The index of the style of type `type` on an object and material (style_source).
    std::uint16_t index(std::pair<std::uint32_t, std::uint32_t> source, EdgeType type,
                        bool visible) {
        if (plain(type)) return visible ? 0 : 1;
        const auto [object, material] = source;
        const auto key = std::make_tuple(object, material, type, visible);
        if (const auto it = known_.find(key); it != known_.end()) return it->second;
        const LineStyle style = resolve_line_style(
            settings_.styles, type == EdgeType::Tone ? tone_base_ : base_, scene_.objects[object],
            scene_.materials[material].name, type, visible);
        std::uint16_t i = 0;
        while (i < styles_.size() && !(styles_[i] == style)) ++i;
        if (i == styles_.size()) {
            if (styles_.size() > 0xffff)
                throw Error("more than 65536 distinct line styles in a frame");
            styles_.push_back(style);
        }
        known_.emplace(key, i);
        return i;
    }

private:
    const Scene& scene_;
    const InkSettings& settings_;
    std::vector<LineStyle>& styles_;
    LineStyle base_, tone_base_;
    std::map<std::tuple<std::uint32_t, std::uint32_t, EdgeType, bool>, std::uint16_t> known_;
};

// The style of every segment, visible and hidden.
std::vector<SegmentStyles> resolve_segment_styles(const Scene& scene,
                                                  std::span<const FeatureSegment> segments,
                                                  StyleResolver& styles) {
    std::vector<SegmentStyles> out(segments.size());
    for (std::size_t i = 0; i < segments.size(); ++i) {
        if (styles.plain(segments[i].type)) {
            out[i] = {0, 1};
            continue;
        }
        const auto source = style_source(scene, segments[i]);
        out[i] = {styles.index(source, segments[i].type, true),
                  styles.index(source, segments[i].type, false)};
    }
    return out;
}

bool tone_look(const InkSettings& settings) {
    return settings.tone.mode != ToneMode::Cel && settings.tone_shading != nullptr;
}

// The tone pens of a frame: one per (object, material) of the triangles, from the style of its
// tone strokes (`styles`, in pixels of the image: `pens`), and which each triangle uses.
void tone_pens(const Scene& scene, const InkSettings& settings, StyleResolver& styles,
               const std::vector<LineStyle>& resolved, int height,
               std::vector<std::uint16_t>& pen_of_triangle, std::vector<TonePen>& pens) {
    pen_of_triangle.resize(scene.triangle_count());
    pens.clear();
    std::map<std::uint16_t, std::uint16_t> pen_of_style;
    const float spacing = stroke_thickness(settings.tone.spacing, height);
    std::pair<std::uint32_t, std::uint32_t> last{kNoIndex, kNoIndex};
    std::uint16_t style = 0;
    for (std::uint32_t t = 0; t < scene.triangle_count(); ++t) {
        // Neighbouring triangles mostly share their object and material.
        const std::pair<std::uint32_t, std::uint32_t> key{scene.tri_object[t],
                                                          scene.tri_material[t]};
        if (key != last) style = styles.index(t, EdgeType::Tone, true);
        last = key;
        auto [it, added] = pen_of_style.try_emplace(style, static_cast<std::uint16_t>(pens.size()));
        if (added) {
            const LineStyle& s = resolved[style];
            TonePen& pen = pens.emplace_back();
            pen.width = stroke_thickness(s.width, height);
            pen.draw = s.draw && pen.width > 0.0f && s.opacity > 0.0f;
            for (float darkness : settings.band_darkness)
                pen.share.push_back(hatch_shares(darkness, pen.width / spacing, s.opacity));
        }
        pen_of_triangle[t] = it->second;
    }
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

    ChainSettings chain = settings.chain;
    chain.hidden = chain.hidden || settings.styles.draws_hidden();
    // Styles only need hidden from visible; how deep a line is hidden is counted for the SVG's
    // hidden layer (settings.chain.hidden) only.
    VisibilitySettings visibility = settings.visibility;
    if (!settings.chain.hidden)
        visibility.max_invisibility = std::min(visibility.max_invisibility, 1);
    // Hidden pieces only when something draws them: the chain's rules keep none otherwise.
    visibility.keep_hidden = chain.hidden;
    visibility.min_piece = chain.min_piece;

    auto start = std::chrono::steady_clock::now();
    // The last frame's welded triangles go to the cache, whose mesh edges were found for them.
    out.intersections.welded = std::move(out.mesh.tri_vertices);
    // The rest of the last frame's mesh (its vertex rings: 12 bytes a triangle) is freed
    // before the next is welded, not after: one mesh at the frame's peak, not two.
    out.mesh = {};
    out.mesh = weld_vertices_without_rings(scene, false);
    FeatureEdgeSettings edges = settings.edges;
    if (!settings.chain.hidden) edges.certainly_hidden = false;  // chaining would drop them
    edges.bands = settings.bands;
    edges.lights = settings.lights;
    edges.band_thresholds = settings.band_thresholds;
    out.segments = find_feature_edges(scene, out.mesh, accel.bvh(), plane.eye, edges, threads,
                                      &out.intersections);
    out.timings.edges = seconds_since(start);
    // The own segments' pieces first: the instances' pieces, a crowd's many, are then appended
    // to them once rather than copied again behind them.
    start = std::chrono::steady_clock::now();
    // The visibility of a smooth line ignores the triangles around its face's corners.
    auto add_rings_for = [&](std::span<const FeatureSegment> segments) {
        if (std::any_of(segments.begin(), segments.end(),
                        [](const FeatureSegment& s) { return s.smooth; }))
            add_vertex_rings(out.mesh);
    };
    add_rings_for(out.segments);
    const VisibilityContext visibility_context{scene, out.mesh, accel, view, &out.instances};
    InstanceVisibility instance_visibility{
        visibility, split_by_visibility(out.segments, visibility_context, visibility, threads)};
    out.timings.visibility = seconds_since(start);

    // The instances' segments come with their pieces (their visibility is timed with the
    // edges), and only those that keep a piece.
    start = std::chrono::steady_clock::now();
    const std::size_t first_instance_segment = out.segments.size();
    add_instance_segments(scene, accel, out.mesh, plane, view, settings.visibility.margin, edges,
                          threads, out.instances, out.segments, {}, &instance_visibility);
    const std::size_t end_instance_segment = out.segments.size();
    out.pieces = std::move(instance_visibility.pieces);
    add_polyline_segments(scene, out.segments);
    const LightingModel lighting{settings.lights, settings.band_thresholds};
    const std::vector<std::uint8_t> closed = closed_objects(out.intersections);
    if (settings.bands || settings.shadows) add_vertex_rings(out.mesh);
    for (bool shadow : {false, true}) {
        if (!(shadow ? settings.shadows : settings.bands)) continue;
        std::vector<FeatureSegment> more =
            shadow ? shadow_segments(scene, out.mesh, accel, view, lighting, threads)
                   : band_segments(scene, out.mesh, plane.eye, lighting,
                                   outward_objects(scene, closed, plane.eye), threads);
        out.segments.insert(out.segments.end(), more.begin(), more.end());
    }
    out.timings.edges += seconds_since(start);

    // The tone's pens and strokes (after every line's segments, so its strokes come last).
    start = std::chrono::steady_clock::now();
    StyleResolver styles(scene, settings, out.styles);
    const bool tone = tone_look(settings);
    std::vector<ToneDot> dots;
    std::vector<std::uint16_t> pen_of_triangle;
    std::vector<TonePen> tone_pens_;
    if (tone) {
        tone_pens(scene, settings, styles, out.styles, height, pen_of_triangle, tone_pens_);
        const ToneContext context{scene,           out.mesh,
                                  accel,           view,
                                  plane,           *settings.tone_shading,
                                  settings.lights, settings.band_thresholds,
                                  settings.tone,   pen_of_triangle,
                                  tone_pens_,      width,
                                  height,          closed};
        if (settings.tone.mode == ToneMode::Hatch) {
            std::vector<FeatureSegment> hatch = hatch_segments(context, threads);
            out.segments.insert(out.segments.end(), hatch.begin(), hatch.end());
        } else {
            dots = screentone_dots(context, threads);
        }
    }
    out.timings.tone = seconds_since(start);

    start = std::chrono::steady_clock::now();
    const std::span<const FeatureSegment> rest =
        std::span(out.segments).subspan(end_instance_segment);
    add_rings_for(rest);
    std::vector<std::vector<EdgePiece>> later(1);
    later[0] = split_by_visibility(rest, visibility_context, visibility, threads);
    for (EdgePiece& piece : later[0])
        piece.segment += static_cast<std::uint32_t>(end_instance_segment);
    append_parts(later, out.pieces);
    // Tone is drawn where it is seen only: its hidden pieces are not strokes.
    if (tone)
        std::erase_if(out.pieces,
                      [](const EdgePiece& p) { return p.type == EdgeType::Tone && !p.visible(); });
    out.timings.visibility += seconds_since(start);

    start = std::chrono::steady_clock::now();
    const std::vector<SegmentStyles> segment_styles =
        resolve_segment_styles(scene, out.segments, styles);
    bool by_depth = false, sketchy = false;
    for (const LineStyle& style : out.styles) {
        by_depth = by_depth || style.by_depth;
        sketchy = sketchy || style.sketch >= 2.0f;
    }
    if (by_depth) chain.eye = plane.eye;
    chain.world = sketchy;
    // A crowd's chaining was a serial stage of its frame, and its tables of line ends the
    // frame's peak: the instances' pieces are chained in parts, in parallel.
    out.strokes =
        chain_pieces_in_parts(out.pieces,
                              instance_chain_cuts(out.pieces, out.segments, first_instance_segment,
                                                  end_instance_segment, 4096),
                              chain, segment_styles, threads);
    // Dots: one-point strokes as wide as their darkness asks.
    for (const ToneDot& dot : dots) {
        const std::uint16_t style = styles.index(dot.prim, EdgeType::Tone, true);
        const float pen_width = stroke_thickness(out.styles[style].width, height);
        if (!(pen_width > 0.0f)) continue;
        Stroke& s = out.strokes.emplace_back();
        s.type = EdgeType::Tone;
        s.points = {dot.centre, dot.centre};
        s.style = style;
        s.scale = 2.0f * dot.radius / pen_width;
    }
    out.timings.chaining = seconds_since(start);

    start = std::chrono::steady_clock::now();
    out.pens.clear();
    float depth_reference = 0.0f;
    if (by_depth) {
        const BBox bounds = scene.bounds();
        depth_reference = length((bounds.lo + bounds.hi) * 0.5f - plane.eye);
    }
    for (const LineStyle& style : out.styles)
        out.pens.push_back(stroke_pen(style, height, depth_reference, settings.brushes));
    if (sketchy) {
        // A pixel's size in the world at the distance of the scene's centre.
        const BBox bounds = scene.bounds();
        const float depth = view.depth((bounds.lo + bounds.hi) * 0.5f);
        const float world_per_pixel =
            std::max(depth, view.near_depth()) * length(plane.step_x) / view.plane_distance();
        out.strokes =
            sketch_strokes(std::move(out.strokes), out.pens, world_per_pixel, settings.frame);
    }
    // Tone strokes come after every line's (above): the lines are the strokes before them.
    const auto first_tone = static_cast<std::size_t>(
        std::find_if(out.strokes.begin(), out.strokes.end(),
                     [](const Stroke& s) { return s.type == EdgeType::Tone; }) -
        out.strokes.begin());
    const std::span<const Stroke> lines(out.strokes.data(), first_tone);
    if ((settings.drawn_types | (1u << static_cast<unsigned>(EdgeType::Tone))) ==
        (1u << kEdgeTypeCount) - 1) {
        draw_styled_strokes(lines, out.pens, width, height, out.coverage, out.style, threads);
    } else {
        std::vector<Stroke> drawn;
        for (const Stroke& stroke : lines)
            if (settings.drawn_types & (1u << static_cast<unsigned>(stroke.type)))
                drawn.push_back(stroke);
        draw_styled_strokes(drawn, out.pens, width, height, out.coverage, out.style, threads);
    }
    if (tone) {
        draw_styled_strokes(std::span<const Stroke>(out.strokes).subspan(first_tone), out.pens,
                            width, height, out.tone_coverage, out.tone_style, threads);
    } else {
        out.tone_coverage.reshape(0, 0);
        out.tone_style.reshape(0, 0);
    }
    out.timings.drawing = seconds_since(start);
}

}  // namespace toonray::ink
