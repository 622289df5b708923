#include "toonray/render/renderer.h"

#include <algorithm>
#include <atomic>
#include <fmt/format.h>

#include "toonray/core/error.h"
#include "toonray/core/saturating.h"
#include "toonray/ink/draw.h"
#include "toonray/render/line_step.h"
#include "toonray/render/look.h"
#include "toonray/render/sampler.h"

namespace toonray {

int samples_per_side(int samples) {
    for (int sub = 1; sub <= 4; ++sub)
        if (sub * sub == samples) return sub;
    throw Error(fmt::format("{} samples per pixel: must be 1, 4, 9 or 16 (a square grid per pixel)",
                            samples));
}

int LineStep::samples_per_side(const RenderSettings& settings) const {
    return toonray::samples_per_side(settings.sampling.samples);
}

namespace {

LineStep& step_for(LineMode mode, const std::unique_ptr<LineStep>& classic,
                   const std::unique_ptr<LineStep>& robust, const std::unique_ptr<LineStep>& ink) {
    return mode == LineMode::Classic ? *classic : (mode == LineMode::Robust ? *robust : *ink);
}

// The fields of first samples: the lines' and the look's, and everything when the layers are
// asked for.
unsigned first_fields(const LineStep& step, const RenderSettings& settings) {
    if (settings.layers) return kSurfaceAll;
    return step.first_fields(settings) | look_fields(settings.shading);
}

unsigned rest_fields(const LineStep& step, const RenderSettings& settings) {
    return step.rest_fields(settings) | look_fields(settings.shading);
}

// Whether a frame keeps strokes: the ink lines, polylines (drawn as strokes in every mode), or
// an SVG asked for.
bool keeps_strokes(const Scene& scene, const RenderSettings& settings) {
    return settings.lines.mode == LineMode::Ink || settings.strokes || !scene.polylines.empty();
}

// A tone look is drawn as ink under the ink lines; the other modes draw the cel look
// (frame/settings.h, check_settings, refuses it there).
bool tone_look(const RenderSettings& settings) {
    return settings.tone.mode != ink::ToneMode::Cel && settings.lines.mode == LineMode::Ink;
}

// The band of a point as the frame's shading finds it, for the tone's strokes: the light terms
// of a hit there seen from the eye, toon shadows included.
class ShadedBands final : public ink::ToneShading {
public:
    ShadedBands(const ShadingContext& shading, const Vec3f& eye) : shading_(shading), eye_(eye) {}

