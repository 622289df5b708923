// The classic line step: the seed's pipeline (render/classic.h). Each bucket's samples, one per
// pixel at its centre, go into frame-sized distance, normal and colour buffers; the Sobel lines
// need the whole frame (the depth map is scaled by the farthest hit), so they are drawn once
// every bucket is in.

#include "toonray/render/classic.h"
#include "toonray/render/line_step.h"

namespace toonray {
namespace {

class ClassicLines : public LineStep {
public:
    int samples_per_side(const RenderSettings&) const override { return 1; }
    unsigned first_fields(const RenderSettings&) const override { return kSurfaceDistance; }

    void begin(const FrameContext& frame, FrameLayers&) override {
        const int w = frame.settings.width, h = frame.settings.height;
        // No fill: every bucket writes all its pixels.
        distance_.reshape(w, h);
        normal_.reshape(w, h);
        colour_.reshape(w, h);
    }

    void bucket(const FrameContext&, const Bucket& bucket, const BucketSampler& sampler,
                FrameLayers&) override {
        const SurfaceSamples& first = sampler.first();
        for (int y = bucket.pixels.y0; y < bucket.pixels.y1; ++y)
            for (int x = bucket.pixels.x0; x < bucket.pixels.x1; ++x) {
                const std::size_t i = sampler.first_index(x, y);
                distance_(x, y) = first.distance[i];
                normal_(x, y) = first.normal[i];
                colour_(x, y) = first.colour[i];
            }
    }

    void finish(const FrameContext& frame, FrameLayers& out) override {
        const RenderSettings& settings = frame.settings;
        const int threads = settings.threads;
        classic_depth_map(distance_, depth_, threads);
        classic_normal_map(normal_, distance_, normal_map_, threads);
        sobel_edges(depth_, settings.lines.classic.depth_threshold, edges_depth_, threads);
        sobel_edges(normal_map_, settings.lines.classic.normal_threshold, edges_normal_, threads);
        merge_edges(edges_depth_, edges_normal_, edges_);
        compose_lines(colour_, edges_, out.image, threads, settings.layers ? &out.cel : nullptr);
        if (!settings.layers) return;
        coverage_of(edges_, out.lines);
        out.line_types.push_back({"depth", {}});
        coverage_of(edges_depth_, out.line_types.back().coverage);
        out.line_types.push_back({"normal", {}});
        coverage_of(edges_normal_, out.line_types.back().coverage);
    }

    std::uint64_t held_frame_bytes() const override {
        return bytes_of(distance_) + bytes_of(normal_) + bytes_of(colour_) + bytes_of(depth_) +
               bytes_of(normal_map_) + bytes_of(edges_depth_) + bytes_of(edges_normal_) +
               bytes_of(edges_);
    }

    std::uint64_t frame_bytes_per_pixel(const RenderSettings&) const override {
        // Distance, normal and colour, and the maps the lines are drawn from (depth, normal,
        // edges_depth, edges_normal, edges).
        return sizeof(float) + 2 * sizeof(Vec3f) + 1 + sizeof(Rgb8) + 3;
    }

private:
    // Coverage 0..1 from black-on-white lines (0 = line).
    static void coverage_of(const ImageGray8& lines, ImageF& out) {
        out.reshape(lines.width(), lines.height());
        for (std::size_t i = 0; i < lines.size(); ++i)
            out.data()[i] = 1.0f - static_cast<float>(lines.data()[i]) / 255.0f;
    }

    ImageF distance_;
    Image<Vec3f> normal_, colour_;
    ImageGray8 depth_;
    ImageRgb8 normal_map_;
    ImageGray8 edges_depth_, edges_normal_, edges_;
};

}  // namespace

std::unique_ptr<LineStep> make_classic_lines() { return std::make_unique<ClassicLines>(); }

}  // namespace toonray
