#include "toonray/render/renderer.h"

#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "toonray/core/error.h"
#include "toonray/core/parallel.h"
#include "toonray/core/saturating.h"
#include "toonray/render/classic.h"
#include "toonray/render/trace.h"

namespace toonray {
namespace {

// A distinct, stable colour for an id (AOVs); black for misses.
Rgb8 id_colour(std::uint32_t id) {
    if (id == kNoIndex) return {0, 0, 0};
    std::uint32_t h = id * 2654435761u;
    h ^= h >> 15;
    return {static_cast<std::uint8_t>(64 + (h & 127)),
            static_cast<std::uint8_t>(64 + ((h >> 8) & 127)),
            static_cast<std::uint8_t>(64 + ((h >> 16) & 127))};
}

// Depth, normal and id images at pixel resolution from the first sample of each pixel.
void gbuffer_feature_images(const GBuffer& g, Aovs& aovs) {
    const int sub = g.sub;
    const int w = g.view_depth.width() / sub, h = g.view_depth.height() / sub;
    float z_max = 0.0f;
    for (std::size_t i = 0; i < g.view_depth.size(); ++i)
        if (std::isfinite(g.view_depth.data()[i])) z_max = std::max(z_max, g.view_depth.data()[i]);
    aovs.depth.resize(w, h);
    aovs.normal.resize(w, h);
    aovs.object_id.resize(w, h);
    aovs.material_id.resize(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            int fx = x * sub, fy = y * sub;
            float z = g.view_depth(fx, fy);
            aovs.depth(x, y) = std::isfinite(z) && z_max > 0
                                   ? static_cast<std::uint8_t>(std::lround(z / z_max * 255.0f))
                                   : 255;
            Vec3f n = g.geometric_normal(fx, fy);
            aovs.normal(x, y) = std::isfinite(z)
                                    ? Rgb8{to_byte(n.x * 0.5f + 0.5f), to_byte(n.y * 0.5f + 0.5f),
                                           to_byte(n.z * 0.5f + 0.5f)}
                                    : Rgb8{0, 0, 0};
            aovs.object_id(x, y) = id_colour(g.object(fx, fy));
            aovs.material_id(x, y) = id_colour(g.material(fx, fy));
        }
}

// gbuffer_feature_images, and the line seeds of each type filtered down.
void robust_feature_images(const GBuffer& g, const Image<std::uint8_t>& seeds, Aovs& aovs,
                           int threads) {
    gbuffer_feature_images(g, aovs);
    resolve_seed_type(seeds, kLineSilhouette, g.sub, aovs.lines_silhouette, threads);
    resolve_seed_type(seeds, kLineCrease, g.sub, aovs.lines_crease, threads);
    resolve_seed_type(seeds, kLineDepth, g.sub, aovs.lines_depth, threads);
    resolve_seed_type(seeds, kLineObject, g.sub, aovs.lines_object, threads);
    resolve_seed_type(seeds, kLineMaterial, g.sub, aovs.lines_material, threads);
}

// The mean colour of each pixel's sub x sub samples, as bytes.
void average_samples(const Image<Vec3f>& fine, int sub, ImageRgb8& out, int threads) {
    const int w = fine.width() / sub, h = fine.height() / sub;
    out.reshape(w, h);
    const float inv_n = 1.0f / static_cast<float>(sub * sub);
    parallel_for(h, 8, threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < w; ++x) {
                Vec3f sum(0.0f);
                for (int j = 0; j < sub; ++j)
                    for (int i = 0; i < sub; ++i) sum += fine(x * sub + i, y * sub + j);
                out(x, y) = {to_byte(sum.x * inv_n), to_byte(sum.y * inv_n),
                             to_byte(sum.z * inv_n)};
            }
    });
}

}  // namespace

ink::InkSettings ink_settings(const RenderSettings& settings) {
    ink::InkSettings s;
    const unsigned types = settings.lines.types;
    s.edges.silhouettes = (types & kLineSilhouette) != 0;
    s.edges.borders = (types & kLineSilhouette) != 0;
    s.edges.creases = (types & kLineCrease) != 0;
    s.edges.materials = (types & kLineMaterial) != 0;
    s.edges.intersections = (types & kLineObject) != 0;
    s.edges.crease_angle = settings.lines.crease_angle;
    s.width = settings.lines.width;
    s.colour = settings.lines.colour;
    s.taper = settings.line_taper;
    s.width_by_depth = settings.line_width_by_depth;
    s.styles = settings.line_styles;
    s.chain.hidden = settings.hidden_lines;
    return s;
}

