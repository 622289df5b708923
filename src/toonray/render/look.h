#pragma once
/// The look stage: colours from the surface record (render/surface.h). Shading finds what
/// lights each sample (band, accents, albedo, light terms); a look decides what that looks
/// like. The cel look, today's only one, gives each band its ramp level. A look also gives
/// each sample an edge signal, so that adaptive refinement (render/sampler.h) refines where the
/// look's colours change inside one surface and band (textures, vertex colours, patterns), and
/// nowhere else: a look's detail does not make every pixel take all its samples.

#include <cstddef>
#include <cstdint>

#include "toonray/render/shading.h"
#include "toonray/render/surface.h"
#include "toonray/scene/scene.h"

namespace toonray {

/// What a look needs of a frame besides the samples.
struct LookFrame {
    const Scene& scene;
    const ShadingSettings& shading;
    Vec3f background;  ///< the colour of samples that see nothing
    /// Whether colours vary inside one surface and band: textured materials or vertex colours.
    /// Only then does the cel look give an edge signal other than 0.
    bool varying_albedo = false;
};

/// The fields a look needs (its own, beyond what lines and layers ask for).
[[nodiscard]] SurfaceFields look_fields(const ShadingSettings& shading);

/// Colours and edge signals of samples [begin, end) of `samples`.
void apply_look(const LookFrame& frame, SurfaceSamples& samples, std::size_t begin,
                std::size_t end);

/// What adaptive refinement compares between two samples: whether they hit, their object and
/// material, band and accents, and the look's edge signal. Equal keys: the look gives the same
/// colour (up to the edge signal's resolution).
struct RefineKey {
    std::uint32_t object, material;
    std::uint32_t shade;  ///< hit, band and accents
    std::uint32_t edge;
    bool operator==(const RefineKey&) const = default;
};
[[nodiscard]] inline RefineKey refine_key(const SurfaceSamples& s, std::size_t i) {
    return {s.object[i], s.material[i],
            static_cast<std::uint32_t>(s.found[i]) << 16 |
                static_cast<std::uint32_t>(s.band[i]) << 8 | s.accents[i],
            s.edge[i]};
}

}  // namespace toonray
