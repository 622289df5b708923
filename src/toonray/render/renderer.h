#pragma once
/// Renders a scene to a cel-shaded, outlined image and its feature images (AOVs).

#include <optional>

#include "toonray/accel/triangle_accel.h"
#include "toonray/core/image.h"
#include "toonray/scene/camera.h"
#include "toonray/scene/scene.h"

namespace toonray {

enum class EdgeMode { Classic };

struct RenderSettings {
    int width = 1280;
    int height = 720;
    std::optional<Vec3f> light;  ///< point light; default: the eye moved by half the scene
                                 ///< radius along the camera's up and right
    Vec3f background{1.0f};      ///< colour of pixels that hit nothing
    EdgeMode edges = EdgeMode::Classic;
    float depth_threshold = 8.0f;   ///< classic: Sobel magnitude on the 8-bit depth map
    float normal_threshold = 4.0f;  ///< classic: Sobel magnitude on the 8-bit normal map
    int threads = 0;                ///< 0 = all hardware threads
};

/// Per-pixel results of the primary rays.
struct GBuffer {
    ImageF distance;        ///< Euclidean distance from the eye; +inf where the ray misses
    Image<Vec3f> normal;    ///< shading normal facing the viewer; zero where the ray misses
    Image<Vec3f> colour;    ///< cel-shaded colour (background where the ray misses)
    Image<std::uint32_t> material;  ///< kNoIndex where the ray misses
    Image<std::uint32_t> object;    ///< kNoIndex where the ray misses
};

/// Feature images a user tunes thresholds with; all 8-bit.
struct Aovs {
    ImageGray8 depth;         ///< lighter = farther
    ImageRgb8 normal;
    ImageGray8 edges_depth;   ///< black lines on white
    ImageGray8 edges_normal;
    ImageGray8 edges;         ///< merged, before blur
    ImageRgb8 cel;            ///< colour without lines
};

/// Renders frames, keeping its buffers between calls so an animation allocates once.
class Renderer {
public:
    /// Renders the final image. Never throws for a valid scene, camera and settings; the
    /// camera must already have been validated (make_view_plane throws on a bad one).
    const ImageRgb8& render(const Scene& scene, const TriangleAccel& accel, const CameraSpec& camera,
                            const RenderSettings& settings);

    /// Valid after render(): the G-buffer and AOVs of the last frame.
    [[nodiscard]] const GBuffer& gbuffer() const { return gbuffer_; }
    [[nodiscard]] const Aovs& aovs() const { return aovs_; }
    /// Light position used for the last frame.
    [[nodiscard]] Vec3f light() const { return light_; }

private:
    void trace(const Scene& scene, const TriangleAccel& accel, const ViewPlane& view,
               const RenderSettings& settings);

    GBuffer gbuffer_;
    Aovs aovs_;
    ImageRgb8 final_;
    Vec3f light_;
};

/// The default light: the eye moved by half the scene radius along the view's up and right.
Vec3f default_light(const Scene& scene, const ViewPlane& view);

}  // namespace toonray
