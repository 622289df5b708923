#include "toonray/render/shade_samples.h"

#include <cmath>
#include <limits>

namespace toonray {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// The outputs shade_samples can be asked for, as a template parameter so that the per-sample
// loop tests nothing but the hit: the colour (and whether each ray hit) alone; with the
// surface the robust lines and feature images need (view depth, geometric normal, ids); or
// the classic G-buffer (distance, shading normal, ids).
enum class Outputs { Colour, Surface, Classic };

// What shading needs of the triangle hit last: neighbouring samples mostly hit the same one.
// Its normals are those of shading_normal and geometric_normal, computed by the same
// operations, so they have the same bits.
struct HitTriangle {
    std::uint32_t prim = kNoIndex;
    std::uint32_t material = 0, object = 0;
    bool plain = false;           ///< shaded by shade_plain: plain light, untextured material
    bool vertex_normals = false;  ///< all three corners have one
    Vec3f n0, n1, n2;
    bool face_ok = false;  ///< the face has a normal (a non-zero cross product)
    Vec3f face;            ///< that normal, unit
    Vec3f kd;

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
};

template <Outputs kOut>
void shade_run(const ShadingContext& ctx, const ViewPlane& view, const Vec3f& background,
               const Light* plain, int begin, int end, const Vec3f* dirs, const Hit* hits,
               const bool* found, const ShadedSamples& out) {
    HitTriangle triangle;
    for (int i = begin; i < end; ++i) {
        if constexpr (kOut != Outputs::Classic) out.found[i] = found[i] ? 1 : 0;
        if (!found[i]) {
            out.colour[i] = background;
            if constexpr (kOut == Outputs::Surface) {
                out.view_depth[i] = kInf;
                out.geometric_normal[i] = Vec3f(0.0f);
            }
            if constexpr (kOut == Outputs::Classic) {
                out.distance[i] = kInf;
                out.shading_normal[i] = Vec3f(0.0f);
            }
            if constexpr (kOut != Outputs::Colour) {
                out.material[i] = kNoIndex;
                out.object[i] = kNoIndex;
            }
            continue;
        }
        const Hit& hit = hits[i];
        const Vec3f& dir = dirs[i];
        if (hit.prim != triangle.prim) triangle.load(ctx, plain, hit.prim);
        const Vec3f n = triangle.shading_normal(hit, dir);
        out.colour[i] = triangle.plain
                            ? shade_plain(ctx, *plain, triangle.kd, hit, view.eye, dir, n)
                            : shade_hit(ctx, hit, view.eye, dir, n);
        if constexpr (kOut == Outputs::Surface) {
            out.view_depth[i] = hit.t * dot(dir, view.forward);
            out.geometric_normal[i] = triangle.geometric_normal(dir);
        }
        if constexpr (kOut == Outputs::Classic) {
            out.distance[i] = hit.t;
            out.shading_normal[i] = n;
        }
        if constexpr (kOut != Outputs::Colour) {
            out.material[i] = triangle.material;
            out.object[i] = triangle.object;
        }
    }
}

}  // namespace

void shade_samples(const ShadingContext& ctx, const ViewPlane& view, const Vec3f& background, int n,
                   const Vec3f* dirs, const Hit* hits, const bool* found,
                   const ShadedSamples& out) {
    const Light* plain = plain_point_light(ctx);
    const Outputs kind =
        out.distance ? Outputs::Classic : (out.view_depth ? Outputs::Surface : Outputs::Colour);
    auto run = [&](int begin, int end) {
        switch (kind) {
            case Outputs::Colour:
                return shade_run<Outputs::Colour>(ctx, view, background, plain, begin, end, dirs,
                                                  hits, found, out);
            case Outputs::Surface:
                return shade_run<Outputs::Surface>(ctx, view, background, plain, begin, end, dirs,
                                                   hits, found, out);
            case Outputs::Classic:
                return shade_run<Outputs::Classic>(ctx, view, background, plain, begin, end, dirs,
                                                   hits, found, out);
        }
    };
    run(0, n);
}

}  // namespace toonray