Vec3f default_light(const Scene& scene, const ViewPlane& view) {
    BBox b = scene.bounds();
    float radius = b.empty() ? 1.0f : 0.5f * length(b.extent());
    return view.eye + (view.up + view.right) * (0.5f * radius);
}

int samples_per_side(int samples) {
    for (int sub = 1; sub <= 4; ++sub)
        if (sub * sub == samples) return sub;
    throw Error(fmt::format("{} samples per pixel: must be 1, 4, 9 or 16 (a square grid per pixel)",
                            samples));
}

std::span<const FeatureImage> feature_images() {
    static const FeatureImage kImages[] = {
        {"depth", true, true, true, &Aovs::depth},
        {"normal", true, true, true, &Aovs::normal},
        {"edges_depth", true, false, false, &Aovs::edges_depth},
        {"edges_normal", true, false, false, &Aovs::edges_normal},
        {"edges", true, true, true, &Aovs::edges},
        {"cel", true, true, true, &Aovs::cel},
        {"lines_silhouette", false, true, true, &Aovs::lines_silhouette},
        {"lines_crease", false, true, true, &Aovs::lines_crease},
        {"lines_depth", false, true, false, &Aovs::lines_depth},
        {"lines_object", false, true, false, &Aovs::lines_object},
        {"lines_material", false, true, true, &Aovs::lines_material},
        {"lines_border", false, false, true, &Aovs::lines_border},
        {"lines_intersection", false, false, true, &Aovs::lines_intersection},
        {"lines_polyline", false, false, true, &Aovs::lines_polyline},
        {"object_id", false, true, true, &Aovs::object_id},
        {"material_id", false, true, true, &Aovs::material_id},
    };
    return kImages;
}

namespace {

// Bytes per pixel of the feature images of a line mode, from the table.
std::uint64_t feature_bytes_per_pixel(EdgeMode mode) {
    std::uint64_t bytes = 0;
    for (const FeatureImage& f : feature_images())
        if (f.in(mode))
            bytes += std::holds_alternative<ImageRgb8 Aovs::*>(f.image) ? sizeof(Rgb8) : 1;
    return bytes;
}

}  // namespace

std::uint64_t frame_buffer_bytes(const RenderSettings& settings) {
    const std::uint64_t pixels =
        mul_saturated(static_cast<std::uint64_t>(std::max(settings.width, 0)),
                      static_cast<std::uint64_t>(std::max(settings.height, 0)));
    const std::uint64_t final_image = sizeof(Rgb8);
    // Per sample, the G-buffer of prepare_gbuffer: colour, material and object, and the mode's
    // depth and normal.
    const std::uint64_t gbuffer =
        sizeof(float) + sizeof(Vec3f) + sizeof(Vec3f) + 2 * sizeof(std::uint32_t);
    if (settings.edges == EdgeMode::Classic) {
        // The maps the lines are drawn from (depth, normal, edges_depth, edges_normal, edges);
        // cel only as a feature image.
        const std::uint64_t maps = 1 + sizeof(Rgb8) + 3;
        const std::uint64_t per_pixel =
            gbuffer + maps + final_image + (settings.feature_images ? sizeof(Rgb8) : 0);
        return mul_saturated(pixels, per_pixel);
    }
    const std::uint64_t samples = static_cast<std::uint64_t>(std::max(settings.samples, 1));
    const int sub = samples_per_side(settings.samples);
    if (settings.edges == EdgeMode::Ink) {
        // The G-buffer, the line layer (coverage and style) and the final image; with feature
        // images, also the layer one line type is drawn into. The edges, pieces and strokes
        // grow with the scene, not the image: they are not counted here.
        const std::uint64_t line_layer = sizeof(float) + sizeof(std::uint16_t);
        const std::uint64_t per_pixel =
            line_layer + final_image +
            (settings.feature_images ? feature_bytes_per_pixel(EdgeMode::Ink) + line_layer : 0);
        return mul_saturated(pixels, add_saturated(mul_saturated(gbuffer, samples), per_pixel));
    }
    const float thickness = line_thickness(settings.lines.width, settings.height, sub);
    const std::uint64_t per_sample =
        gbuffer + 1 /* line seed */ +
        (line_distance_band(thickness) > kMaxDistanceBand ? sizeof(float) : 0);
    const std::uint64_t per_pixel =
        final_image + (settings.feature_images ? feature_bytes_per_pixel(EdgeMode::Robust) : 0);
    return mul_saturated(pixels, add_saturated(mul_saturated(per_sample, samples), per_pixel));
}

