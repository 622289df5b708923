#include "toonray/render/shade_samples.h"

#include <cmath>
#include <limits>

namespace toonray {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// What shading needs of the triangle hit last: neighbouring samples mostly hit the same one.
// Its normals are those of shading_normal and geometric_normal, computed by the same
// operations, so they have the same bits.
struct HitTriangle {
    std::uint32_t prim = kNoIndex;
    std::uint32_t material = 0, object = 0;
    bool plain = false;           ///< lit by plain_light_terms: plain light, untextured material
    bool vertex_normals = false;  ///< all three corners have one
    Vec3f n0, n1, n2;
    bool face_ok = false;  ///< the face has a normal (a non-zero cross product)
    Vec3f face;            ///< that normal, unit
    Vec3f kd;
    bool texcoords = false;  ///< all three corners have texture coordinates
    Vec2f t0, t1, t2;

    void load(const ShadingContext& ctx, const Light* plain_light, std::uint32_t p) {
        const Scene& scene = ctx.scene;
        prim = p;
        material = scene.tri_material[p];
        object = scene.tri_object[p];
        plain = plain_light && !material_texture(ctx, material);
        kd = scene.materials[material].kd;
        const auto& tn = scene.tri_normals[p];
        vertex_normals = tn[0] != kNoIndex && tn[1] != kNoIndex && tn[2] != kNoIndex;
        if (vertex_normals) {
            n0 = scene.normals[tn[0]];
            n1 = scene.normals[tn[1]];
            n2 = scene.normals[tn[2]];
        }
        const auto& tt = scene.tri_texcoords[p];
        texcoords = tt[0] != kNoIndex && tt[1] != kNoIndex && tt[2] != kNoIndex;
        if (texcoords) {
            t0 = scene.texcoords[tt[0]];
            t1 = scene.texcoords[tt[1]];
            t2 = scene.texcoords[tt[2]];
        }
        const auto& tri = scene.tri_positions[p];
        const Vec3f& p0 = scene.positions[tri[0]];
        face = cross(scene.positions[tri[1]] - p0, scene.positions[tri[2]] - p0);
        const float len = length(face);
        face_ok = len > 0.0f;
        if (face_ok) face = face / len;
    }
    /// shading_normal(scene, hit, dir).
    [[nodiscard]] Vec3f shading_normal(const Hit& hit, const Vec3f& dir) const {
        Vec3f n;
        bool interpolated = false;
        if (vertex_normals) {
            const float w0 = 1.0f - hit.u - hit.v;
            n = n0 * w0 + n1 * hit.u + n2 * hit.v;
            const float len = length(n);
            if (len > 0.0f && std::isfinite(len)) {
                n = n / len;
                interpolated = true;
            }
        }
        if (!interpolated) n = face_ok ? face : -normalize(dir);
        return dot(n, dir) > 0.0f ? -n : n;
    }
    /// geometric_normal(scene, hit, dir).
    [[nodiscard]] Vec3f geometric_normal(const Vec3f& dir) const {
        const Vec3f n = face_ok ? face : -dir;
        return dot(n, dir) > 0.0f ? -n : n;
    }
    [[nodiscard]] Vec2f uv(const Hit& hit) const {
        if (!texcoords) return {};
        const float w0 = 1.0f - hit.u - hit.v;
        return {t0.x * w0 + t1.x * hit.u + t2.x * hit.v, t0.y * w0 + t1.y * hit.u + t2.y * hit.v};
    }
};

// One level of fields, as a template parameter so that the per-sample loop tests nothing but
// the hit.
template <SurfaceFields kLevel>
void shade_run(const ShadingContext& ctx, const ViewPlane& view, const Light* plain, int n,
               const Vec3f* dirs, const Hit* hits, const bool* found, SurfaceSamples& out,
               std::size_t offset) {
    constexpr bool kGeometry = kLevel >= SurfaceFields::Geometry;
    constexpr bool kAll = kLevel >= SurfaceFields::All;
    const std::size_t lights = kAll ? static_cast<std::size_t>(out.light_count) : 0;
    HitTriangle triangle;
    for (int k = 0; k < n; ++k) {
        const std::size_t i = offset + static_cast<std::size_t>(k);
        out.found[i] = found[k] ? 1 : 0;
        if (!found[k]) {
            out.object[i] = kNoIndex;
            out.material[i] = kNoIndex;
            out.band[i] = kNoBand;
            out.accents[i] = 0;
            out.albedo[i] = Vec3f(0.0f);
            if constexpr (kGeometry) {
                out.distance[i] = kInf;
                out.view_depth[i] = kInf;
                out.normal[i] = Vec3f(0.0f);
                out.geometric_normal[i] = Vec3f(0.0f);
            }
            if constexpr (kAll) {
                out.position[i] = Vec3f(0.0f);
                out.uv[i] = {};
                out.prim[i] = kNoIndex;
                out.barycentric[i] = {};
                out.diffuse[i] = 0.0f;
                for (std::size_t l = 0; l < lights; ++l) out.n_dot_l[i * lights + l] = 0.0f;
                out.shadowed[i] = 0;
            }
            continue;
        }
        const Hit& hit = hits[k];
        const Vec3f& dir = dirs[k];
        if (hit.prim != triangle.prim) triangle.load(ctx, plain, hit.prim);
        const Vec3f normal = triangle.shading_normal(hit, dir);
        float* n_dot_l = kAll ? out.n_dot_l.data() + i * lights : nullptr;
        const LightTerms terms =
            triangle.plain
                ? plain_light_terms(ctx, *plain, triangle.kd, hit, view.eye, dir, normal, n_dot_l)
                : light_terms(ctx, hit, view.eye, dir, normal, n_dot_l);
        out.object[i] = triangle.object;
        out.material[i] = triangle.material;
        out.band[i] = terms.band;
        out.accents[i] = terms.accents;
        out.albedo[i] = terms.albedo;
        if constexpr (kGeometry) {
            out.distance[i] = hit.t;
            out.view_depth[i] = hit.t * dot(dir, view.forward);
            out.normal[i] = normal;
            out.geometric_normal[i] = triangle.geometric_normal(dir);
        }
        if constexpr (kAll) {
            out.position[i] = view.eye + dir * hit.t;
            out.uv[i] = triangle.uv(hit);
            out.prim[i] = hit.prim;
            out.barycentric[i] = {hit.u, hit.v};
            out.diffuse[i] = terms.diffuse;
            out.shadowed[i] = terms.shadowed;
        }
    }
}

}  // namespace

void shade_samples(const ShadingContext& ctx, const ViewPlane& view, int n, const Vec3f* dirs,
                   const Hit* hits, const bool* found, SurfaceSamples& out, std::size_t offset) {
    const Light* plain = plain_point_light(ctx);
    switch (out.fields) {
        case SurfaceFields::Look:
            return shade_run<SurfaceFields::Look>(ctx, view, plain, n, dirs, hits, found, out,
                                                  offset);
        case SurfaceFields::Geometry:
            return shade_run<SurfaceFields::Geometry>(ctx, view, plain, n, dirs, hits, found, out,
                                                      offset);
        case SurfaceFields::All:
            return shade_run<SurfaceFields::All>(ctx, view, plain, n, dirs, hits, found, out,
                                                 offset);
    }
}

}  // namespace toonray
