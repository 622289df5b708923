#pragma once
/// What the renderer hands to the frame: the picture and, when asked, every layer of it, per
/// pixel, and the strokes. The frame layer (frame/) only encodes them (PNG, EXR, SVG).

#include <cstdint>
#include <string_view>
#include <vector>

#include "toonray/core/image.h"
#include "toonray/ink/ink.h"
#include "toonray/render/line_settings.h"

namespace toonray {

/// One line type's coverage: 0 = no line, 1 = covered.
struct LineLayer {
    std::string_view name;  ///< the type: "silhouette", ... ("depth" and "normal" in classic)
    ImageF coverage;
};

/// A frame's picture and layers. The per-pixel layers are those of each pixel's first sample
/// (its centre when one sample is taken, else the first of its grid: render/sampler.h), filled
/// when RenderSettings::layers asks for them, else empty.
struct FrameLayers {
    LineMode mode = LineMode::Ink;
    ImageRgb8 image;  ///< the final picture
    ImageRgb8 cel;    ///< the colours without lines

    ImageF distance;                ///< along the ray; +inf where nothing is seen
    ImageF view_depth;              ///< along the view direction; +inf likewise
    Image<Vec3f> normal;            ///< shading normal facing the eye; 0 likewise
    Image<Vec3f> geometric_normal;  ///< facing the eye; 0 likewise
    Image<std::uint32_t> object;    ///< kNoIndex where nothing is seen
    Image<std::uint32_t> material;  ///< kNoIndex likewise
    Image<std::uint8_t> band;       ///< the ramp band; kNoBand likewise
    ImageF light;                   ///< the summed light term the band comes from
    Image<Vec3f> position;          ///< world space; 0 where nothing is seen
    Image<Vec2f> uv;                ///< texture coordinates; 0 likewise or without them
    Image<std::uint8_t> refined;    ///< 1 where the pixel took all its samples
    ImageF lines;                   ///< every line drawn over the picture
    /// The tone look's strokes or dots, drawn under the lines (ink mode; 0 for the cel look).
    ImageF tone;
    std::vector<LineLayer> line_types;  ///< each line type's own, in the mode's order

    /// The strokes (ink lines, and polylines in every mode): in the ink mode, when the scene
    /// has polylines, and when RenderSettings::strokes asks for them; else null.
    const ink::InkLines* strokes = nullptr;

    [[nodiscard]] const LineLayer* line_type(std::string_view name) const {
        for (const LineLayer& layer : line_types)
            if (layer.name == name) return &layer;
        return nullptr;
    }
};

}  // namespace toonray
