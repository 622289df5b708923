#pragma once
/// The part of a frame that differs between line modes. The renderer's one bucket driver
/// (render/renderer.h) samples every bucket the same way; a mode's line step says what the
/// sampler must keep and how refinement compares samples, turns each sampled bucket into its
/// pixels of the picture, and finishes the frame.

#include <cstdint>
#include <memory>

#include "toonray/accel/triangle_accel.h"
#include "toonray/core/parallel.h"
#include "toonray/render/frame_layers.h"
#include "toonray/render/render_settings.h"
#include "toonray/render/sampler.h"
#include "toonray/scene/camera.h"
#include "toonray/scene/scene.h"

namespace toonray {

/// What a line step sees of the frame being rendered.
struct FrameContext {
    const Scene& scene;
    const TriangleAccel& accel;
    const CameraSpec& camera;
    const ViewPlane& view;
    const RenderSettings& settings;
    int sub;  ///< samples per pixel side
};

/// A bucket: its own pixels, and those its lines are decided for (its pixels and a halo).
struct Bucket {
    PixelRect pixels;
    PixelRect decided;
};

class LineStep {
public:
    virtual ~LineStep() = default;
    /// Samples per pixel side the mode takes for `settings`.
    [[nodiscard]] virtual int samples_per_side(const RenderSettings& settings) const;
    /// Pixels around a bucket whose samples its lines depend on.
    [[nodiscard]] virtual int halo(const RenderSettings&) const { return 0; }
    /// What makes a pixel take all its samples beyond its refine key.
    [[nodiscard]] virtual RefineRule refine_rule(const RenderSettings&) const { return {}; }
    /// The fields (SurfaceFields bits) the step reads of each pixel's first sample, and of its
    /// other samples. (The sampler keeps the keys of first samples it refines by.)
    [[nodiscard]] virtual unsigned first_fields(const RenderSettings&) const { return 0; }
    [[nodiscard]] virtual unsigned rest_fields(const RenderSettings&) const { return 0; }

    /// Before the buckets.
    virtual void begin(const FrameContext&, FrameLayers&) {}
    /// Per pixel of the image, or null: 1 where lines drawn over the picture cover it
    /// completely (after begin).
    [[nodiscard]] virtual const std::uint8_t* covered() const { return nullptr; }
    /// One sampled bucket to its pixels of the picture (and of the cel and line layers when
    /// settings.layers asks). Called on any thread, once per bucket.
    virtual void bucket(const FrameContext& frame, const Bucket& bucket,
                        const BucketSampler& sampler, FrameLayers& out) = 0;
    /// After every bucket.
    virtual void finish(const FrameContext&, FrameLayers&) {}

    /// Bytes per pixel of the frame-sized buffers the step keeps for `settings`.
    [[nodiscard]] virtual std::uint64_t frame_bytes_per_pixel(const RenderSettings&) const {
        return 0;
    }
    /// Bytes of one thread's bucket buffers at most, for buckets of `decided` pixels.
    [[nodiscard]] virtual std::uint64_t bucket_bytes(const RenderSettings&,
                                                     std::uint64_t /*decided*/) const {
        return 0;
    }
    /// Bytes its per-thread buffers hold now.
    [[nodiscard]] virtual std::uint64_t held_bytes() const { return 0; }
    /// Bytes its frame-sized buffers hold now.
    [[nodiscard]] virtual std::uint64_t held_frame_bytes() const { return 0; }
};

/// The step of each mode: render/lines_classic.cpp, lines_robust.cpp, lines_ink.cpp.
[[nodiscard]] std::unique_ptr<LineStep> make_classic_lines();
[[nodiscard]] std::unique_ptr<LineStep> make_robust_lines();
[[nodiscard]] std::unique_ptr<LineStep> make_ink_lines();

/// Bytes an image holds.
template <typename T>
[[nodiscard]] std::uint64_t bytes_of(const Image<T>& image) {
    return static_cast<std::uint64_t>(image.capacity()) * sizeof(T);
}

/// Copies the pixels of `to_rect` from `from`, whose pixel (0, 0) is pixel (from_x0, from_y0) of
/// the frame, into the frame image `to`.
template <typename T>
void copy_rect(const Image<T>& from, int from_x0, int from_y0, const PixelRect& to_rect,
               Image<T>& to) {
    for (int y = to_rect.y0; y < to_rect.y1; ++y)
        std::copy_n(from.row(y - from_y0) + (to_rect.x0 - from_x0), to_rect.width(),
                    to.row(y) + to_rect.x0);
}

}  // namespace toonray