void prepare_gbuffer(GBuffer& g, int width, int height, int sub, EdgeMode mode) {
    const int w = width * sub, h = height * sub;
    const bool classic = mode == EdgeMode::Classic;
    g.sub = sub;
    // Only the buffers this mode reads are kept at full size. No fill: shade_tile writes every
    // sample of the fine grid (the tiles cover it exactly), so filling would only touch the
    // memory twice.
    g.distance.reshape(classic ? w : 0, classic ? h : 0);
    g.normal.reshape(classic ? w : 0, classic ? h : 0);
    g.view_depth.reshape(classic ? 0 : w, classic ? 0 : h);
    g.geometric_normal.reshape(classic ? 0 : w, classic ? 0 : h);
    g.colour.reshape(w, h);
    g.material.reshape(w, h);
    g.object.reshape(w, h);
}

namespace {

// shade_tile for one line mode: the mode decides which depth and normal are stored, so it is a
// template parameter rather than a test per sample.
template <bool kClassic>
void shade_tile_rows(const ShadingContext& ctx, const ViewPlane& view, const Vec3f& background,
                     const SampleTile& t, GBuffer& g) {
    const Scene& scene = ctx.scene;
    const float inf = std::numeric_limits<float>::infinity();
    const int tw = t.width();
    const Light* plain = plain_point_light(ctx);  // the common case, shaded inline below
    for (int y = t.y0; y < t.y1; ++y) {
        const int first = (y - t.y0) * tw;  // the row's first sample in the tile's arrays
        const Vec3f* dirs = t.dirs + first;
        const Hit* hits = t.hits + first;
        const bool* found = t.found + first;
        float* depth = kClassic ? g.distance.row(y) + t.x0 : g.view_depth.row(y) + t.x0;
        Vec3f* normal = kClassic ? g.normal.row(y) + t.x0 : g.geometric_normal.row(y) + t.x0;
        Vec3f* colour = g.colour.row(y) + t.x0;
        std::uint32_t* material = g.material.row(y) + t.x0;
        std::uint32_t* object = g.object.row(y) + t.x0;
        for (int i = 0; i < tw; ++i) {
            if (!found[i]) {
                depth[i] = inf;
                normal[i] = Vec3f(0.0f);
                colour[i] = background;
                material[i] = kNoIndex;
                object[i] = kNoIndex;
                continue;
            }
            const Hit& hit = hits[i];
            const Vec3f& dir = dirs[i];
            const Vec3f n = shading_normal(scene, hit, dir);
            if constexpr (kClassic) {
                depth[i] = hit.t;
                normal[i] = n;
            } else {
                depth[i] = hit.t * dot(dir, view.forward);
                normal[i] = geometric_normal(scene, hit, dir);
            }
            const std::uint32_t m = scene.tri_material[hit.prim];
            colour[i] = plain && !material_texture(ctx, m)
                            ? shade_plain(ctx, *plain, hit, view.eye, dir, n)
                            : shade_hit(ctx, hit, view.eye, dir, n);
            material[i] = m;
            object[i] = scene.tri_object[hit.prim];
        }
    }
}

}  // namespace

void shade_tile(const ShadingContext& ctx, const ViewPlane& view, const RenderSettings& settings,
                const SampleTile& tile, GBuffer& g) {
    if (settings.edges == EdgeMode::Classic)
        shade_tile_rows<true>(ctx, view, settings.background, tile, g);
    else shade_tile_rows<false>(ctx, view, settings.background, tile, g);
}

void Renderer::trace(const Scene& scene, const TriangleAccel& accel, const ViewPlane& view,
                     const RenderSettings& settings, int sub, const TextureSet* textures) {
    const ShadingContext shading{scene, accel, settings.shading, lights_, textures};
    prepare_gbuffer(gbuffer_, settings.width, settings.height, sub, settings.edges);
    trace_primary(accel, view, settings.width, settings.height, sub, settings.threads,
                  [&](const SampleTile& t) { shade_tile(shading, view, settings, t, gbuffer_); });
}

const Aovs& Renderer::aovs() const {
    static const Aovs kNone;
    return feature_images_ ? aovs_ : kNone;
}

