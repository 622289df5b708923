#include "toonray/render/renderer.h"

#include <atomic>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "toonray/core/error.h"
#include "toonray/core/parallel.h"
#include "toonray/core/saturating.h"
#include "toonray/core/portable_math.h"
#include "toonray/render/classic.h"
#include "toonray/render/sampler.h"
#include "toonray/render/shade_samples.h"
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

// A feature image's byte for a normal: each channel's n * 0.5 + 0.5.
Rgb8 normal_colour(const Vec3f& n) {
    return {to_byte(n.x * 0.5f + 0.5f), to_byte(n.y * 0.5f + 0.5f), to_byte(n.z * 0.5f + 0.5f)};
}

// Copies the pixels of `to_rect` from `from`, whose pixel (0, 0) is pixel (from_x0, from_y0) of
// the frame, into the frame image `to`.
template <typename T>
void copy_rect(const Image<T>& from, int from_x0, int from_y0, const PixelRect& to_rect,
               Image<T>& to) {
    for (int y = to_rect.y0; y < to_rect.y1; ++y)
        std::copy_n(from.row(y - from_y0) + (to_rect.x0 - from_x0), to_rect.width(),
                    to.row(y) + to_rect.x0);
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
        {"samples", false, true, true, &Aovs::samples},
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

int robust_halo(float thickness, int sub) {
    const float reach = thickness > 0.0f ? thickness * 0.5f + 0.5f : 0.0f;
    const int fine = static_cast<int>(std::ceil(reach)) + 1;
    return (fine + sub - 1) / sub;
}

std::uint64_t bucket_buffer_bytes(const RenderSettings& settings) {
    const int sub = samples_per_side(settings.samples);
    const bool robust = settings.edges == EdgeMode::Robust;
    const float thickness =
        robust ? line_thickness(settings.lines.width, settings.height, sub) : 0.0f;
    const std::uint64_t halo = robust ? static_cast<std::uint64_t>(robust_halo(thickness, sub)) : 0;
    // The largest bucket, grown by the halo (and one pixel more for the first samples) within
    // the image.
    const std::uint64_t tile = static_cast<std::uint64_t>(std::max(settings.tile_size, 1));
    const std::uint64_t w = static_cast<std::uint64_t>(std::max(settings.width, 0));
    const std::uint64_t h = static_cast<std::uint64_t>(std::max(settings.height, 0));
    auto side = [&](std::uint64_t image, std::uint64_t grow) {
        return std::min(image, std::min(tile, image) + 2 * grow);
    };
    const std::uint64_t decided = mul_saturated(side(w, halo), side(h, halo));
    const std::uint64_t traced = mul_saturated(side(w, halo + 1), side(h, halo + 1));
    const std::uint64_t samples = static_cast<std::uint64_t>(sub) * sub;
    // A sample's colour, view depth, normal, ids and hit flag; while traced also its direction,
    // hit and found flag.
    const std::uint64_t surface = 2 * sizeof(Vec3f) + sizeof(float) + 2 * sizeof(std::uint32_t) + 1;
    const std::uint64_t ray = sizeof(Vec3f) + sizeof(Hit) + 1;
    // The rays of one traced tile and their sample columns and rows.
    const std::uint64_t tile_rays = TriangleAccel::kTileSize * TriangleAccel::kTileSize;
    std::uint64_t bytes = tile_rays * ray + 2 * TriangleAccel::kTileSize * sizeof(int);
    // The first samples, with their colours as bytes and keys, the differences to their
    // neighbours, whether lines hide them, and a row of no differences.
    bytes = add_saturated(
        bytes, mul_saturated(traced, surface + sizeof(Rgb8) + sizeof(std::uint32_t) + 3));
    bytes = add_saturated(bytes, side(w, halo + 1));
    // Every other sample of every decided pixel, with its slot and flag.
    bytes = add_saturated(
        bytes, mul_saturated(decided, add_saturated(mul_saturated(samples - 1, surface + ray),
                                                    1 + 2 * sizeof(std::uint32_t))));
    if (robust) {
        // The fine grid of decided pixels (depth, normal, colour, ids, seed), the resolved
        // pixels (final, cel, edges, one line type) and, for very wide lines, the distances.
        const std::uint64_t fine =
            sizeof(float) + 2 * sizeof(Vec3f) + 2 * sizeof(std::uint32_t) + 1 +
            (line_distance_band(thickness) > kMaxDistanceBand ? sizeof(float) : 0);
        bytes = add_saturated(bytes, mul_saturated(mul_saturated(decided, samples), fine));
        bytes = add_saturated(bytes, mul_saturated(decided, 2 * sizeof(Rgb8) + 2));
    }
    return bytes;
}

std::uint64_t frame_buffer_bytes(const RenderSettings& settings) {
    const std::uint64_t pixels =
        mul_saturated(static_cast<std::uint64_t>(std::max(settings.width, 0)),
                      static_cast<std::uint64_t>(std::max(settings.height, 0)));
    const std::uint64_t final_image = sizeof(Rgb8);
    if (settings.edges == EdgeMode::Classic) {
        // The G-buffer of prepare_gbuffer (distance, normal, colour, material, object), the
        // maps the lines are drawn from (depth, normal, edges_depth, edges_normal, edges); cel
        // only as a feature image.
        const std::uint64_t gbuffer = sizeof(float) + 2 * sizeof(Vec3f) + 2 * sizeof(std::uint32_t);
        const std::uint64_t maps = 1 + sizeof(Rgb8) + 3;
        const std::uint64_t per_pixel =
            gbuffer + maps + final_image + (settings.feature_images ? sizeof(Rgb8) : 0);
        return mul_saturated(pixels, per_pixel);
    }
    const int threads = settings.threads > 0 ? settings.threads : hardware_threads();
    const std::uint64_t buckets = mul_saturated(static_cast<std::uint64_t>(std::max(threads, 1)),
                                                bucket_buffer_bytes(settings));
    // Feature images: the images themselves and the first samples' depths they are scaled by.
    const std::uint64_t features =
        settings.feature_images ? feature_bytes_per_pixel(settings.edges) + sizeof(float) : 0;
    std::uint64_t per_pixel = final_image + features;
    if (settings.edges == EdgeMode::Ink) {
        // The line layer (coverage and style); with feature images also the layer one line type
        // is drawn into. The edges, pieces and strokes grow with the scene, not the image: they
        // are not counted here.
        const std::uint64_t line_layer = sizeof(float) + sizeof(std::uint16_t);
        // Without feature images also the mask of pixels the lines hide.
        per_pixel += line_layer + (settings.feature_images ? line_layer : 1);
    }
    return add_saturated(mul_saturated(pixels, per_pixel), buckets);
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

// shade_tile for one line mode: the mode decides which depth and normal are stored.
void shade_tile_rows(const ShadingContext& ctx, const ViewPlane& view, const Vec3f& background,
                     const SampleTile& t, GBuffer& g, bool classic) {
    const int tw = t.width();
    for (int y = t.y0; y < t.y1; ++y) {
        const int first = (y - t.y0) * tw;  // the row's first sample in the tile's arrays
        ShadedSamples out;
        out.colour = g.colour.row(y) + t.x0;
        out.material = g.material.row(y) + t.x0;
        out.object = g.object.row(y) + t.x0;
        if (classic) {
            out.distance = g.distance.row(y) + t.x0;
            out.shading_normal = g.normal.row(y) + t.x0;
        } else {
            out.view_depth = g.view_depth.row(y) + t.x0;
            out.geometric_normal = g.geometric_normal.row(y) + t.x0;
        }
        shade_samples(ctx, view, background, tw, t.dirs + first, t.hits + first, t.found + first,
                      out);
    }
}

}  // namespace

void shade_tile(const ShadingContext& ctx, const ViewPlane& view, const RenderSettings& settings,
                const SampleTile& tile, GBuffer& g) {
    shade_tile_rows(ctx, view, settings.background, tile, g, settings.edges == EdgeMode::Classic);
}

struct Renderer::Bucket {
    PixelRect pixels;   ///< the bucket's own pixels
    PixelRect decided;  ///< and the halo the robust lines need
};

/// One thread's buffers for its buckets.
struct Renderer::BucketBuffers {
    BucketSampler sampler;
    GBuffer fine;  ///< robust lines: the fine grid of the bucket and its halo
    Image<std::uint8_t> seeds;
    ImageRgb8 resolved, cel;
    ImageGray8 edges, lines;

    [[nodiscard]] std::uint64_t bytes() const {
        auto of = [](const auto& image) {
            return static_cast<std::uint64_t>(image.capacity()) * sizeof(*image.data());
        };
        return sampler.bytes() + of(fine.view_depth) + of(fine.geometric_normal) + of(fine.colour) +
               of(fine.material) + of(fine.object) + of(seeds) + of(resolved) + of(cel) +
               of(edges) + of(lines);
    }
};

Renderer::Renderer() : buckets_(std::make_unique<PerThread<BucketBuffers>>()) {}
Renderer::~Renderer() = default;
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;

std::uint64_t Renderer::bucket_bytes() const {
    std::uint64_t bytes = 0;
    buckets_->for_each([&](const BucketBuffers& b) { bytes += b.bytes(); });
    return bytes;
}

void Renderer::trace(const Scene& scene, const TriangleAccel& accel, const ViewPlane& view,
                     const RenderSettings& settings, const TextureSet* textures) {
    const ShadingContext shading{scene, accel, settings.shading, lights_, textures};
    prepare_gbuffer(gbuffer_, settings.width, settings.height, 1, settings.edges);
    trace_primary(accel, view, settings.width, settings.height, 1, settings.threads,
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
    refined_pixels_ = 0;
    if (lights_.empty()) lights_.push_back(Light{Light::Kind::Point, light_, 1.0f});
    if (settings.edges == EdgeMode::Classic) {
        trace(scene, accel, view, settings, textures);
        render_classic(settings);
        return final_;
    }
    // The other modes keep no frame-sized G-buffer: they render bucket by bucket.
    prepare_gbuffer(gbuffer_, 0, 0, 1, settings.edges);
    if (settings.edges != EdgeMode::Ink) {
        render_buckets(scene, accel, view, settings, textures, nullptr);
        return final_;
    }
    // Ink lines first: where they cover a pixel completely its colour cannot show, so it needs
    // no more than one sample (unless the feature images show the colours without lines).
    ink::draw_ink_lines(scene, accel, camera, settings.width, settings.height,
                        ink_settings(settings), settings.threads, ink_);
    if (!settings.feature_images) ink::opaque_lines(ink_.coverage, ink_.style, ink_.pens, hidden_);
    render_buckets(scene, accel, view, settings, textures,
                   settings.feature_images ? nullptr : hidden_.data());
    render_ink(settings);
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

void Renderer::render_buckets(const Scene& scene, const TriangleAccel& accel, const ViewPlane& view,
                              const RenderSettings& settings, const TextureSet* textures,
                              const std::uint8_t* hidden) {
    const int w = settings.width, h = settings.height;
    const int sub = samples_per_side(settings.samples);
    const bool robust = settings.edges == EdgeMode::Robust;
    const bool features = settings.feature_images;
    const ShadingContext shading{scene, accel, settings.shading, lights_, textures};
    RefineRule rule;
    if (robust) {
        // The robust lines look for creases, depth steps and id changes between samples:
        // pixels next to any of them take all samples. The thresholds are lower than the
        // lines' (a quarter of the crease angle, half the depth step) because first samples
        // are a pixel apart: on the piano's mouldings half the crease angle let through thin
        // chamfers and left 0.5% of pixels off full supersampling, a quarter 0.1%.
        rule.surface = true;
        rule.cos_normal = portable::cos(settings.lines.crease_angle * 0.25f * 3.14159265f / 180.0f);
        rule.depth_step = settings.lines.depth_threshold * 0.5f;
    }
    const SamplerFrame frame{accel, shading, view,     settings.background,
                             w,     h,       sub,      settings.adaptive,
                             rule,  robust,  features, hidden};
    const float thickness = robust ? line_thickness(settings.lines.width, h, sub) : 0.0f;
    const int halo = robust ? robust_halo(thickness, sub) : 0;

    final_.reshape(w, h);
    if (features) {
        first_depth_.reshape(w, h);
        aovs_.normal.reshape(w, h);
        aovs_.object_id.reshape(w, h);
        aovs_.material_id.reshape(w, h);
        aovs_.samples.reshape(w, h);
        if (robust) {
            aovs_.cel.reshape(w, h);
            aovs_.edges.reshape(w, h);
            for (ImageGray8 Aovs::*type :
                 {&Aovs::lines_silhouette, &Aovs::lines_crease, &Aovs::lines_depth,
                  &Aovs::lines_object, &Aovs::lines_material})
                (aovs_.*type).reshape(w, h);
        }
    } else {
        first_depth_.reshape(0, 0);
    }
    const BucketGrid grid{w, h, std::max(settings.tile_size, 1)};
    std::atomic<std::uint64_t> refined{0};
    parallel_for(grid.count(), 1, settings.threads, [&](int begin, int end) {
        BucketBuffers& b = buckets_->local();
        for (int index = begin; index < end; ++index) {
            Bucket bucket;
            bucket.pixels = grid.bucket(index);
            bucket.decided = bucket.pixels.grown(halo, w, h);
            b.sampler.sample(frame, bucket.decided.grown(1, w, h), bucket.decided);
            if (robust) resolve_robust_bucket(bucket, b, settings);
            else resolve_ink_bucket(bucket, b);
            if (features) first_sample_features(bucket, b);
            std::uint64_t count = 0;
            for (int y = bucket.pixels.y0; y < bucket.pixels.y1; ++y)
                for (int x = bucket.pixels.x0; x < bucket.pixels.x1; ++x)
                    count += b.sampler.refined(x, y) ? 1 : 0;
            refined += count;
        }
    });
    refined_pixels_ = refined;
    // The depth feature image is classic's 8-bit depth map of the first samples' view depths:
    // lighter is farther, scaled by the frame's farthest surface, 255 where nothing is seen.
    if (features) classic_depth_map(first_depth_, aovs_.depth, settings.threads);
}

void Renderer::resolve_robust_bucket(const Bucket& bucket, BucketBuffers& b,
                                     const RenderSettings& settings) {
    const int sub = samples_per_side(settings.samples);
    GBuffer& g = b.fine;
    g.sub = sub;
    b.sampler.fill_fine(g.view_depth, g.geometric_normal, g.colour, g.material, g.object);
    find_line_seeds(FineBuffers{g.view_depth, g.geometric_normal, g.object, g.material},
                    settings.lines, b.seeds, 1);
    const float thickness = line_thickness(settings.lines.width, settings.height, sub);
    const bool features = settings.feature_images;
    // Distance to the seeds and line coverage in one banded pass, over the bucket and its
    // halo; the bucket's own pixels are exact (robust_halo).
    resolve_lines_from_seeds(g.colour, b.seeds, thickness, sub, settings.lines.colour, b.resolved,
                             features ? &b.cel : nullptr, features ? &b.edges : nullptr, 1);
    const int x0 = bucket.decided.x0, y0 = bucket.decided.y0;
    copy_rect(b.resolved, x0, y0, bucket.pixels, final_);
    if (!features) return;
    copy_rect(b.cel, x0, y0, bucket.pixels, aovs_.cel);
    copy_rect(b.edges, x0, y0, bucket.pixels, aovs_.edges);
    static constexpr std::pair<unsigned, ImageGray8 Aovs::*> kTypes[] = {
        {kLineSilhouette, &Aovs::lines_silhouette},
        {kLineCrease, &Aovs::lines_crease},
        {kLineDepth, &Aovs::lines_depth},
        {kLineObject, &Aovs::lines_object},
        {kLineMaterial, &Aovs::lines_material}};
    for (const auto& [type, image] : kTypes) {
        resolve_seed_type(b.seeds, type, sub, b.lines, 1);
        copy_rect(b.lines, x0, y0, bucket.pixels, aovs_.*image);
    }
}

void Renderer::resolve_ink_bucket(const Bucket& bucket, const BucketBuffers& b) {
    b.sampler.resolve_colours(bucket.pixels, final_, 0, 0);
}

void Renderer::first_sample_features(const Bucket& bucket, const BucketBuffers& b) {
    const SurfaceSamples& first = b.sampler.first();
    for (int y = bucket.pixels.y0; y < bucket.pixels.y1; ++y)
        for (int x = bucket.pixels.x0; x < bucket.pixels.x1; ++x) {
            const std::size_t i = b.sampler.first_index(x, y);
            const bool found = first.found[i] != 0;
            first_depth_(x, y) =
                found ? first.view_depth[i] : std::numeric_limits<float>::infinity();
            aovs_.normal(x, y) = found ? normal_colour(first.normal[i]) : Rgb8{0, 0, 0};
            aovs_.object_id(x, y) = id_colour(found ? first.object[i] : kNoIndex);
            aovs_.material_id(x, y) = id_colour(found ? first.material[i] : kNoIndex);
            aovs_.samples(x, y) = b.sampler.refined(x, y) ? 0 : 255;
        }
}

void Renderer::render_ink(const RenderSettings& settings) {
    const int threads = settings.threads;
    const bool features = settings.feature_images;
    if (features) aovs_.cel = final_;
    ink::composite_styled_lines(ink_.coverage, ink_.style, ink_.pens, final_);
    if (features) {
        ink::coverage_to_gray(ink_.coverage, aovs_.edges);
        ink_type_feature_images(settings, threads);
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
