// Every float operation here must round exactly as the scalar shading functions do (the
// project compiles with -ffp-contract=off, and each vector expression below is the scalar one
// in the same order): frames are compared bit for bit across builds and CPUs.
#include "toonray/render/shade_samples.h"

#include "toonray/core/simd_sse.h"

#include <array>
#include <cstdlib>
#include <limits>

namespace toonray {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// A vector of three components, four lanes each.
struct V3 {
    __m128 x, y, z;
};

inline V3 sub(const V3& a, const V3& b) {
    return {_mm_sub_ps(a.x, b.x), _mm_sub_ps(a.y, b.y), _mm_sub_ps(a.z, b.z)};
}
inline V3 scale(const V3& a, __m128 s) {
    return {_mm_mul_ps(a.x, s), _mm_mul_ps(a.y, s), _mm_mul_ps(a.z, s)};
}
inline V3 divide(const V3& a, __m128 s) {
    return {_mm_div_ps(a.x, s), _mm_div_ps(a.y, s), _mm_div_ps(a.z, s)};
}
inline V3 negate(const V3& a) {
    const __m128 sign = _mm_set1_ps(-0.0f);
    return {_mm_xor_ps(a.x, sign), _mm_xor_ps(a.y, sign), _mm_xor_ps(a.z, sign)};
}
// dot(): (x * x' + y * y') + z * z'.
inline __m128 dot4(const V3& a, const V3& b) {
    return _mm_add_ps(_mm_add_ps(_mm_mul_ps(a.x, b.x), _mm_mul_ps(a.y, b.y)), _mm_mul_ps(a.z, b.z));
}
// cross() component by component.
inline V3 cross4(const V3& a, const V3& b) {
    return {_mm_sub_ps(_mm_mul_ps(a.y, b.z), _mm_mul_ps(a.z, b.y)),
            _mm_sub_ps(_mm_mul_ps(a.z, b.x), _mm_mul_ps(a.x, b.z)),
            _mm_sub_ps(_mm_mul_ps(a.x, b.y), _mm_mul_ps(a.y, b.x))};
}
inline V3 select(__m128 mask, const V3& yes, const V3& no) {
    return {_mm_blendv_ps(no.x, yes.x, mask), _mm_blendv_ps(no.y, yes.y, mask),
            _mm_blendv_ps(no.z, yes.z, mask)};
}
// n turned to face the viewer: -n where dot(n, dir) > 0.
inline V3 facing(const V3& n, const V3& dir) {
    return select(_mm_cmpgt_ps(dot4(n, dir), _mm_setzero_ps()), negate(n), n);
}

inline void store(const V3& v, Vec3f* out) {
    alignas(16) float x[4], y[4], z[4];
    _mm_store_ps(x, v.x);
    _mm_store_ps(y, v.y);
    _mm_store_ps(z, v.z);
    for (int l = 0; l < 4; ++l) out[l] = Vec3f(x[l], y[l], z[l]);
}

// Four lanes' Vec3f values as one V3.
template <typename Get>
inline V3 gather(Get get) {
    const Vec3f a = get(0), b = get(1), c = get(2), d = get(3);
    return {_mm_setr_ps(a.x, b.x, c.x, d.x), _mm_setr_ps(a.y, b.y, c.y, d.y),
            _mm_setr_ps(a.z, b.z, c.z, d.z)};
}

// The outputs shade_samples can be asked for, as a template parameter so that the per-sample
// loop tests nothing but the hit: the colour (and whether each ray hit) alone; with the
// surface the robust lines and feature images need (view depth, geometric normal, ids); or
// the classic G-buffer (distance, shading normal, ids).
enum class Outputs { Colour, Surface, Classic };

template <Outputs kOut>
void shade_run(const ShadingContext& ctx, const ViewPlane& view, const Vec3f& background,
               const Light* plain, int begin, int end, const Vec3f* dirs, const Hit* hits,
               const bool* found, const ShadedSamples& out) {
    const Scene& scene = ctx.scene;
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
        const Vec3f n = shading_normal(scene, hit, dir);
        const std::uint32_t m = scene.tri_material[hit.prim];
        out.colour[i] = plain && !material_texture(ctx, m)
                            ? shade_plain(ctx, *plain, hit, view.eye, dir, n)
                            : shade_hit(ctx, hit, view.eye, dir, n);
        if constexpr (kOut == Outputs::Surface) {
            out.view_depth[i] = hit.t * dot(dir, view.forward);
            out.geometric_normal[i] = geometric_normal(scene, hit, dir);
        }
        if constexpr (kOut == Outputs::Classic) {
            out.distance[i] = hit.t;
            out.shading_normal[i] = n;
        }
        if constexpr (kOut != Outputs::Colour) {
            out.material[i] = m;
            out.object[i] = scene.tri_object[hit.prim];
        }
    }
}

