#pragma once
/// Renders a scene to a cel-shaded, outlined image and its feature images (AOVs).

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <variant>

#include "toonray/accel/triangle_accel.h"
#include "toonray/core/image.h"
#include "toonray/core/parallel.h"
#include "toonray/ink/ink.h"
#include "toonray/render/robust.h"
#include "toonray/render/shading.h"
#include "toonray/render/trace.h"
#include "toonray/scene/camera.h"
#include "toonray/scene/scene.h"

namespace toonray {

enum class EdgeMode {
    Robust,   ///< the default: supersampled, plane-aware, resolution-independent lines
    Classic,  ///< the seed's pipeline, exactly: Sobel on 8-bit depth and normal maps
    /// Lines found on the geometry (ink/ink.h): feature edges with ray-traced visibility,
    /// chained into strokes and drawn with exact coverage over the cel colours; also as SVG.
    Ink,
};

struct RenderSettings {
    int width = 1280;
    int height = 720;
    std::optional<Vec3f> light;  ///< the point light when shading.lights is empty; default: the
        ///< eye moved by half the scene radius along the camera's up and right
    ShadingSettings shading;  ///< ramp, extra lights, shadows, specular, rim, textures
    Vec3f background{1.0f};   ///< colour of pixels that hit nothing
    EdgeMode edges = EdgeMode::Robust;
    float depth_threshold = 8.0f;   ///< classic: Sobel magnitude on the 8-bit depth map
    float normal_threshold = 4.0f;  ///< classic: Sobel magnitude on the 8-bit normal map
    RobustLineSettings lines;       ///< robust and ink: line types, crease angle, width, colour
    int samples = 4;  ///< robust and ink: samples per pixel on a regular grid (1, 4, 9 or 16)
    /// Robust and ink: adaptive sampling (render/sampler.h): one sample per pixel, and the
    /// whole grid only where neighbours differ. false: every pixel takes every sample (full
    /// supersampling, the reference the adaptive frames are measured against).
    bool adaptive = true;
    /// Robust and ink: pixels per side of the buckets the frame is rendered in. Memory follows
    /// the bucket, not the image; the frame is the same for any size. 126: with the one pixel
    /// of halo each side that an ink bucket traces, 128 = 8 of the accelerator's 16-ray tiles
    /// (piano frame: 3% fewer instructions in the bucket pass than 64).
    int tile_size = 126;
    int threads = 0;  ///< 0 = all hardware threads
    /// Also compute the feature images (Renderer::aovs). The final image is the same either way.
    bool feature_images = false;
    /// Ink: also chain the hidden lines into strokes (Renderer::ink_lines, for SVG), with the
    /// number of surfaces hiding them. They are not drawn: the final image is the same.
    bool hidden_lines = false;
    /// Ink: line sets and styles (ink/line_style.h); hidden lines are drawn where a rule says.
    ink::LineStyleSet line_styles;
    float line_taper = 0.0f;  ///< ink: default taper at open stroke ends, pixels at 720 lines
    bool line_width_by_depth = false;  ///< ink: default width by depth (ink::InkSettings)
};

/// Sub-samples per pixel side for a sample count: 1, 4, 9, 16 -> 1, 2, 3, 4. Throws Error
/// ("N samples per pixel: ...") otherwise.
int samples_per_side(int samples);

/// Per-sample results of the primary rays. Classic mode fills distance and normal, one sample
/// per pixel, for the whole frame; the robust lines fill view_depth and geometric_normal, on a
/// grid `sub` times finer than the image, one bucket (and its halo) at a time.
struct GBuffer {
    int sub = 1;                    ///< samples per pixel side
    ImageF distance;                ///< Euclidean distance from the eye; +inf where the ray misses
    Image<Vec3f> normal;            ///< shading normal facing the viewer; zero where the ray misses
    ImageF view_depth;              ///< distance along the view direction; +inf where it misses
    Image<Vec3f> geometric_normal;  ///< facing the viewer; zero where the ray misses
    Image<Vec3f> colour;            ///< cel-shaded colour (background where the ray misses)
    Image<std::uint32_t> material;  ///< kNoIndex where the ray misses
    Image<std::uint32_t> object;    ///< kNoIndex where the ray misses
};

/// Feature images a user tunes thresholds with; all 8-bit. Which are filled depends on the
/// line mode (see feature_images()).
struct Aovs {
    ImageGray8 depth;  ///< lighter = farther
    ImageRgb8 normal;
    ImageGray8 edges_depth;   ///< classic: Sobel lines of the depth map, black on white
    ImageGray8 edges_normal;  ///< classic: Sobel lines of the normal map
    ImageGray8 edges;         ///< all lines: classic merged before blur; robust and ink coverage
    ImageRgb8 cel;            ///< colour without lines
    ImageGray8 lines_silhouette, lines_crease, lines_depth, lines_object,
        lines_material;  ///< robust; ink: silhouette, crease and material
    ImageGray8 lines_border, lines_intersection, lines_polyline;  ///< ink
    ImageRgb8 object_id, material_id;  ///< robust and ink: ids in false colour
    /// Robust and ink: 0 where a pixel took every sample of its grid (adaptive sampling), 255
    /// where it took one.
    ImageGray8 samples;
};

/// One feature image of Aovs: its name, the line modes that fill it, and which member it is.
struct FeatureImage {
    std::string_view name;
    bool classic;  ///< filled in EdgeMode::Classic
    bool robust;   ///< filled in EdgeMode::Robust
    bool ink;      ///< filled in EdgeMode::Ink
    std::variant<ImageGray8 Aovs::*, ImageRgb8 Aovs::*> image;