    std::uint8_t band(std::uint32_t prim, float u, float v, const Vec3f& p) const override {
        Vec3f dir = p - eye_;
        const float t = length(dir);
        if (!(t > 0.0f)) return 0;
        dir = dir / t;
        const Hit hit{t, prim, u, v};
        return light_terms(shading_, hit, eye_, dir, shading_normal(shading_.scene, hit, dir)).band;
    }
    bool bands_follow_corners() const override { return !shading_.settings.shadows; }

private:
    const ShadingContext& shading_;
    Vec3f eye_;
};

}  // namespace

std::uint64_t layer_bytes_per_pixel(LineMode mode) {
    // cel, distance, view depth, both normals, ids, band, light, position, uv, refined, lines,
    // and the line types of the mode (classic 2, robust 5 and the polylines, ink 6).
    // Ink: each type but tone (8), and the tone layer.
    const std::uint64_t types = mode == LineMode::Classic ? 3 : (mode == LineMode::Robust ? 6 : 9);
    return sizeof(Rgb8) + 2 * sizeof(float) + 2 * sizeof(Vec3f) + 2 * sizeof(std::uint32_t) + 1 +
           sizeof(float) + sizeof(Vec3f) + sizeof(Vec2f) + 1 + sizeof(float) +
           types * sizeof(float);
}

/// One thread's buffers for its buckets.
struct Renderer::Buffers {
    BucketSampler sampler;
};

Renderer::Renderer()
    : buffers_(std::make_unique<PerThread<Buffers>>()),
      classic_(make_classic_lines()),
      robust_(make_robust_lines()),
      ink_lines_(make_ink_lines()) {}
Renderer::~Renderer() = default;
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;

std::uint64_t Renderer::bucket_bytes() const {
    std::uint64_t bytes = 0;
    buffers_->for_each([&](const Buffers& b) { bytes += b.sampler.bytes(); });
    return bytes + classic_->held_bytes() + robust_->held_bytes() + ink_lines_->held_bytes();
}

std::uint64_t Renderer::held_bytes() const {
    const FrameLayers& l = layers_;
    std::uint64_t bytes = bytes_of(l.image) + bytes_of(l.cel) + bytes_of(l.distance) +
                          bytes_of(l.view_depth) + bytes_of(l.normal) +
                          bytes_of(l.geometric_normal) + bytes_of(l.object) + bytes_of(l.material) +
                          bytes_of(l.band) + bytes_of(l.light) + bytes_of(l.position) +
                          bytes_of(l.uv) + bytes_of(l.refined) + bytes_of(l.lines) +
                          bytes_of(l.tone) + bytes_of(ink_.coverage) + bytes_of(ink_.style) +
                          bytes_of(ink_.tone_coverage) + bytes_of(ink_.tone_style);
    for (const LineLayer& type : l.line_types) bytes += bytes_of(type.coverage);
    for (const auto* step : {classic_.get(), robust_.get(), ink_lines_.get()})
        bytes += step->held_frame_bytes();
    return bytes + bucket_bytes();
}

std::uint64_t frame_buffer_bytes(const RenderSettings& settings, int lights) {
    static const std::unique_ptr<LineStep> kClassic = make_classic_lines(),
                                           kRobust = make_robust_lines(), kInk = make_ink_lines();
    const LineStep& step = step_for(settings.lines.mode, kClassic, kRobust, kInk);
    const std::uint64_t pixels =
        mul_saturated(static_cast<std::uint64_t>(std::max(settings.width, 0)),
                      static_cast<std::uint64_t>(std::max(settings.height, 0)));
    std::uint64_t per_pixel = sizeof(Rgb8) + step.frame_bytes_per_pixel(settings);
    if (settings.layers) per_pixel += layer_bytes_per_pixel(settings.lines.mode);
    // The largest bucket, grown by the halo (and one pixel more for the first samples) within
    // the image, for each thread.
    const int sub = step.samples_per_side(settings);
    const std::uint64_t halo = static_cast<std::uint64_t>(step.halo(settings));
    const std::uint64_t tile = static_cast<std::uint64_t>(std::max(settings.sampling.tile_size, 1));
    const std::uint64_t w = static_cast<std::uint64_t>(std::max(settings.width, 0));
    const std::uint64_t h = static_cast<std::uint64_t>(std::max(settings.height, 0));
    auto side = [&](std::uint64_t image, std::uint64_t grow) {
        return std::min(image, std::min(tile, image) + 2 * grow);
    };
    const std::uint64_t decided = mul_saturated(side(w, halo), side(h, halo));
    const std::uint64_t traced = mul_saturated(side(w, halo + 1), side(h, halo + 1));
    const std::uint64_t bucket =
        add_saturated(BucketSampler::max_bytes(traced, decided, sub, first_fields(step, settings),
                                               rest_fields(step, settings), std::max(lights, 1)),
                      step.bucket_bytes(settings, decided));
    const int threads = settings.threads > 0 ? settings.threads : hardware_threads();
    const std::uint64_t buckets =
        mul_saturated(static_cast<std::uint64_t>(std::max(threads, 1)), bucket);
    return add_saturated(mul_saturated(pixels, per_pixel), buckets);
}

const ImageRgb8& Renderer::render(const Scene& scene, const TriangleAccel& accel,
                                  const CameraSpec& camera, std::span<const Light> lights,
                                  const RenderSettings& settings, const TextureSet* textures,
                                  RenderProgress* progress) {
    auto check_cancel = [progress] {
        if (progress && progress->cancel.load(std::memory_order_relaxed)) throw RenderCancelled();
    };
    check_cancel();
    const ViewPlane view = make_view_plane(camera, settings.width, settings.height);
    LineStep& step = step_for(settings.lines.mode, classic_, robust_, ink_lines_);
    const FrameContext frame{scene, accel, camera, view, settings, step.samples_per_side(settings)};
    const ShadingContext shading{scene, accel, settings.shading, lights, textures};
    layers_.mode = settings.lines.mode;
    layers_.line_types.clear();
    if (!settings.layers) {  // nothing of an earlier frame's layers stays
        layers_.cel.reshape(0, 0);
        layers_.lines.reshape(0, 0);
        layers_.tone.reshape(0, 0);
    }
    if (keeps_strokes(scene, settings) || tone_look(settings)) {
        const ShadedBands bands(shading, view.eye);
        ink::InkSettings ink = ink_settings(settings);
        ink.lights = lights;
        if (tone_look(settings)) ink.tone_shading = &bands;
        ink::draw_ink_lines(scene, accel, camera, settings.width, settings.height, ink,
                            settings.threads, ink_);
        layers_.strokes = &ink_;
    } else {
        layers_.strokes = nullptr;
    }
    check_cancel();
    step.begin(frame, layers_);
    render_buckets(frame, shading, step, progress);
    check_cancel();
    step.finish(frame, layers_);
    if (settings.lines.mode != LineMode::Ink && !scene.polylines.empty())
        strokes_over_picture(settings);
    return layers_.image;
}

void Renderer::render_buckets(const FrameContext& frame, const ShadingContext& shading,
                              LineStep& step, RenderProgress* progress) {
    const RenderSettings& settings = frame.settings;
    const int w = settings.width, h = settings.height;
    const bool layers = settings.layers;
    // Colours vary inside a surface and band only with textures or vertex colours.
    bool textured = false;
    for (std::uint32_t m = 0; m < frame.scene.materials.size(); ++m)
        textured = textured || material_texture(shading, m) != nullptr;
    // A tone look shows each band at its full colour: the tone's ink gives its darkness.
    ShadingSettings full;
    if (tone_look(settings)) {
        full = settings.shading;
        std::fill(full.ramp.levels.begin(), full.ramp.levels.end(), 1.0f);
    }
    const LookFrame look{frame.scene, tone_look(settings) ? full : settings.shading,
                         settings.background, textured || frame.scene.has_colours(),
                         !tone_look(settings)};
    SamplerFrame sampling{frame.accel,
                          shading,
                          look,
                          frame.view,
                          w,
                          h,
                          frame.sub,
                          settings.sampling.adaptive,
                          step.refine_rule(settings),
                          first_fields(step, settings),
                          rest_fields(step, settings),
                          step.covered()};
    FrameLayers& out = layers_;
    out.image.reshape(w, h);
    const int lw = layers ? w : 0, lh = layers ? h : 0;
    out.distance.reshape(lw, lh);
    out.view_depth.reshape(lw, lh);
    out.normal.reshape(lw, lh);
    out.geometric_normal.reshape(lw, lh);
    out.object.reshape(lw, lh);
    out.material.reshape(lw, lh);
    out.band.reshape(lw, lh);
    out.light.reshape(lw, lh);
    out.position.reshape(lw, lh);
    out.uv.reshape(lw, lh);
    out.refined.reshape(lw, lh);
    const int halo = step.halo(settings);
    const BucketGrid grid{w, h, std::max(settings.sampling.tile_size, 1)};
    std::atomic<std::uint64_t> refined{0};
    if (progress) {
        progress->buckets_done = 0;
        progress->buckets = static_cast<std::uint32_t>(grid.count());
    }
    parallel_for(grid.count(), 1, settings.threads, [&](int begin, int end) {
        BucketSampler& sampler = buffers_->local().sampler;
        for (int index = begin; index < end; ++index) {
            if (progress && progress->cancel.load(std::memory_order_relaxed)) return;
            Bucket bucket;
            bucket.pixels = grid.bucket(index);
            bucket.decided = bucket.pixels.grown(halo, w, h);
            // One pixel more is traced around the decided ones, for their neighbours' first
            // samples; one sample per pixel needs no neighbours.
            const PixelRect traced = frame.sub > 1 ? bucket.decided.grown(1, w, h) : bucket.decided;
            sampler.sample(sampling, traced, bucket.decided);
            step.bucket(frame, bucket, sampler, out);
            std::uint64_t count = 0;
            const SurfaceSamples& first = sampler.first();
            for (int y = bucket.pixels.y0; y < bucket.pixels.y1; ++y)
                for (int x = bucket.pixels.x0; x < bucket.pixels.x1; ++x) {
                    const bool all = sampler.refined(x, y);
                    count += all ? 1 : 0;
                    if (!layers) continue;
                    const std::size_t i = sampler.first_index(x, y);
                    out.distance(x, y) = first.distance[i];
                    out.view_depth(x, y) = first.view_depth[i];
                    out.normal(x, y) = first.normal[i];
                    out.geometric_normal(x, y) = first.geometric_normal[i];
                    out.object(x, y) = first.object[i];
                    out.material(x, y) = first.material[i];
                    out.band(x, y) = first.band[i];
                    out.light(x, y) = first.diffuse[i];
                    out.position(x, y) = first.position[i];
                    out.uv(x, y) = first.uv[i];
                    out.refined(x, y) = all ? 1 : 0;
                }
            refined += count;
            if (progress) progress->buckets_done.fetch_add(1, std::memory_order_relaxed);
        }
    });
    refined_pixels_ = refined;
}

void Renderer::strokes_over_picture(const RenderSettings& settings) {
    // The polylines, drawn as strokes over the picture of a mode whose lines are not strokes:
    // the only strokes drawn into the line layer there (ink_settings).
    ink::composite_styled_lines(ink_.coverage, ink_.style, ink_.pens, layers_.image);
    if (!settings.layers) return;
    LineLayer& polylines = layers_.line_types.emplace_back();
    polylines.name = "polyline";
    polylines.coverage = ink_.coverage;
    for (std::size_t i = 0; i < layers_.lines.size(); ++i)
        layers_.lines.data()[i] = std::max(layers_.lines.data()[i], ink_.coverage.data()[i]);
}

}  // namespace toonray
