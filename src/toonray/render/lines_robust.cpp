// The robust line step (render/robust.h): each bucket's fine grid, with the halo its lines reach
// into, gives the bucket's line seeds, and from them its lines and colours, filtered down.

#include <cmath>

#include "toonray/core/portable_math.h"
#include "toonray/core/saturating.h"
#include "toonray/render/line_step.h"
#include "toonray/render/robust.h"

namespace toonray {
namespace {

float thickness_of(const RenderSettings& settings, int sub) {
    return line_thickness(settings.lines.width, settings.height, sub);
}

// The bytes of a black-on-white line image (255 = none) as coverage into the frame's layer.
void copy_coverage(const ImageGray8& from, int from_x0, int from_y0, const PixelRect& rect,
                   ImageF& to) {
    for (int y = rect.y0; y < rect.y1; ++y) {
        const std::uint8_t* in = from.row(y - from_y0) + (rect.x0 - from_x0);
        float* out = to.row(y) + rect.x0;
        for (int x = 0; x < rect.width(); ++x) out[x] = 1.0f - static_cast<float>(in[x]) / 255.0f;
    }
}

class RobustLines : public LineStep {
public:
    int halo(const RenderSettings& settings) const override {
        const int sub = samples_per_side(settings);
        return robust_halo(thickness_of(settings, sub), sub);
    }
    RefineRule refine_rule(const RenderSettings& settings) const override {
        // The robust lines look for creases and depth steps between samples: pixels next to
        // either take all samples. The thresholds are lower than the lines' (a quarter of the
        // crease angle, half the depth step) because first samples are a pixel apart: on the
        // piano's mouldings half the crease angle let through thin chamfers and left 0.5% of
        // pixels off full supersampling, a quarter 0.1%.
        RefineRule rule;
        rule.surface = true;
        rule.cos_normal = portable::cos(settings.lines.crease_angle * 0.25f * 3.14159265f / 180.0f);
        rule.depth_step = settings.lines.robust.depth_step * 0.5f;
        return rule;
    }
    // The fine grid: ids, view depths and geometric normals of every sample.
    unsigned first_fields(const RenderSettings&) const override {
        return kSurfaceKeys | kSurfaceViewDepth;
    }
    unsigned rest_fields(const RenderSettings&) const override {
        return kSurfaceKeys | kSurfaceViewDepth;
    }

    void begin(const FrameContext& frame, FrameLayers& out) override {
        if (!frame.settings.layers) return;
        const int w = frame.settings.width, h = frame.settings.height;
        out.cel.reshape(w, h);
        out.lines.reshape(w, h);
        for (const auto& [type, name] : kTypes) out.line_types.push_back({name, ImageF(w, h)});
    }

    void bucket(const FrameContext& frame, const Bucket& bucket, const BucketSampler& sampler,
                FrameLayers& out) override {
        const RenderSettings& settings = frame.settings;
        const int sub = frame.sub;
        Scratch& b = scratch_.local();
        sampler.fill_fine(b.view_depth, b.normal, b.colour, b.material, b.object);
        find_line_seeds(FineBuffers{b.view_depth, b.normal, b.object, b.material}, settings.lines,
                        b.seeds, 1);
        const bool layers = settings.layers;
        // Distance to the seeds and line coverage in one banded pass, over the bucket and its
        // halo; the bucket's own pixels are exact (robust_halo).
        resolve_lines_from_seeds(b.colour, b.seeds, thickness_of(settings, sub), sub,
                                 settings.lines.colour, b.resolved, layers ? &b.cel : nullptr,
                                 layers ? &b.edges : nullptr, 1);
        const int x0 = bucket.decided.x0, y0 = bucket.decided.y0;
        copy_rect(b.resolved, x0, y0, bucket.pixels, out.image);
        if (!layers) return;
        copy_rect(b.cel, x0, y0, bucket.pixels, out.cel);
        copy_coverage(b.edges, x0, y0, bucket.pixels, out.lines);
        for (std::size_t t = 0; t < std::size(kTypes); ++t) {
            resolve_seed_type(b.seeds, kTypes[t].first, sub, b.lines, 1);
            copy_coverage(b.lines, x0, y0, bucket.pixels, out.line_types[t].coverage);
        }
    }

    std::uint64_t bucket_bytes(const RenderSettings& settings,
                               std::uint64_t decided) const override {
        // The fine grid of decided pixels (depth, normal, colour, ids, seed), the resolved
        // pixels (final, cel, edges, one line type) and, for very wide lines, the distances.
        const int sub = samples_per_side(settings);
        const std::uint64_t samples = static_cast<std::uint64_t>(sub) * sub;
        const std::uint64_t fine =
            sizeof(float) + 2 * sizeof(Vec3f) + 2 * sizeof(std::uint32_t) + 1 +
            (line_distance_band(thickness_of(settings, sub)) > kMaxDistanceBand ? sizeof(float)
                                                                                : 0);
        return add_saturated(mul_saturated(mul_saturated(decided, samples), fine),
                             mul_saturated(decided, 2 * sizeof(Rgb8) + 2));
    }
    std::uint64_t held_bytes() const override {
        std::uint64_t bytes = 0;
        scratch_.for_each([&](const Scratch& b) { bytes += b.bytes(); });
        return bytes;
    }

private:
    static constexpr std::pair<unsigned, std::string_view> kTypes[] = {
        {kLineSilhouette, "silhouette"},
        {kLineCrease, "crease"},
        {kLineDepth, "depth"},
        {kLineObject, "object"},
        {kLineMaterial, "material"}};

    /// One thread's buffers: the fine grid of a bucket and its halo, its seeds and its
    /// resolved pixels.
    struct Scratch {
        ImageF view_depth;
        Image<Vec3f> normal, colour;
        Image<std::uint32_t> material, object;
        Image<std::uint8_t> seeds;
        ImageRgb8 resolved, cel;
        ImageGray8 edges, lines;

        [[nodiscard]] std::uint64_t bytes() const {
            auto of = [](const auto& image) {
                return static_cast<std::uint64_t>(image.capacity()) * sizeof(*image.data());
            };
            return of(view_depth) + of(normal) + of(colour) + of(material) + of(object) +
                   of(seeds) + of(resolved) + of(cel) + of(edges) + of(lines);
        }
    };
    PerThread<Scratch> scratch_;
};

}  // namespace

std::unique_ptr<LineStep> make_robust_lines() { return std::make_unique<RobustLines>(); }

}  // namespace toonray
