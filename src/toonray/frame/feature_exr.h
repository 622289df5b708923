#pragma once
/// The feature images of a frame as one multi-layer OpenEXR file (docs/exr.md): distance and
/// view depth, normals, object and material ids at each pixel's centre, traced once more for
/// the purpose (the renderer's own buffers are 8-bit images or sub-pixel samples); the cel
/// colour and each line type's coverage from the renderer's finished feature images.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "toonray/accel/triangle_accel.h"
#include "toonray/render/renderer.h"
#include "toonray/scene/camera.h"
#include "toonray/scene/scene.h"

namespace toonray {

/// Z and view_depth.Z where no surface is seen: Blender's value for the background (finite,
/// because compositing nodes such as defocus misbehave on infinity).
inline constexpr float kExrBackgroundDepth = 1e10f;
/// object_id.id and material_id.id where no surface is seen (0 is the default object/material).
inline constexpr float kExrBackgroundId = -1.0f;

/// The layers of one frame, whole images of width * height floats each, row-major from the top.
struct FeatureLayers {
    int width = 0, height = 0;
    /// Name and whether it is stored as half, then the values.
    struct Layer {
        std::string name;
        bool half = true;
        std::vector<float> values;
    };
    std::vector<Layer> channels;

    [[nodiscard]] const Layer* find(std::string_view name) const;
};

/// Gathers the layers of the frame `renderer` last rendered (with settings.feature_images) of
/// `scene` through `accel`, seen by `camera`. Channels: R, G, B (cel colour, linear), A
/// (1 where a surface is seen), Z (distance along the ray), view_depth.Z (along the view
/// axis), N.X, N.Y, N.Z (world-space shading normal facing the eye), object_id.id,
/// material_id.id, lines.all and one lines.<type> per line type the mode draws.
/// `polylines`: in the classic and robust modes, the coverage of the polylines drawn over the
/// frame (ink/polylines.h), as lines.polyline and in lines.all; nullptr when none were drawn.
void gather_feature_layers(const Scene& scene, const TriangleAccel& accel, const CameraSpec& camera,
                           const RenderSettings& settings, const Renderer& renderer,
                           FeatureLayers& out, const ImageF* polylines = nullptr);

/// Writes the layers as one EXR file, atomically. Throws Error when the build has no OpenEXR.
void write_feature_exr(const std::filesystem::path& path, const FeatureLayers& layers);

/// Bytes of the layers and their encoding for a frame of `pixels` pixels (for frame_bytes).
[[nodiscard]] std::uint64_t feature_exr_bytes(std::uint64_t pixels);

}  // namespace toonray