// Four hits under the plain point light on untextured materials, in SIMD.
template <Outputs kOut>
void shade_four_plain(const ShadingContext& ctx, const ViewPlane& view, const Light& light,
                      const Vec3f* dirs, const Hit* hits, const ShadedSamples& out, int i) {
    const Scene& scene = ctx.scene;
    const std::array<std::uint32_t, 3>* tn[4];
    bool all_with_normals = true;
    alignas(16) std::uint32_t with_normals[4];
    for (int l = 0; l < 4; ++l) {
        tn[l] = &scene.tri_normals[hits[l].prim];
        const bool with =
            (*tn[l])[0] != kNoIndex && (*tn[l])[1] != kNoIndex && (*tn[l])[2] != kNoIndex;
        with_normals[l] = with ? ~0u : 0u;
        all_with_normals &= with;
    }
    const V3 dir = gather([&](int l) { return dirs[l]; });
    const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f), inf = _mm_set1_ps(kInf);
    const __m128 tv = _mm_setr_ps(hits[0].t, hits[1].t, hits[2].t, hits[3].t);
    const __m128 uv = _mm_setr_ps(hits[0].u, hits[1].u, hits[2].u, hits[3].u);
    const __m128 vv = _mm_setr_ps(hits[0].v, hits[1].v, hits[2].v, hits[3].v);

    // The face's normal, cross(p1 - p0, p2 - p0), where some lane or the outputs need it.
    const bool need_face = !all_with_normals || kOut == Outputs::Surface;
    V3 face_unit{zero, zero, zero};
    __m128 face_ok = zero;
    if (need_face) {
        auto corner = [&](int c) {
            return gather(
                [&](int l) { return scene.positions[scene.tri_positions[hits[l].prim][c]]; });
        };
        const V3 a = corner(0);
        const V3 face = cross4(sub(corner(1), a), sub(corner(2), a));
        const __m128 face_length = _mm_sqrt_ps(dot4(face, face));
        face_ok = _mm_cmpgt_ps(face_length, zero);
        face_unit = divide(face, face_length);
    }

    // shading_normal: the vertex normals interpolated, n0 w0 + n1 u + n2 v with w0 = 1 - u - v,
    // where all three corners have one and the result has a finite, non-zero length; else the
    // face's normal, or -normalize(dir) for a degenerate face.
    auto vertex_normal = [&](int c) {
        return gather(
            [&](int l) { return with_normals[l] ? scene.normals[(*tn[l])[c]] : Vec3f(0.0f); });
    };
    const __m128 w0 = _mm_sub_ps(_mm_sub_ps(one, uv), vv);
    const V3 m0 = scale(vertex_normal(0), w0), m1 = scale(vertex_normal(1), uv),
             m2 = scale(vertex_normal(2), vv);
    const V3 blended{_mm_add_ps(_mm_add_ps(m0.x, m1.x), m2.x),
                     _mm_add_ps(_mm_add_ps(m0.y, m1.y), m2.y),
                     _mm_add_ps(_mm_add_ps(m0.z, m1.z), m2.z)};
    const __m128 blended_length = _mm_sqrt_ps(dot4(blended, blended));
    const __m128 interpolated = _mm_and_ps(
        _mm_castsi128_ps(_mm_load_si128(reinterpret_cast<const __m128i*>(with_normals))),
        _mm_and_ps(_mm_cmpgt_ps(blended_length, zero), _mm_cmplt_ps(blended_length, inf)));
    V3 normal = divide(blended, blended_length);
    if (!all_with_normals || _mm_movemask_ps(interpolated) != 0xf) {
        const V3 away = negate(divide(dir, _mm_sqrt_ps(dot4(dir, dir))));
        normal = select(interpolated, normal, select(face_ok, face_unit, away));
    }
    normal = facing(normal, dir);

    // shade_plain: l.n of the light from the hit point eye + dir t, clamped, banded.
    const V3 point{_mm_add_ps(_mm_set1_ps(view.eye.x), _mm_mul_ps(dir.x, tv)),
                   _mm_add_ps(_mm_set1_ps(view.eye.y), _mm_mul_ps(dir.y, tv)),
                   _mm_add_ps(_mm_set1_ps(view.eye.z), _mm_mul_ps(dir.z, tv))};
    const V3 lamp{_mm_set1_ps(light.vector.x), _mm_set1_ps(light.vector.y),
                  _mm_set1_ps(light.vector.z)};
    const V3 to_light = sub(lamp, point);
    const __m128 distance = _mm_sqrt_ps(dot4(to_light, to_light));
    const __m128 l_dot_n = _mm_blendv_ps(one, _mm_div_ps(dot4(to_light, normal), distance),
                                         _mm_cmpgt_ps(distance, zero));
    // std::max(0, l.n) is maxps(l.n, 0) and std::min(d, 1) is minps(1, d), NaNs included.
    const __m128 diffuse =
        _mm_min_ps(one, _mm_mul_ps(_mm_set1_ps(light.intensity), _mm_max_ps(l_dot_n, zero)));
    // ToonRamp::level: the first threshold the diffuse term is below.
    const ToonRamp& ramp = ctx.settings.ramp;
    __m128i band = _mm_setzero_si128();
    __m128 above = _mm_castsi128_ps(_mm_set1_epi32(-1));
    for (float threshold : ramp.thresholds) {
        above = _mm_and_ps(above, _mm_cmpge_ps(diffuse, _mm_set1_ps(threshold)));
        band = _mm_sub_epi32(band, _mm_castps_si128(above));
    }
    alignas(16) std::int32_t bands[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(bands), band);
    for (int l = 0; l < 4; ++l) {
        const std::uint32_t m = scene.tri_material[hits[l].prim];
        out.colour[i + l] = scene.materials[m].kd * ramp.levels[bands[l]];
        if constexpr (kOut != Outputs::Classic) out.found[i + l] = 1;
        if constexpr (kOut != Outputs::Colour) {
            out.material[i + l] = m;
            out.object[i + l] = scene.tri_object[hits[l].prim];
        }
    }
    if constexpr (kOut == Outputs::Classic) {
        store(normal, out.shading_normal + i);
        _mm_storeu_ps(out.distance + i, tv);
    }
    if constexpr (kOut == Outputs::Surface) {
        store(facing(select(face_ok, face_unit, negate(dir)), dir), out.geometric_normal + i);
        const V3 forward{_mm_set1_ps(view.forward.x), _mm_set1_ps(view.forward.y),
                         _mm_set1_ps(view.forward.z)};
        _mm_storeu_ps(out.view_depth + i, _mm_mul_ps(tv, dot4(dir, forward)));
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
    int i = 0;
    static const bool simd = std::getenv("TOONRAY_SIMD_SHADE") != nullptr;
    if (plain && simd) {
        for (; i + 4 <= n; i += 4) {
            bool four = found[i] && found[i + 1] && found[i + 2] && found[i + 3];
            for (int l = 0; l < 4 && four; ++l)
                four = material_texture(ctx, ctx.scene.tri_material[hits[i + l].prim]) == nullptr;
            if (!four) run(i, i + 4);
            else if (kind == Outputs::Colour)
                shade_four_plain<Outputs::Colour>(ctx, view, *plain, dirs + i, hits + i, out, i);
            else if (kind == Outputs::Surface)
                shade_four_plain<Outputs::Surface>(ctx, view, *plain, dirs + i, hits + i, out, i);
            else shade_four_plain<Outputs::Classic>(ctx, view, *plain, dirs + i, hits + i, out, i);
        }
    }
    run(i, n);
}

}  // namespace toonray
