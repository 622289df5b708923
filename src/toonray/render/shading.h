#pragma once
/// Toon shading of a hit: the diffuse light picks a band of a ramp that scales the material's
/// colour; optional hard-edged specular and rim bands, toon shadows and textures.
///
/// With the defaults (the seed's ramp, one point light, nothing optional) this is exactly the
/// seed's cel shading: k = clamp(int(l.n * 16), 0, 15) into {0.5 x4, 0.75 x4, 1.0 x8}.

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "toonray/accel/triangle_accel.h"
#include "toonray/core/image.h"
#include "toonray/core/math.h"
#include "toonray/render/surface.h"
#include "toonray/scene/light.h"
#include "toonray/scene/scene.h"

namespace toonray {

/// Bands of a toon ramp: diffuse light below thresholds[0] gives levels[0], below
/// thresholds[1] levels[1], ..., and levels.back() above the last threshold.
struct ToonRamp {
    std::vector<float> levels{0.5f, 0.75f, 1.0f};
    std::vector<float> thresholds{0.25f, 0.5f};

    /// The band of a diffuse term: the index of its level.
    [[nodiscard]] std::uint8_t band(float diffuse) const {
        std::size_t i = 0;
        while (i < thresholds.size() && diffuse >= thresholds[i]) ++i;
        return static_cast<std::uint8_t>(i);
    }
    [[nodiscard]] float level(float diffuse) const { return levels[band(diffuse)]; }
    bool operator==(const ToonRamp&) const = default;
};

/// The most levels a ramp may have (a band index is a byte, and one value means no band).
inline constexpr std::size_t kMaxRampLevels = 64;

/// Parses "0.5,0.75,1.0@0.25,0.5": N levels (at most kMaxRampLevels), then N-1 increasing
/// thresholds. Throws Error ("ramp '...': ...").
ToonRamp parse_ramp(const std::string& text);
/// The text parse_ramp reads back as `ramp` exactly.
std::string format_ramp(const ToonRamp& ramp);

struct ShadingSettings {
    ToonRamp ramp;
    bool shadows = false;        ///< lights blocked by geometry do not count (toon shadows)
    bool specular = false;       ///< hard highlight band from MTL Ks and Ns where given
    float rim = 0.0f;            ///< rim band width in [0, 1) of (1 - n.v); 0 = off
    float rim_strength = 0.35f;  ///< how much the rim band brightens
    bool textures = true;        ///< multiply Kd by map_Kd where a material has one
};

/// The decoded textures of a scene's materials, by material index; a material without one
/// (or past the end) keeps its Kd. Shared, so that frames of an animation reuse one decode.
using TextureSet = std::vector<std::shared_ptr<const ImageRgb8>>;

/// The texture of material m in `textures`, or null.
inline const ImageRgb8* texture_of(const TextureSet& textures, std::uint32_t m) {
    return m < textures.size() ? textures[m].get() : nullptr;
}

/// Everything shading needs for one frame.
struct ShadingContext {
    const Scene& scene;
    const TriangleAccel& accel;  ///< for shadow rays
    const ShadingSettings& settings;
    std::span<const Light> lights;
    const TextureSet* textures = nullptr;
};

/// The corners of triangle `prim` of instance `instance` (kNoIndex: the scene's own) in world
/// space: an instance's transformed by Affine3::point, as flatten_instances places them.
inline std::array<Vec3f, 3> world_corners(const Scene& scene, std::uint32_t instance,
                                          std::uint32_t prim) {
    const TriangleMesh& mesh = scene.mesh_of(instance);
    const auto& tri = mesh.tri_positions[prim];
    std::array<Vec3f, 3> p{mesh.positions[tri[0]], mesh.positions[tri[1]], mesh.positions[tri[2]]};
    if (instance != kNoIndex)
        for (Vec3f& q : p) q = scene.instances[instance].to_world.point(q);
    return p;
}

/// Corner k's normal of triangle `prim` of instance `instance` in world space (an instance's by
/// Affine3::unit_normal, as flatten_instances transforms them); the triangle must have one.
inline Vec3f world_normal(const Scene& scene, std::uint32_t instance, std::uint32_t prim, int k) {
    const TriangleMesh& mesh = scene.mesh_of(instance);
    const Vec3f& n = mesh.normals[mesh.tri_normals[prim][static_cast<std::size_t>(k)]];
    return instance == kNoIndex ? n : scene.instances[instance].to_world.unit_normal(n);
}

/// The hit triangle's geometric normal, unit, facing the viewer. Inline (as is shading_normal):
/// both run once per sample, inside the renderer's per-tile loop.
inline Vec3f geometric_normal(const Scene& scene, const Hit& hit, const Vec3f& dir) {
    const std::array<Vec3f, 3> p = world_corners(scene, hit.instance, hit.prim);
    Vec3f n = cross(p[1] - p[0], p[2] - p[0]);
    float len = length(n);
    n = len > 0.0f ? n / len : -dir;
    return dot(n, dir) > 0.0f ? -n : n;
}

/// The shading normal at a hit: vertex normals interpolated when all three corners have one,
/// else the geometric normal; turned to face the viewer (against `dir`).
inline Vec3f shading_normal(const Scene& scene, const Hit& hit, const Vec3f& dir) {
    const TriangleMesh& mesh = scene.mesh_of(hit.instance);
    const auto& tn = mesh.tri_normals[hit.prim];
    Vec3f n;
    bool interpolated = false;
    if (tn[0] != kNoIndex && tn[1] != kNoIndex && tn[2] != kNoIndex) {
        float w0 = 1.0f - hit.u - hit.v;
        n = world_normal(scene, hit.instance, hit.prim, 0) * w0 +
            world_normal(scene, hit.instance, hit.prim, 1) * hit.u +
            world_normal(scene, hit.instance, hit.prim, 2) * hit.v;
        float len = length(n);
        if (len > 0.0f && std::isfinite(len)) {
            n = n / len;
            interpolated = true;
        }
    }
    if (!interpolated) {
        const std::array<Vec3f, 3> p = world_corners(scene, hit.instance, hit.prim);
        n = cross(p[1] - p[0], p[2] - p[0]);
        float len = length(n);
        n = len > 0.0f ? n / len : -normalize(dir);
    }
    return dot(n, dir) > 0.0f ? -n : n;
}

/// How the lights reach a point of a surface: what the cel look (and every other look) reads.
struct LightTerms {
    Vec3f albedo;                ///< Kd times the vertex colour and the texture there
    float diffuse = 0.0f;        ///< summed intensity times max(0, n.l) of the unblocked lights
    std::uint8_t band = 0;       ///< the ramp's band for min(diffuse, 1)
    std::uint8_t accents = 0;    ///< SurfaceAccent bits (render/surface.h)
    std::uint32_t shadowed = 0;  ///< bit i: light i (i < 32) is blocked (toon shadows)
};

/// The light terms of a hit seen along `dir` from `eye`, with shading normal `n`; when
/// `n_dot_l` is not null, each light's n.l into n_dot_l[0, lights.size()).
LightTerms light_terms(const ShadingContext& ctx, const Hit& hit, const Vec3f& eye,
                       const Vec3f& dir, const Vec3f& n, float* n_dot_l = nullptr);

/// The cel look of a point (render/look.h): albedo times its band's level, plus the material's
/// Ks in the highlight band and albedo times the rim strength in the rim band.
inline Vec3f cel_colour(const ShadingSettings& s, const Vec3f& albedo, std::uint8_t band,
                        std::uint8_t accents, const Vec3f& ks) {
    Vec3f colour = albedo * s.ramp.levels[band];
    if (accents & kAccentHighlight) colour += ks;
    if (accents & kAccentRim) colour += albedo * s.rim_strength;
    return colour;
}

/// Toon colour of a hit seen along `dir` from `eye`, with shading normal `n`: the cel look of
/// its light terms.
Vec3f shade_hit(const ShadingContext& ctx, const Hit& hit, const Vec3f& eye, const Vec3f& dir,
                const Vec3f& n);

/// The texture that multiplies material m's Kd in this frame, or null.
inline const ImageRgb8* material_texture(const ShadingContext& ctx, std::uint32_t m) {
    return ctx.settings.textures && ctx.textures ? texture_of(*ctx.textures, m) : nullptr;
}

/// The frame's one point light when its shading is the seed's plain setup (one point light; no
/// shadows, specular or rim band; no vertex colours), else null. Then shade_plain gives shade_hit's colour for every
/// hit on an untextured material; the renderer checks this once per tile, not per sample.
const Light* plain_point_light(const ShadingContext& ctx);

/// A point light as the seed lit a hit: l.n from the unit light vector against the unit normal,
/// computed as the seed did (dot with the unnormalised vector, divided by its length). Every
/// path of shade_hit uses this, so they all round alike.
struct PointLighting {
    Vec3f to_light;  ///< unnormalised, from the hit to the light
    float distance;
    float l_dot_n;
};
inline PointLighting light_point(const Vec3f& light_position, const Vec3f& p, const Vec3f& n) {
    PointLighting l;
    l.to_light = light_position - p;
    l.distance = length(l.to_light);
    l.l_dot_n = l.distance > 0.0f ? dot(l.to_light, n) / l.distance : 1.0f;
    return l;
}

/// light_terms under plain lighting (`light` from plain_point_light) on an untextured
/// material of colour `kd`: the band of the light's l.n, nothing blocked, no accents. It is
/// what light_terms's general path computes there: its diffuse sum starts at 0 and 0 + x == x,
/// with nothing else added. The light's n.l goes to *n_dot_l when it is not null.
inline LightTerms plain_light_terms(const ShadingContext& ctx, const Light& light, const Vec3f& kd,
                                    const Hit& hit, const Vec3f& eye, const Vec3f& dir,
                                    const Vec3f& n, float* n_dot_l = nullptr) {
    const Vec3f p = eye + dir * hit.t;
    const float l_dot_n = light_point(light.vector, p, n).l_dot_n;
    if (n_dot_l) *n_dot_l = l_dot_n;
    LightTerms terms;
    terms.albedo = kd;
    terms.diffuse = light.intensity * std::max(0.0f, l_dot_n);
    terms.band = ctx.settings.ramp.band(std::min(terms.diffuse, 1.0f));
    return terms;
}

}  // namespace toonray
