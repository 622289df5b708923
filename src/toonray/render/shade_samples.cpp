#include "toonray/render/shade_samples.h"

#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "toonray/core/error.h"

namespace toonray {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// What shading needs of the triangle hit last: neighbouring samples mostly hit the same one.
// Its normals are those of shading_normal and geometric_normal, computed by the same
// operations, so they have the same bits.
struct HitTriangle {
    std::uint32_t prim = kNoIndex;
    std::uint32_t instance = kNoIndex;
    std::uint32_t material = 0, object = 0;
    bool plain = false;           ///< lit by plain_light_terms: plain light, untextured material
    bool vertex_normals = false;  ///< all three corners have one
    Vec3f n0, n1, n2;
    bool face_ok = false;  ///< the face has a normal (a non-zero cross product)
    Vec3f face;            ///< that normal, unit
    Vec3f kd;
    bool texcoords = false;  ///< all three corners have texture coordinates
    Vec2f t0, t1, t2;

    [[nodiscard]] bool is(const Hit& hit) const {
        return hit.prim == prim && hit.instance == instance;
    }
    void load(const ShadingContext& ctx, const Light* plain_light, const Hit& hit) {
        const Scene& scene = ctx.scene;
        const std::uint32_t p = hit.prim;
        prim = p;
        instance = hit.instance;
        if (instance != kNoIndex) return load_instanced(ctx, plain_light);
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
    // A triangle of an instance: its mesh's, in world space as flatten_instances would put it
    // (world_corners, world_normal), with the instance's object.
    [[gnu::noinline]] void load_instanced(const ShadingContext& ctx, const Light* plain_light) {
        const Scene& scene = ctx.scene;
        const TriangleMesh& mesh = scene.mesh_of(instance);
        material = mesh.tri_material[prim];
        object = scene.instances[instance].object;
        plain = plain_light && !material_texture(ctx, material);
        kd = scene.materials[material].kd;
        const auto& tn = mesh.tri_normals[prim];
        vertex_normals = tn[0] != kNoIndex && tn[1] != kNoIndex && tn[2] != kNoIndex;
        if (vertex_normals) {
            n0 = world_normal(scene, instance, prim, 0);
            n1 = world_normal(scene, instance, prim, 1);
            n2 = world_normal(scene, instance, prim, 2);
        }
        const auto& tt = mesh.tri_texcoords[prim];
        texcoords = tt[0] != kNoIndex && tt[1] != kNoIndex && tt[2] != kNoIndex;
        if (texcoords) {
            t0 = mesh.texcoords[tt[0]];
            t1 = mesh.texcoords[tt[1]];
            t2 = mesh.texcoords[tt[2]];
        }
        const std::array<Vec3f, 3> p = world_corners(scene, instance, prim);
        face = cross(p[1] - p[0], p[2] - p[0]);
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

// Where shade_run writes: the arrays of a SurfaceSamples from the first sample written, as
// plain pointers. The byte arrays (found, band, accents) could alias anything through the
// vectors: with restrict pointers the loop does not reload every array's address after each
// store.
struct Outputs {
    std::uint8_t* __restrict found;
    std::uint32_t* __restrict object;
    std::uint32_t* __restrict material;
    std::uint8_t* __restrict band;
    std::uint8_t* __restrict accents;
    Vec3f* __restrict albedo;
    Vec3f* __restrict colour;
    std::uint32_t* __restrict edge;
    float* __restrict distance;
    float* __restrict view_depth;
    Vec3f* __restrict normal;
    Vec3f* __restrict geometric_normal;
    Vec3f* __restrict position;
    Vec2f* __restrict uv;
    std::uint32_t* __restrict prim;
    Vec2f* __restrict barycentric;
    float* __restrict diffuse;
    float* __restrict n_dot_l;
    std::uint32_t* __restrict shadowed;

    Outputs(SurfaceSamples& s, std::size_t offset) {
        auto at = [offset](auto& v) { return v.empty() ? nullptr : v.data() + offset; };
        found = at(s.found);
        object = at(s.object);
        material = at(s.material);
        band = at(s.band);
        accents = at(s.accents);
        albedo = at(s.albedo);
        colour = at(s.colour);
        edge = at(s.edge);
        distance = at(s.distance);
        view_depth = at(s.view_depth);
        normal = at(s.normal);
        geometric_normal = at(s.geometric_normal);
        position = at(s.position);
        uv = at(s.uv);
        prim = at(s.prim);
        barycentric = at(s.barycentric);
        diffuse = at(s.diffuse);
        n_dot_l = s.n_dot_l.empty() ? nullptr : s.n_dot_l.data() + offset * s.light_count;
        shadowed = at(s.shadowed);
    }
};

// The fields kept (SurfaceFields bits), as a template parameter so that the per-sample loop
// tests nothing but the hit.
template <unsigned kFields>
void shade_run(const ShadingContext& ctx, const LookFrame& look, const ViewPlane& view,
               const Light* plain, int n, const Vec3f* dirs, const Hit* hits, const bool* found,
               const Outputs& out, std::size_t lights) {
    constexpr bool kKeys = (kFields & kSurfaceKeys) != 0;
    constexpr bool kDistance = (kFields & kSurfaceDistance) != 0;
    constexpr bool kViewDepth = (kFields & kSurfaceViewDepth) != 0;
    constexpr bool kAll = (kFields & kSurfaceWhere) != 0;
    HitTriangle triangle;
    for (int i = 0; i < n; ++i) {
        out.found[i] = found[i] ? 1 : 0;
        if (!found[i]) {
            if constexpr (kKeys) {
                out.object[i] = kNoIndex;
                out.material[i] = kNoIndex;
                out.band[i] = kNoBand;
                out.accents[i] = 0;
                out.edge[i] = 0;
            }
            if constexpr (kDistance) {
                out.distance[i] = kInf;
                out.normal[i] = Vec3f(0.0f);
            }
            if constexpr (kViewDepth) {
                out.view_depth[i] = kInf;
                out.geometric_normal[i] = Vec3f(0.0f);
            }
            if constexpr (kAll) {
                out.albedo[i] = Vec3f(0.0f);
                out.position[i] = Vec3f(0.0f);
                out.uv[i] = {};
                out.prim[i] = kNoIndex;
                out.barycentric[i] = {};
                out.diffuse[i] = 0.0f;
                for (std::size_t l = 0; l < lights; ++l) out.n_dot_l[i * lights + l] = 0.0f;
                out.shadowed[i] = 0;
            }
            out.colour[i] = look_miss(look).colour;
            continue;
        }
        const Hit& hit = hits[i];
        const Vec3f& dir = dirs[i];
        if (!triangle.is(hit)) triangle.load(ctx, plain, hit);
        const Vec3f normal = triangle.shading_normal(hit, dir);
        float* n_dot_l = kAll ? out.n_dot_l + i * lights : nullptr;
        const LightTerms terms =
            triangle.plain
                ? plain_light_terms(ctx, *plain, triangle.kd, hit, view.eye, dir, normal, n_dot_l)
                : light_terms(ctx, hit, view.eye, dir, normal, n_dot_l);
        const LookResult seen =
            look_hit(look, triangle.material, terms.albedo, terms.band, terms.accents);
        out.colour[i] = seen.colour;
        if constexpr (kKeys) {
            out.object[i] = triangle.object;
            out.material[i] = triangle.material;
            out.band[i] = terms.band;
            out.accents[i] = terms.accents;
            out.edge[i] = seen.edge;
        }
        if constexpr (kDistance) {
            out.distance[i] = hit.t;
            out.normal[i] = normal;
        }
        if constexpr (kViewDepth) {
            out.view_depth[i] = hit.t * dot(dir, view.forward);
            out.geometric_normal[i] = triangle.geometric_normal(dir);
        }
        if constexpr (kAll) {
            out.albedo[i] = terms.albedo;
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

void shade_samples(const ShadingContext& ctx, const LookFrame& look, const ViewPlane& view, int n,
                   const Vec3f* dirs, const Hit* hits, const bool* found, SurfaceSamples& out,
                   std::size_t offset) {
    const Light* plain = plain_point_light(ctx);
    const Outputs to(out, offset);
    const auto lights = static_cast<std::size_t>(out.light_count);
    // The sets of fields the line modes keep, each its own loop; any other, everything.
    switch (out.fields) {
        case 0: return shade_run<0>(ctx, look, view, plain, n, dirs, hits, found, to, lights);
        case kSurfaceKeys:
            return shade_run<kSurfaceKeys>(ctx, look, view, plain, n, dirs, hits, found, to,
                                           lights);
        case kSurfaceDistance:
            return shade_run<kSurfaceDistance>(ctx, look, view, plain, n, dirs, hits, found, to,
                                               lights);
        case kSurfaceKeys | kSurfaceViewDepth:
            return shade_run<kSurfaceKeys | kSurfaceViewDepth>(ctx, look, view, plain, n, dirs,
                                                               hits, found, to, lights);
        default: {
            SurfaceSamples& all = out;
            if (all.fields != kSurfaceAll)
                throw Error(fmt::format("shading: no loop for the fields {}", all.fields));
            return shade_run<kSurfaceAll>(ctx, look, view, plain, n, dirs, hits, found, to, lights);
        }
    }
}

}  // namespace toonray
