#pragma once
/// Renders a scene to its cel-shaded, outlined picture and its layers (render/frame_layers.h),
/// bucket by bucket, in every line mode through one driver: each bucket is sampled
/// (render/sampler.h), its samples get their surface record and look, and the mode's line step
/// (render/line_step.h) turns them into pixels.

#include <atomic>
#include <cstdint>
#include <memory>
#include <span>

#include "toonray/accel/triangle_accel.h"
#include "toonray/core/error.h"
#include "toonray/core/image.h"
#include "toonray/core/parallel.h"
#include "toonray/ink/ink.h"
#include "toonray/render/frame_layers.h"
#include "toonray/render/line_settings.h"
#include "toonray/render/render_settings.h"
#include "toonray/render/shading.h"
#include "toonray/scene/camera.h"
#include "toonray/scene/light.h"
#include "toonray/scene/scene.h"

namespace toonray {

class LineStep;

/// Bytes of the buffers Renderer keeps for a frame with `settings`: the picture; the layers
/// when settings.layers asks for them; the mode's frame-sized buffers (classic's G-buffer and
/// maps; the ink line layer); each thread's bucket buffers (the sampler's at most, and the
/// mode's); and for `lights` lights. The strokes grow with the scene, not the image: they are
/// not counted. Saturates at UINT64_MAX; throws Error for a sample count that
/// samples_per_side rejects.
[[nodiscard]] std::uint64_t frame_buffer_bytes(const RenderSettings& settings, int lights = 1);

/// Bytes per pixel of FrameLayers' per-pixel layers in `mode` (what settings.layers adds).
[[nodiscard]] std::uint64_t layer_bytes_per_pixel(LineMode mode);

/// The ink lines' settings for a frame (render/lines_ink.cpp): crease angle, width, colour and
/// pen from `settings.lines`, its types mapped to the ink's (silhouette -> silhouettes and
/// borders, crease -> creases, material -> material boundaries, object -> intersection
/// lines). Outside the ink mode the geometry's lines are found only for settings.strokes and
/// only polylines are drawn.
[[nodiscard]] ink::InkSettings ink_settings(const RenderSettings& settings);

/// Lets another thread follow a frame while it renders, and stop it (the Python module and the
/// Blender engine poll it). Progress counts the frame's buckets, most of its work.
struct RenderProgress {
    std::atomic<std::uint32_t> buckets{0};       ///< of the frame, set when they start
    std::atomic<std::uint32_t> buckets_done{0};  ///< finished so far
    /// Set to stop the frame: buckets not yet started are skipped and render throws
    /// RenderCancelled. Render leaves it set.
    std::atomic<bool> cancel{false};
};

/// What Renderer::render throws when its RenderProgress::cancel was set.
class RenderCancelled : public Error {
public:
    RenderCancelled() : Error("rendering cancelled") {}
};

/// Renders frames, keeping its buffers between calls so an animation allocates once.
class Renderer {
public:
    Renderer();
    ~Renderer();
    Renderer(Renderer&&) noexcept;
    Renderer& operator=(Renderer&&) noexcept;

    /// Renders the picture of `scene` seen by `camera` and lit by `lights` (a scene source's:
    /// scene/scene_source.h), and its layers as settings asks. `textures` are the decoded
    /// textures of the scene's materials (null: none). Never throws for a valid scene, camera
    /// and settings; the camera must already have been validated (make_view_plane throws on a
    /// bad one). With `progress`, counts its buckets there and throws RenderCancelled, leaving
    /// the layers incomplete, when its cancel flag is set before the frame is done.
    const ImageRgb8& render(const Scene& scene, const TriangleAccel& accel,
                            const CameraSpec& camera, std::span<const Light> lights,
                            const RenderSettings& settings, const TextureSet* textures = nullptr,
                            RenderProgress* progress = nullptr);

    /// The last frame's picture, layers and strokes.
    [[nodiscard]] const FrameLayers& layers() const { return layers_; }
    /// The last frame's strokes, when it kept them (FrameLayers::strokes).
    [[nodiscard]] const ink::InkLines& ink_lines() const { return ink_; }
    /// Pixels of the last frame that took all their samples.
    [[nodiscard]] std::uint64_t refined_pixels() const { return refined_pixels_; }
    /// Bytes held now by the per-thread bucket buffers (for memory accounting).
    [[nodiscard]] std::uint64_t bucket_bytes() const;
    /// Bytes held now by every buffer frame_buffer_bytes counts: the picture and layers, the
    /// modes' frame-sized buffers, the line layer of the strokes and the bucket buffers.
    [[nodiscard]] std::uint64_t held_bytes() const;

private:
    struct Buffers;
    void render_buckets(const struct FrameContext& frame, const ShadingContext& shading,
                        LineStep& step, RenderProgress* progress);
    void strokes_over_picture(const RenderSettings& settings);

    FrameLayers layers_;
    ink::InkLines ink_;
    std::unique_ptr<PerThread<Buffers>> buffers_;
    std::unique_ptr<LineStep> classic_, robust_, ink_lines_;
    std::uint64_t refined_pixels_ = 0;
};

}  // namespace toonray
