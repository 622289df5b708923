#pragma once
/// The layers of a frame as one multi-layer OpenEXR file (docs/exr.md), from the renderer's
/// layers (render/frame_layers.h): the cel colour, distance and view depth, normal, object and
/// material ids, band, light term, position and texture coordinates of each pixel's first
/// sample, and every line type's coverage.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "toonray/io/record.h"
#include "toonray/render/frame_layers.h"

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

/// Gathers the EXR channels of a frame's layers (rendered with RenderSettings::layers).
/// Channels: R, G, B (cel colour, linear), A (1 where a surface is seen), Z (distance along the
/// ray), view_depth.Z (along the view axis), N.X, N.Y, N.Z (world-space shading normal facing
/// the eye), object_id.id, material_id.id, band.index (the ramp band; -1 where nothing is
/// seen), light.L (the summed light term), P.X, P.Y, P.Z (world position), uv.U, uv.V, lines.all
/// and one lines.<type> per line type of the mode. Throws Error when a layer the channels come
/// from is missing or not the size of the picture.
void gather_feature_layers(const FrameLayers& layers, FeatureLayers& out);

/// Writes the layers as one EXR file, atomically, with the record in string attributes of its
/// header ("software", "toonraySettings") when it has one. Throws Error when the build has no
/// OpenEXR.
void write_feature_exr(const std::filesystem::path& path, const FeatureLayers& layers,
                       const OutputRecord& record = {});

/// Bytes of the layers and their encoding for a frame of `pixels` pixels (for frame_bytes).
[[nodiscard]] std::uint64_t feature_exr_bytes(std::uint64_t pixels);

}  // namespace toonray
