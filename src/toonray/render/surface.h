#pragma once
/// The surface record: per primary sample, what its ray sees, kept in separate arrays. Shading
/// fills it (render/shade_samples.h); a look turns it into colours (render/look.h); adaptive
/// refinement compares its discrete fields; the line modes and the frame's layers read it.

#include <cstdint>
#include <vector>

#include "toonray/core/math.h"

namespace toonray {

/// Which fields of a SurfaceSamples are kept. Each level keeps the fields of the levels before
/// it.
enum class SurfaceFields {
    /// What a look and refinement need: hit, ids, band, accents, albedo, the sample's image
    /// position, and the look's colour and edge signal.
    Look,
    /// Also the geometry the lines and the layers read: distance, view depth, shading and
    /// geometric normals.
    Geometry,
    /// Also where on the surface: world position, texture coordinates, triangle and
    /// barycentric coordinates, and the light terms (summed, and n.l and shadow per light).
    All,
};

/// Accent bits of a sample (SurfaceSamples::accents).
enum SurfaceAccent : std::uint8_t {
    kAccentHighlight = 1u << 0,  ///< inside the hard specular highlight band
    kAccentRim = 1u << 1,        ///< inside the rim band
};

/// The band of a sample that sees nothing.
inline constexpr std::uint8_t kNoBand = 255;

/// Per sample, in separate arrays, sized by resize() for a level of SurfaceFields.
struct SurfaceSamples {
    // SurfaceFields::Look
    std::vector<std::uint8_t> found;              ///< 1 where the ray hits
    std::vector<std::uint32_t> object, material;  ///< kNoIndex where the ray misses
    std::vector<std::uint8_t> band;     ///< index into the ramp's levels; kNoBand on a miss
    std::vector<std::uint8_t> accents;  ///< SurfaceAccent bits
    /// Kd times vertex colour times texture: the colour the ramp's levels scale. Zero on a miss.
    std::vector<Vec3f> albedo;
    std::vector<Vec2f> image;   ///< where the sample lies on the image, in pixels
    std::vector<Vec3f> colour;  ///< the look's colour; the background on a miss
    /// The look's edge signal: samples of one surface in one band whose edge signals differ may
    /// differ in colour (a texture, vertex colours, a pattern), so refinement compares them.
    std::vector<std::uint32_t> edge;
    // SurfaceFields::Geometry
    std::vector<float> distance;          ///< along the ray; +inf on a miss
    std::vector<float> view_depth;        ///< along the view direction; +inf on a miss
    std::vector<Vec3f> normal;            ///< shading normal, unit, facing the viewer; 0 on a miss
    std::vector<Vec3f> geometric_normal;  ///< unit, facing the viewer; 0 on a miss
    // SurfaceFields::All
    std::vector<Vec3f> position;          ///< world space
    std::vector<Vec2f> uv;                ///< texture coordinates; 0 where the triangle has none
    std::vector<std::uint32_t> prim;      ///< the triangle hit; kNoIndex on a miss
    std::vector<Vec2f> barycentric;       ///< the hit's (u, v) on that triangle
    std::vector<float> diffuse;           ///< the summed light term the band is chosen by
    std::vector<float> n_dot_l;           ///< per sample, light_count values: n.l of each light
    std::vector<std::uint32_t> shadowed;  ///< bit i: light i is blocked (toon shadows)

    SurfaceFields fields = SurfaceFields::Look;
    int light_count = 0;

    /// Sizes the arrays of `fields` for n samples and leaves the others empty (keeping their
    /// memory). light_count: values of n_dot_l per sample.
    void resize(std::size_t n, SurfaceFields fields, int light_count);
    [[nodiscard]] std::size_t size() const { return found.size(); }
    [[nodiscard]] bool has(SurfaceFields level) const { return fields >= level; }
    /// Bytes held by the arrays.
    [[nodiscard]] std::uint64_t bytes() const;
    /// Bytes per sample at a level with `light_count` lights: what resize() keeps.
    [[nodiscard]] static std::uint64_t bytes_per_sample(SurfaceFields fields, int light_count);
};

}  // namespace toonray
