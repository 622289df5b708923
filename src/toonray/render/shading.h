#pragma once
/// Toon shading of a hit: the diffuse light picks a band of a ramp that scales the material's
/// colour; optional hard-edged specular and rim bands, toon shadows and textures.
///
/// With the defaults (the seed's ramp, one point light, nothing optional) this is exactly the
/// seed's cel shading: k = clamp(int(l.n * 16), 0, 15) into {0.5 x4, 0.75 x4, 1.0 x8}.

#include <memory>
#include <string>
#include <vector>

#include "toonray/accel/triangle_accel.h"
#include "toonray/core/image.h"
#include "toonray/core/math.h"
#include "toonray/scene/scene.h"

namespace toonray {

/// Bands of a toon ramp: diffuse light below thresholds[0] gives levels[0], below
/// thresholds[1] levels[1], ..., and levels.back() above the last threshold.
struct ToonRamp {
    std::vector<float> levels{0.5f, 0.75f, 1.0f};
    std::vector<float> thresholds{0.25f, 0.5f};

    [[nodiscard]] float level(float diffuse) const {
        std::size_t i = 0;
        while (i < thresholds.size() && diffuse >= thresholds[i]) ++i;
        return levels[i];
    }
};

/// Parses "0.5,0.75,1.0@0.25,0.5": N levels, then N-1 increasing thresholds. Throws Error
/// ("ramp '...': ...").
ToonRamp parse_ramp(const std::string& text);

struct Light {
    enum class Kind { Point, Directional };
    Kind kind = Kind::Point;
    Vec3f vector;  ///< point: position; directional: direction the light travels
    float intensity = 1.0f;
};

/// Parses "x,y,z" or "point:x,y,z" (a point light) or "dir:x,y,z" (a directional light,
/// shining along the vector), each optionally followed by "@intensity". Throws Error
/// ("light '...': ...").
Light parse_light(const std::string& text);

struct ShadingSettings {
    ToonRamp ramp;
    std::vector<Light> lights;   ///< empty: the default point light (see Renderer)
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
    const std::vector<Light>& lights;  ///< resolved (never empty)
    const TextureSet* textures = nullptr;
};

/// The hit triangle's geometric normal, unit, facing the viewer. Inline (as is shading_normal):
/// both run once per sample, inside the renderer's per-tile loop.
inline Vec3f geometric_normal(const Scene& scene, const Hit& hit, const Vec3f& dir) {
    const auto& tri = scene.tri_positions[hit.prim];
    const Vec3f& p0 = scene.positions[tri[0]];
    Vec3f n = cross(scene.positions[tri[1]] - p0, scene.positions[tri[2]] - p0);
    float len = length(n);
    n = len > 0.0f ? n / len : -dir;
    return dot(n, dir) > 0.0f ? -n : n;
}

/// The shading normal at a hit: vertex normals interpolated when all three corners have one,
/// else the geometric normal; turned to face the viewer (against `dir`).
inline Vec3f shading_normal(const Scene& scene, const Hit& hit, const Vec3f& dir) {
    const auto& tri = scene.tri_positions[hit.prim];
    const auto& tn = scene.tri_normals[hit.prim];
    Vec3f n;
    bool interpolated = false;
    if (tn[0] != kNoIndex && tn[1] != kNoIndex && tn[2] != kNoIndex) {
        float w0 = 1.0f - hit.u - hit.v;
        n = scene.normals[tn[0]] * w0 + scene.normals[tn[1]] * hit.u + scene.normals[tn[2]] * hit.v;
        float len = length(n);
        if (len > 0.0f && std::isfinite(len)) {
            n = n / len;
            interpolated = true;
        }
    }
    if (!interpolated) {
        const Vec3f& p0 = scene.positions[tri[0]];
        n = cross(scene.positions[tri[1]] - p0, scene.positions[tri[2]] - p0);
        float len = length(n);
        n = len > 0.0f ? n / len : -normalize(dir);
    }
    return dot(n, dir) > 0.0f ? -n : n;
}

/// Toon colour of a hit seen along `dir` from `eye`, with shading normal `n`.
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

/// shade_hit under plain lighting (`light` from plain_point_light) on an untextured material:
/// Kd times the ramp's band for the light's l.n. It is what shade_hit's general path computes
/// there: its diffuse sum starts at 0 and 0 + x == x, with nothing else added.
inline Vec3f shade_plain(const ShadingContext& ctx, const Light& light, const Vec3f& kd,
                         const Hit& hit, const Vec3f& eye, const Vec3f& dir, const Vec3f& n) {
    const Vec3f p = eye + dir * hit.t;
    const float diffuse = light.intensity * std::max(0.0f, light_point(light.vector, p, n).l_dot_n);
    return kd * ctx.settings.ramp.level(std::min(diffuse, 1.0f));
}
/// The same with the hit triangle's material's Kd.
inline Vec3f shade_plain(const ShadingContext& ctx, const Light& light, const Hit& hit,
                         const Vec3f& eye, const Vec3f& dir, const Vec3f& n) {
    const Material& material = ctx.scene.materials[ctx.scene.tri_material[hit.prim]];
    return shade_plain(ctx, light, material.kd, hit, eye, dir, n);
}

}  // namespace toonray