    [[nodiscard]] bool in(EdgeMode mode) const {
        return mode == EdgeMode::Classic ? classic : (mode == EdgeMode::Robust ? robust : ink);
    }
};

/// Every feature image, in the order they are listed and written. Classic: depth, normal,
/// edges_depth, edges_normal, edges (merged, before blur), cel. Robust: depth, normal, edges
/// (line coverage), cel, lines_silhouette, lines_crease, lines_depth, lines_object,
/// lines_material, object_id, material_id. Ink: depth, normal, edges (line coverage), cel,
/// one coverage image per line type (lines_silhouette, lines_crease, lines_material,
/// lines_border, lines_intersection, lines_polyline), object_id, material_id. Robust and ink
/// also: samples.
std::span<const FeatureImage> feature_images();

/// Bytes of the buffers Renderer keeps for a frame with `settings`: classic mode's G-buffer and
/// maps; for robust and ink lines each thread's bucket buffers (at most every sample of a
/// bucket, its halo and, for very wide robust lines, its distance image) and the ink line
/// layer; the final image, and the feature images when settings.feature_images asks for them.
/// Per-thread scratch rows are not counted. Saturates at UINT64_MAX; throws Error for a sample
/// count that samples_per_side rejects.
[[nodiscard]] std::uint64_t frame_buffer_bytes(const RenderSettings& settings);

/// Bytes of one thread's bucket buffers for `settings` (robust and ink), at most: what they
/// reach when every sample of the largest bucket is traced. Throws Error for a sample count
/// that samples_per_side rejects.
[[nodiscard]] std::uint64_t bucket_buffer_bytes(const RenderSettings& settings);

/// Robust lines: pixels around a bucket whose samples its lines depend on. A line covers fine
/// samples nearer than thickness / 2 + 0.5 to its seeds, and a seed depends on the samples next
/// to it, so the bucket's fine grid is grown by that reach plus one sample, in whole pixels.
[[nodiscard]] int robust_halo(float thickness, int sub);

/// The ink lines' settings from a frame's: crease angle and width from `lines`, and its types
/// mapped to the ink's: silhouette -> silhouettes and borders, crease -> creases, material ->
/// material boundaries, object -> intersection lines (depth lines are a pixel notion; the
/// geometry's silhouettes are drawn instead).
[[nodiscard]] ink::InkSettings ink_settings(const RenderSettings& settings);

/// Sizes the G-buffer for a frame of width x height pixels with sub x sub samples each, for
/// `mode`'s buffers. The contents are left unspecified until shade_tile has covered every sample.
void prepare_gbuffer(GBuffer& g, int width, int height, int sub, EdgeMode mode);

/// The per-sample work of Renderer::trace for one traced tile: shading normal, toon colour,
/// material and object ids, and the depth and normal settings.edges needs, written into `g`
/// (sized by prepare_gbuffer). Public so the stage benchmark times the renderer's own code.
void shade_tile(const ShadingContext& ctx, const ViewPlane& view, const RenderSettings& settings,
                const SampleTile& tile, GBuffer& g);

/// Renders frames, keeping its buffers between calls so an animation allocates once.
class Renderer {
public:
    Renderer();
    ~Renderer();
    Renderer(Renderer&&) noexcept;
    Renderer& operator=(Renderer&&) noexcept;

