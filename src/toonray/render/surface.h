#pragma once
/// The surface record: per primary sample, what its ray sees, kept in separate arrays. Shading
/// fills it (render/shade_samples.h); a look turns it into colours (render/look.h); adaptive
/// refinement compares its discrete fields; the line modes and the frame's layers read it.

#include <cstdint>
#include <vector>

#include "toonray/core/math.h"

namespace toonray {

/// Groups of fields of a SurfaceSamples, as bits: which are kept is what the frame reads. Every
/// sample keeps whether it hits and its look's colour.
enum SurfaceFields : unsigned {
    /// What refinement compares: object, material, band, accents, the look's edge signal.
    kSurfaceKeys = 1u << 0,
    /// The classic lines': distance along the ray and shading normal.
    kSurfaceDistance = 1u << 1,
    /// The robust lines': view depth and geometric normal.
    kSurfaceViewDepth = 1u << 2,
    /// Where, and how lit: on the image, in the world, in texture coordinates, the triangle and
    /// the barycentric coordinates; the albedo and the light terms (summed, and n.l and shadow
    /// per light).
    kSurfaceWhere = 1u << 3,
    kSurfaceAll = 15u,
};

/// Accent bits of a sample (SurfaceSamples::accents).
enum SurfaceAccent : std::uint8_t {
    kAccentHighlight = 1u << 0,  ///< inside the hard specular highlight band
    kAccentRim = 1u << 1,        ///< inside the rim band
};

/// The band of a sample that sees nothing.
inline constexpr std::uint8_t kNoBand = 255;

/// Per sample, in separate arrays, sized by resize() for a set of SurfaceFields.
struct SurfaceSamples {
    // Always
    std::vector<std::uint8_t> found;  ///< 1 where the ray hits
    std::vector<Vec3f> colour;        ///< the look's colour; the background on a miss
    // kSurfaceKeys
    std::vector<std::uint32_t> object, material;  ///< kNoIndex where the ray misses
    std::vector<std::uint8_t> band;     ///< index into the ramp's levels; kNoBand on a miss
    std::vector<std::uint8_t> accents;  ///< SurfaceAccent bits
    /// The look's edge signal: samples of one surface in one band whose edge signals differ may
    /// differ in colour (a texture, vertex colours, a pattern), so refinement compares them.
    std::vector<std::uint32_t> edge;
    // kSurfaceDistance
    std::vector<float> distance;  ///< along the ray; +inf on a miss
    std::vector<Vec3f> normal;    ///< shading normal, unit, facing the viewer; 0 on a miss
    // kSurfaceViewDepth
    std::vector<float> view_depth;        ///< along the view direction; +inf on a miss
    std::vector<Vec3f> geometric_normal;  ///< unit, facing the viewer; 0 on a miss
    // kSurfaceWhere
    std::vector<Vec2f> image;  ///< where the sample lies on the image, in pixels
    /// Kd times vertex colour times texture: the colour the ramp's levels scale. Zero on a miss.
    std::vector<Vec3f> albedo;
    std::vector<Vec3f> position;          ///< world space
    std::vector<Vec2f> uv;                ///< texture coordinates; 0 where the triangle has none
    std::vector<std::uint32_t> prim;      ///< the triangle hit; kNoIndex on a miss
    std::vector<Vec2f> barycentric;       ///< the hit's (u, v) on that triangle
    std::vector<float> diffuse;           ///< the summed light term the band is chosen by
    std::vector<float> n_dot_l;           ///< per sample, light_count values: n.l of each light
    std::vector<std::uint32_t> shadowed;  ///< bit i: light i is blocked (toon shadows)

    unsigned fields = 0;  ///< SurfaceFields bits
    int light_count = 0;

    /// Sizes the arrays of `fields` for n samples and leaves the others empty (keeping their
    /// memory). light_count: values of n_dot_l per sample.
    void resize(std::size_t n, unsigned fields, int light_count);
    [[nodiscard]] std::size_t size() const { return found.size(); }
    [[nodiscard]] bool has(unsigned group) const { return (fields & group) == group; }
    /// Bytes held by the arrays.
    [[nodiscard]] std::uint64_t bytes() const;
    /// Bytes per sample with `fields` and `light_count` lights: what resize() keeps.
    [[nodiscard]] static std::uint64_t bytes_per_sample(unsigned fields, int light_count);
};

}  // namespace toonray
