#include "toonray/render/shading.h"

#include <cmath>
#include <fmt/format.h>

#include "toonray/core/error.h"
#include "toonray/core/parse.h"
#include "toonray/core/portable_math.h"

namespace toonray {
namespace {

// Bilinear lookup with wrap-around (texture coordinates repeat), v = 0 at the bottom as OBJ has it.
Vec3f sample_texture(const ImageRgb8& tex, float u, float v) {
    const int w = tex.width(), h = tex.height();
    float x = (u - std::floor(u)) * w - 0.5f;
    float y = (1.0f - (v - std::floor(v))) * h - 0.5f;
    int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
    float fx = x - x0, fy = y - y0;
    auto at = [&](int xi, int yi) {
        xi = ((xi % w) + w) % w;
        yi = ((yi % h) + h) % h;
        const Rgb8& c = tex(xi, yi);
        return Vec3f(c[0], c[1], c[2]) * (1.0f / 255.0f);
    };
    return (at(x0, y0) * (1 - fx) + at(x0 + 1, y0) * fx) * (1 - fy) +
           (at(x0, y0 + 1) * (1 - fx) + at(x0 + 1, y0 + 1) * fx) * fy;
}

}  // namespace

ToonRamp parse_ramp(const std::string& text) {
    auto at = text.find('@');
    ToonRamp ramp;
    const std::string what = fmt::format("ramp '{}'", text);
    ramp.levels = parse_number_list(text.substr(0, at), what);
    ramp.thresholds = at == std::string::npos ? std::vector<float>{}
                                              : parse_number_list(text.substr(at + 1), what);
    if (ramp.levels.empty()) throw Error(fmt::format("{}: needs at least one level", what));
    if (ramp.levels.size() > kMaxRampLevels)
        throw Error(
            fmt::format("{}: {} levels, more than {}", what, ramp.levels.size(), kMaxRampLevels));
    if (ramp.thresholds.size() + 1 != ramp.levels.size())
        throw Error(fmt::format("ramp '{}': {} levels need {} thresholds after '@', got {}", text,
                                ramp.levels.size(), ramp.levels.size() - 1,
                                ramp.thresholds.size()));
    for (std::size_t i = 1; i < ramp.thresholds.size(); ++i)
        if (!(ramp.thresholds[i] > ramp.thresholds[i - 1]))
            throw Error(fmt::format("ramp '{}': thresholds must increase", text));
    return ramp;
}

std::string format_ramp(const ToonRamp& ramp) {
    std::string out;
    for (std::size_t i = 0; i < ramp.levels.size(); ++i)
        out += (i ? "," : "") + format_number(ramp.levels[i]);
    if (!ramp.thresholds.empty()) out += "@";
    for (std::size_t i = 0; i < ramp.thresholds.size(); ++i)
        out += (i ? "," : "") + format_number(ramp.thresholds[i]);
    return out;
}

namespace {

// Everything light_terms can do: any lights, toon shadows, specular and rim bands, textures,
// vertex colours, for the hit at p. Kept out of line (noinline) so that the plain path
// (plain_light_terms), taken for almost every hit of a default frame, does not pay for this
// function's register saves and stack frame.
[[gnu::noinline]] LightTerms general_light_terms(const ShadingContext& ctx, const Hit& hit,
                                                 const Vec3f& dir, const Vec3f& n, const Vec3f& p,
                                                 const ImageRgb8* texture, float* n_dot_l) {
    const Scene& scene = ctx.scene;
    const TriangleMesh& mesh = scene.mesh_of(hit.instance);
    const ShadingSettings& s = ctx.settings;
    const Material& material = scene.materials[mesh.tri_material[hit.prim]];
    LightTerms terms;
    float diffuse = 0.0f;
    bool highlight = false;
    for (std::size_t i = 0; i < ctx.lights.size(); ++i) {
        const Light& light = ctx.lights[i];
        Vec3f to_light;
        float distance = std::numeric_limits<float>::infinity();
        float l_dot_n;
        if (light.kind == Light::Kind::Point) {
            const PointLighting l = light_point(light.vector, p, n);
            l_dot_n = l.l_dot_n;
            to_light = l.distance > 0.0f ? l.to_light / l.distance : n;
            distance = l.distance;
        } else {
            to_light = -normalize(light.vector);
            l_dot_n = dot(to_light, n);
        }
        if (n_dot_l) n_dot_l[i] = l_dot_n;
        if (s.shadows && l_dot_n > 0.0f) {
            // Leave the surface along its normal to avoid hitting it again.
            Vec3f origin = p + n * (1e-4f * std::max(1.0f, hit.t));
            if (ctx.accel.occluded(Ray{origin, to_light, distance})) {
                if (i < 32) terms.shadowed |= 1u << i;
                continue;
            }
        }
        diffuse += light.intensity * std::max(0.0f, l_dot_n);
        if (s.specular && material.ns > 0.0f &&
            (material.ks.x > 0 || material.ks.y > 0 || material.ks.z > 0)) {
            Vec3f half = normalize(to_light - dir);
            float n_dot_h = std::max(0.0f, dot(n, half));
            if (portable::pow(n_dot_h, material.ns) > 0.5f) highlight = true;  // one hard band
        }
    }
    Vec3f kd = material.kd;
    if (!mesh.colours.empty()) {
        const auto& tri = mesh.tri_positions[hit.prim];
        kd = kd * (mesh.colours[tri[0]] * (1.0f - hit.u - hit.v) + mesh.colours[tri[1]] * hit.u +
                   mesh.colours[tri[2]] * hit.v);
    } else if (!scene.meshes.empty() && scene.has_colours()) {
        // Where other meshes have colours, one without has white ones (as flatten_instances
        // gives it), interpolated like any others.
        const Vec3f white(1.0f);
        kd = kd * (white * (1.0f - hit.u - hit.v) + white * hit.u + white * hit.v);
    }
    if (texture) {
        const auto& tt = mesh.tri_texcoords[hit.prim];
        if (tt[0] != kNoIndex && tt[1] != kNoIndex && tt[2] != kNoIndex) {
            float w0 = 1.0f - hit.u - hit.v;
            const Vec2f& a = mesh.texcoords[tt[0]];
            const Vec2f& b = mesh.texcoords[tt[1]];
            const Vec2f& c = mesh.texcoords[tt[2]];
            kd = kd * sample_texture(*texture, a.x * w0 + b.x * hit.u + c.x * hit.v,
                                     a.y * w0 + b.y * hit.u + c.y * hit.v);
        }
    }
    // With one unit light the band is that of max(0, l.n): the seed's int(l.n * 16) bands.
    terms.albedo = kd;
    terms.diffuse = diffuse;
    terms.band = s.ramp.band(std::min(diffuse, 1.0f));
    if (highlight) terms.accents |= kAccentHighlight;
    if (s.rim > 0.0f && 1.0f - std::abs(dot(n, dir)) > 1.0f - s.rim) terms.accents |= kAccentRim;
    return terms;
}

}  // namespace

const Light* plain_point_light(const ShadingContext& ctx) {
    const ShadingSettings& s = ctx.settings;
    const bool plain = ctx.lights.size() == 1 && ctx.lights[0].kind == Light::Kind::Point &&
                       !s.shadows && !s.specular && !(s.rim > 0.0f) && !ctx.scene.has_colours();
    return plain ? &ctx.lights[0] : nullptr;
}

LightTerms light_terms(const ShadingContext& ctx, const Hit& hit, const Vec3f& eye,
                       const Vec3f& dir, const Vec3f& n, float* n_dot_l) {
    const std::uint32_t m = ctx.scene.mesh_of(hit.instance).tri_material[hit.prim];
    const ImageRgb8* texture = material_texture(ctx, m);
    if (const Light* light = plain_point_light(ctx); light && !texture)
        return plain_light_terms(ctx, *light, ctx.scene.materials[m].kd, hit, eye, dir, n, n_dot_l);
    return general_light_terms(ctx, hit, dir, n, eye + dir * hit.t, texture, n_dot_l);
}

Vec3f shade_hit(const ShadingContext& ctx, const Hit& hit, const Vec3f& eye, const Vec3f& dir,
                const Vec3f& n) {
    const LightTerms t = light_terms(ctx, hit, eye, dir, n);
    const Material& material =
        ctx.scene.materials[ctx.scene.mesh_of(hit.instance).tri_material[hit.prim]];
    return cel_colour(ctx.settings, t.albedo, t.band, t.accents, material.ks);
}

}  // namespace toonray