const ImageRgb8& Renderer::render(const Scene& scene, const TriangleAccel& accel,
                                  const CameraSpec& camera, const RenderSettings& settings,
                                  const TextureSet* textures) {
    ViewPlane view = make_view_plane(camera, settings.width, settings.height);
    light_ = settings.light ? *settings.light : default_light(scene, view);
    lights_ = settings.shading.lights;
    feature_images_ = settings.feature_images;
    if (lights_.empty()) lights_.push_back(Light{Light::Kind::Point, light_, 1.0f});
    if (settings.edges == EdgeMode::Classic) {
        trace(scene, accel, view, settings, 1, textures);
        render_classic(settings);
    } else if (settings.edges == EdgeMode::Ink) {
        trace(scene, accel, view, settings, samples_per_side(settings.samples), textures);
        render_ink(scene, accel, camera, settings);
    } else {
        trace(scene, accel, view, settings, samples_per_side(settings.samples), textures);
        render_robust(settings);
    }
    return final_;
}

void Renderer::render_classic(const RenderSettings& settings) {
    const int threads = settings.threads;
    classic_depth_map(gbuffer_.distance, aovs_.depth, threads);
    classic_normal_map(gbuffer_.normal, gbuffer_.distance, aovs_.normal, threads);
    sobel_edges(aovs_.depth, settings.depth_threshold, aovs_.edges_depth, threads);
    sobel_edges(aovs_.normal, settings.normal_threshold, aovs_.edges_normal, threads);
    merge_edges(aovs_.edges_depth, aovs_.edges_normal, aovs_.edges);
    compose_lines(gbuffer_.colour, aovs_.edges, final_, threads,
                  settings.feature_images ? &aovs_.cel : nullptr);
}

void Renderer::render_robust(const RenderSettings& settings) {
    const int threads = settings.threads;
    const GBuffer& g = gbuffer_;
    FineBuffers fine{g.view_depth, g.geometric_normal, g.object, g.material};
    find_line_seeds(fine, settings.lines, seeds_, threads);
    float thickness = line_thickness(settings.lines.width, settings.height, g.sub);
    // Distance to the seeds and line coverage in one banded pass: no full-size distance image.
    const bool features = settings.feature_images;
    resolve_lines_from_seeds(g.colour, seeds_, thickness, g.sub, settings.lines.colour, final_,
                             features ? &aovs_.cel : nullptr, features ? &aovs_.edges : nullptr,
                             threads);
    if (features) robust_feature_images(g, seeds_, aovs_, threads);
}

void Renderer::render_ink(const Scene& scene, const TriangleAccel& accel, const CameraSpec& camera,
                          const RenderSettings& settings) {
    const int threads = settings.threads;
    const GBuffer& g = gbuffer_;
    average_samples(g.colour, g.sub, final_, threads);
    const bool features = settings.feature_images;
    if (features) aovs_.cel = final_;
    ink::draw_ink_lines(scene, accel, camera, settings.width, settings.height,
                        ink_settings(settings), threads, ink_);
    ink::composite_styled_lines(ink_.coverage, ink_.style, ink_.pens, final_);
    if (features) {
        ink::coverage_to_gray(ink_.coverage, aovs_.edges);
        ink_type_feature_images(settings, threads);
        gbuffer_feature_images(g, aovs_);
    }
}

void Renderer::ink_type_feature_images(const RenderSettings& settings, int threads) {
    // Indexed by ink::EdgeType.
    static constexpr ImageGray8 Aovs::*kTypeImages[ink::kEdgeTypeCount] = {
        &Aovs::lines_silhouette, &Aovs::lines_border,       &Aovs::lines_crease,
        &Aovs::lines_material,   &Aovs::lines_intersection, &Aovs::lines_polyline};
    // One line layer (coverage and style) for the types in turn, freed after: frame_buffer_bytes
    // counts it.
    ImageF coverage;
    Image<std::uint16_t> style;
    std::vector<ink::Stroke> strokes;
    for (int type = 0; type < ink::kEdgeTypeCount; ++type) {
        // The strokes of one type drawn with their own pens, exactly as in the frame's layer.
        strokes.clear();
        for (const ink::Stroke& s : ink_.strokes)
            if (static_cast<int>(s.type) == type) strokes.push_back(s);
        ink::draw_styled_strokes(strokes, ink_.pens, settings.width, settings.height, coverage,
                                 style, threads);
        ink::coverage_to_gray(coverage, aovs_.*kTypeImages[type]);
    }
}

}  // namespace toonray
