#pragma once
/// The feature images: the renderer's layers (render/frame_layers.h) encoded as 8-bit PNG
/// images a user tunes thresholds with, one table of them for every line mode
/// (`NAME_<feature>.png`, docs/rendering.md).

#include <span>
#include <string_view>

#include "toonray/core/image.h"
#include "toonray/render/frame_layers.h"

namespace toonray {

/// A feature image encoded: gray (channels 1) or RGB (channels 3).
struct FeatureBytes {
    int channels = 1;
    ImageGray8 gray;
    ImageRgb8 rgb;
};

/// One feature image: its name, the line modes that write it, and how it is encoded from the
/// layers.
struct FeatureImage {
    std::string_view name;
    bool classic, robust, ink;  ///< the modes that write it
    void (*encode)(const FrameLayers& layers, int threads, FeatureBytes& out);

    [[nodiscard]] bool in(LineMode mode) const {
        return mode == LineMode::Classic ? classic : (mode == LineMode::Robust ? robust : ink);
    }
};

/// Every feature image, in the order they are listed and written. Every mode: depth (lighter =
/// farther), normal, edges (every line), cel (colour without lines). Classic: edges_depth and
/// edges_normal (the Sobel lines of each map). Robust and ink: one image per line type
/// (robust: lines_silhouette, lines_crease, lines_depth, lines_object, lines_material; ink:
/// lines_silhouette, lines_crease, lines_material, lines_border, lines_intersection,
/// lines_polyline), object_id and material_id in false colour, and samples (black where a
/// pixel took all its samples).
[[nodiscard]] std::span<const FeatureImage> feature_images();

/// The false colour of an object or material id in the id feature images: distinct and stable;
/// black for kNoIndex (nothing seen).
[[nodiscard]] Rgb8 id_colour(std::uint32_t id);

/// Bytes per pixel of the encoded feature images of a mode, one at a time (for frame_bytes).
[[nodiscard]] std::uint64_t feature_image_bytes_per_pixel();

}  // namespace toonray
