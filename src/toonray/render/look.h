#pragma once
/// The look stage: colours from the surface record (render/surface.h). Shading finds what
/// lights each sample (band, accents, albedo, light terms); a look decides what that looks
/// like. The cel look, today's only one, gives each band its ramp level. A look also gives
/// each sample an edge signal, so that adaptive refinement (render/sampler.h) refines where the
/// look's colours change inside one surface and band (textures, vertex colours, patterns), and
/// nowhere else: a look's detail does not make every pixel take all its samples.

#include <cstddef>
#include <cstdint>

#include "toonray/render/classic.h"
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
    /// Whether a band's colour is its own: the cel look's levels. A tone look shows every band
    /// at its full colour (its ink, drawn over the picture, gives the darkness), so refinement
    /// does not compare bands.
    bool bands_shade = true;
};

/// The fields (SurfaceFields bits) a look reads after shading, beyond what lines and layers ask
/// for.
[[nodiscard]] unsigned look_fields(const ShadingSettings& shading);

/// What a look gives a sample.
struct LookResult {
    Vec3f colour;
    std::uint32_t edge = 0;  ///< the edge signal (SurfaceSamples::edge)
};

/// The look of a hit on `material` with these light terms (the values its surface fields
/// hold). Shading calls it for each sample it fills (render/shade_samples.h), with the terms
/// still at hand.
inline LookResult look_hit(const LookFrame& frame, std::uint32_t material, const Vec3f& albedo,
                           std::uint8_t band, std::uint8_t accents) {
    // Ks only counts in the highlight band: looked up only there.
    const Vec3f ks = accents & kAccentHighlight ? frame.scene.materials[material].ks : Vec3f(0.0f);
    LookResult out;
    out.colour = cel_colour(frame.shading, albedo, band, accents, ks);
    // The albedo as bytes where a texture or vertex colours vary it within a band.
    if (frame.varying_albedo)
        out.edge = static_cast<std::uint32_t>(to_byte(albedo.x)) |
                   static_cast<std::uint32_t>(to_byte(albedo.y)) << 8 |
                   static_cast<std::uint32_t>(to_byte(albedo.z)) << 16;
    return out;
}

/// The look of a sample that sees nothing: the background.
inline LookResult look_miss(const LookFrame& frame) { return {frame.background, 0}; }

/// Colours and edge signals of samples [begin, end) of `samples`, which keep kSurfaceKeys and
/// kSurfaceWhere (the albedo): a look applied again after shading.
void apply_look(const LookFrame& frame, SurfaceSamples& samples, std::size_t begin,
                std::size_t end);

/// What adaptive refinement compares between two samples: whether they hit, their object and
/// material, band and accents, and the look's edge signal. Equal keys: the look gives the same
/// colour (up to the edge signal's resolution).
/// Packed in two words, so that comparing keys is two loads and no branch.
struct RefineKey {
    std::uint64_t ids;    ///< object (high half) and material
    std::uint64_t shade;  ///< hit, band and accents (high half) and the edge signal
};
/// `band_mask` is 0xff, or 0 when bands do not change the colour (LookFrame::bands_shade).
[[nodiscard]] inline RefineKey refine_key(const SurfaceSamples& s, std::size_t i,
                                          std::uint64_t band_mask = 0xff) {
    const std::uint64_t shade = static_cast<std::uint64_t>(s.found[i]) << 16 |
                                (static_cast<std::uint64_t>(s.band[i]) & band_mask) << 8 |
                                s.accents[i];
    return {static_cast<std::uint64_t>(s.object[i]) << 32 | s.material[i], shade << 32 | s.edge[i]};
}

}  // namespace toonray