    /// Renders the final image. `textures` are the decoded textures of the scene's materials
    /// (null: none). Never throws for a valid scene, camera and settings; the camera must
    /// already have been validated (make_view_plane throws on a bad one).
    const ImageRgb8& render(const Scene& scene, const TriangleAccel& accel,
                            const CameraSpec& camera, const RenderSettings& settings,
                            const TextureSet* textures = nullptr);

    /// Classic mode, after render(): the G-buffer of the last frame (empty in the other modes,
    /// which keep no frame-sized G-buffer).
    [[nodiscard]] const GBuffer& gbuffer() const { return gbuffer_; }
    /// Robust and ink: the pixels of the last frame that took all their samples.
    [[nodiscard]] std::uint64_t refined_pixels() const { return refined_pixels_; }
    /// Bytes held now by the per-thread bucket buffers (for memory accounting).
    [[nodiscard]] std::uint64_t bucket_bytes() const;
    /// The feature images of the last frame; all empty unless its settings.feature_images.
    [[nodiscard]] const Aovs& aovs() const;
    /// The single point light of the last frame (settings.light or the default).
    [[nodiscard]] Vec3f light() const { return light_; }
    /// Ink mode: the last frame's feature edges, pieces, strokes (for SVG) and line coverage.
    [[nodiscard]] const ink::InkLines& ink_lines() const { return ink_; }

private:
    struct Bucket;
    struct BucketBuffers;

    void trace(const Scene& scene, const TriangleAccel& accel, const ViewPlane& view,
               const RenderSettings& settings, const TextureSet* textures);
    void render_classic(const RenderSettings& settings);
    void render_buckets(const Scene& scene, const TriangleAccel& accel, const ViewPlane& view,
                        const RenderSettings& settings, const TextureSet* textures,
                        const std::uint8_t* hidden);
    void resolve_robust_bucket(const Bucket& bucket, BucketBuffers& b,
                               const RenderSettings& settings);
    void resolve_ink_bucket(const Bucket& bucket, const BucketBuffers& b);
    void first_sample_features(const Bucket& bucket, const BucketBuffers& b);
    void render_ink(const RenderSettings& settings);
    void ink_type_feature_images(const RenderSettings& settings, int threads);

    GBuffer gbuffer_;
    Aovs aovs_;  ///< classic mode draws its lines from depth, normal and edges* here
    bool feature_images_ = false;
    ImageRgb8 final_;
    ImageF first_depth_;          ///< feature images: each pixel's first sample's view depth
    Image<std::uint8_t> hidden_;  ///< ink: where the lines hide the picture (ink::opaque_lines)
    std::unique_ptr<PerThread<BucketBuffers>> buckets_;
    std::uint64_t refined_pixels_ = 0;
    ink::InkLines ink_;
    Vec3f light_;
    std::vector<Light> lights_;
};

/// The default light: the eye moved by half the scene radius along the view's up and right.
Vec3f default_light(const Scene& scene, const ViewPlane& view);

}  // namespace toonray
