#pragma once
/// The scalar watertight ray/triangle test (internal to the accel module). Every SIMD kernel
/// does exactly these float operations in this order, lane by lane, so that all paths give the
/// same t bit for bit; exact zeros of the edge functions go back to this code (double).
///
/// Internal linkage on purpose: the AVX2 kernels include it too, compiled for another target,
/// and the copies must not be merged by the linker.

#include <cmath>
#include <utility>

#include "toonray/accel/ray.h"
#include "toonray/core/index.h"

namespace toonray::accel {
namespace {

// Watertight ray/triangle intersection (Woop, Benthin and Wald, JCGT 2013): the ray is
// sheared so that it runs along +z, and the triangle's 2D edge functions are evaluated in that
// frame. Neighbouring triangles compute the same edge function for a shared edge, so a ray can
// never slip between them (Moller-Trumbore can, leaving pinholes that show as specks of far
// depth). Exact zeros are re-evaluated in double, as the paper prescribes.
struct ShearedRay {
    int kx, ky, kz;
    float sx, sy, sz;
    Vec3f origin;

    ShearedRay() = default;
    explicit ShearedRay(const Ray& ray) : ShearedRay(ray.origin, ray.dir) {}
    ShearedRay(const Vec3f& org, const Vec3f& dir) : origin(org) {
        float ax = std::abs(dir.x), ay = std::abs(dir.y), az = std::abs(dir.z);
        kz = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
        kx = (kz + 1) % 3;
        ky = (kx + 1) % 3;
        if (dir[kz] < 0.0f) std::swap(kx, ky);  // keep the winding
        sx = dir[kx] / dir[kz];
        sy = dir[ky] / dir[kz];
        sz = 1.0f / dir[kz];
    }
};

inline bool watertight_test(const ShearedRay& r, const Vec3f& v0, const Vec3f& v1, const Vec3f& v2,
                            float tmax, float& t, float& u, float& v) {
    const Vec3f a = v0 - r.origin, b = v1 - r.origin, c = v2 - r.origin;
    const float ax = a[r.kx] - r.sx * a[r.kz], ay = a[r.ky] - r.sy * a[r.kz];
    const float bx = b[r.kx] - r.sx * b[r.kz], by = b[r.ky] - r.sy * b[r.kz];
    const float cx = c[r.kx] - r.sx * c[r.kz], cy = c[r.ky] - r.sy * c[r.kz];
    float e0 = cx * by - cy * bx;  // weight of v0
    float e1 = ax * cy - ay * cx;  // weight of v1
    float e2 = bx * ay - by * ax;  // weight of v2
    if (e0 == 0.0f || e1 == 0.0f || e2 == 0.0f) {
        e0 = static_cast<float>(static_cast<double>(cx) * by - static_cast<double>(cy) * bx);
        e1 = static_cast<float>(static_cast<double>(ax) * cy - static_cast<double>(ay) * cx);
        e2 = static_cast<float>(static_cast<double>(bx) * ay - static_cast<double>(by) * ax);
    }
    if ((e0 < 0.0f || e1 < 0.0f || e2 < 0.0f) && (e0 > 0.0f || e1 > 0.0f || e2 > 0.0f))
        return false;
    const float det = e0 + e1 + e2;
    if (det == 0.0f) return false;
    const float az = r.sz * a[r.kz], bz = r.sz * b[r.kz], cz = r.sz * c[r.kz];
    const float scaled_t = e0 * az + e1 * bz + e2 * cz;
    // Only t itself is tested, after the division. A cheaper test of scaled_t against
    // tmax * det, with relative slack, fails where those products fall among the denormals:
    // it then rejected hits at exactly tmax, so a tie went to whichever triangle was met first
    // rather than to the lower index.
    const float inv = 1.0f / det;
    t = scaled_t * inv;
    u = e1 * inv;
    v = e2 * inv;
    return t > 0.0f && t <= tmax;
}

// The box tests' slack on the far distance (pbrt's 1 + 2 gamma(3), rounded up): rounding never
// culls a box whose triangle is hit at exactly tmax, so ties reach the triangle test and are
// broken by index.
inline constexpr float kBoxSlack = 1.0f + 1.0f / (1 << 20);

// Best hit so far. A candidate hit is taken when it is nearer, or at the same distance with a
// lower triangle index (but a first hit must be strictly inside the ray's tmax): the result is
// the lowest (t, index) pair, whatever order triangles are tested in.
struct BestHit {
    float t;
    std::uint32_t prim = kNoIndex;
    float u = 0, v = 0;

    [[nodiscard]] bool takes(float t_new, std::uint32_t prim_new) const {
        return t_new < t || (t_new == t && prim != kNoIndex && prim_new < prim);
    }
    void take(float t_new, std::uint32_t prim_new, float u_new, float v_new) {
        t = t_new;
        prim = prim_new;
        u = u_new;
        v = v_new;
    }
};

}  // namespace
}  // namespace toonray::accel
