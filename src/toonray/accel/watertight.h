#pragma once
/// The scalar watertight ray/triangle test (internal to the accel module). Every SIMD kernel
/// does exactly these float operations in this order, lane by lane, so that all paths give the
/// same t bit for bit; exact zeros of the edge functions go back to this code (double).
///
/// Internal linkage on purpose: the AVX2 kernels include it too, compiled for another target,
/// and the copies must not be merged by the linker.

#include <cmath>
#include <limits>
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
    float sx, sy, sz;  // sz = 1 / dir[kz]
    float ix, iy;      // 1 / dir[kx], 1 / dir[ky]
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
        ix = 1.0f / dir[kx];
        iy = 1.0f / dir[ky];
    }
};

// The min and max of the SIMD kernels (minps, maxps): the first operand when it compares less
// (greater), else the second (so the second when either is NaN). Written as compares, every
// build picks the same value.
inline float lane_min(float a, float b) { return a < b ? a : b; }
inline float lane_max(float a, float b) { return a > b ? a : b; }

// Where the ray enters the triangle's bounding box, as the box tests find a box's entry: per
// axis the corner nearest along the ray (the lowest, or the highest when the inverse direction's
// sign bit is set, so that -0 counts as negative as -inf does) times the inverse direction, and
// the farthest of those and 0. A NaN (a corner in the plane of a direction component that is
// zero: 0 * inf) is ignored, as the box tests ignore it. `p` holds the corners relative to the
// origin in the ray's kx, ky, kz order, `inv` the inverse direction in that order. The
// single-ray kernels do the same operations; a regular tile group takes the least product over
// the corners per axis, the same value for every lane that can be a hit (group_box_entry in
// kernels.inl).
inline float box_entry(const float (&p)[3][3], const float (&inv)[3]) {
    float entry = 0.0f;
    for (int axis = 0; axis < 3; ++axis) {
        const float lo = lane_min(lane_min(p[0][axis], p[1][axis]), p[2][axis]);
        const float hi = lane_max(lane_max(p[0][axis], p[1][axis]), p[2][axis]);
        entry = lane_max((std::signbit(inv[axis]) ? hi : lo) * inv[axis], entry);
    }
    return entry;
}

// A hit's t is raised to the ray's entry into the triangle's box, less this fraction. The
// traversal culls a box that the ray enters beyond the best t (widened by kBoxSlack), which is
// only safe if no triangle's t lies before its box. For a triangle seen almost edge-on, far
// away, the computed t can: its error grows with the triangle's depth along the ray, and two
// traversals then disagreed on a tie (one culled the box of the lower index). With t held to
// its box, every box holding a hit at the best t is entered within kBoxSlack of it (the box
// tests round no more than this slack and kBoxSlack allow). Well-conditioned hits lie well
// within it and keep their t.
inline constexpr float kEntrySlack = 1.0f - 1.0f / (1 << 21);

// Whether the triangle's box lies wholly behind the ray's origin along some axis: its far side
// there (the highest corner, or the lowest when the inverse direction's sign bit is set) is on
// the origin's near side. Along an axis the ray does not move on (a zero direction component:
// an infinite inverse), either side of the origin will do. Then no point of the triangle is at
// t >= 0, and the box tests find the box's exit before 0 (or its entry at infinity) and cull
// it; a positive t from the watertight test is its rounding (an origin within an ulp or so of
// the triangle's plane, the ray leaving it). The corners are differences of floats, whose signs
// are exact, so this is decided exactly, the same way on every path.
inline bool box_behind(const float (&p)[3][3], const float (&inv)[3]) {
    for (int axis = 0; axis < 3; ++axis) {
        const float lo = lane_min(lane_min(p[0][axis], p[1][axis]), p[2][axis]);
        const float hi = lane_max(lane_max(p[0][axis], p[1][axis]), p[2][axis]);
        if (std::isinf(inv[axis])) {
            if (lo > 0.0f || hi < 0.0f) return true;
        } else if (std::signbit(inv[axis]) ? lo > 0.0f : hi < 0.0f) {
            return true;
        }
    }
    return false;
}

// t held to the triangle's box: at least box_entry(p, inv) * kEntrySlack, and NaN (no hit:
// every comparison with it fails) when the box is behind the origin (box_behind). Either only
// raises t or refuses it, so a lane refused by its t before is refused after.
inline float held_to_box(float t, const float (&p)[3][3], const float (&inv)[3]) {
    if (box_behind(p, inv)) return std::numeric_limits<float>::quiet_NaN();
    const float bound = box_entry(p, inv) * kEntrySlack;
    return t < bound ? bound : t;
}

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
    if (!(t > 0.0f)) return false;
    const float corners[3][3] = {
        {a[r.kx], a[r.ky], a[r.kz]}, {b[r.kx], b[r.ky], b[r.kz]}, {c[r.kx], c[r.ky], c[r.kz]}};
    const float inv_dir[3] = {r.ix, r.iy, r.sz};
    t = held_to_box(t, corners, inv_dir);
    return t <= tmax;
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
