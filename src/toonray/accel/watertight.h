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

// A hit's t is raised to the ray's entry into the triangle's box, less this fraction. The
// traversal culls a box that the ray enters beyond the best t (widened by kBoxSlack), which is
// only safe if no triangle's t lies before its box. For a triangle seen almost edge-on, far
// away, the computed t can: its error grows with the triangle's depth along the ray, and two
// traversals then disagreed on a tie (one culled the box of the lower index). With t held to
// its box, every box holding a hit at the best t is entered within kBoxSlack of it (the box
// tests round no more than this slack and kBoxSlack allow). Well-conditioned hits lie well
// within it and keep their t.
inline constexpr float kEntrySlack = 1.0f - 1.0f / (1 << 21);

// The box tests' slack on the far distance (pbrt's 1 + 2 gamma(3), rounded up): rounding never
// culls a box whose triangle is hit at exactly tmax, so ties reach the triangle test and are
// broken by index.
inline constexpr float kBoxSlack = 1.0f + 1.0f / (1 << 20);

// The fused box test's constants on one axis (the AVX2 and AVX-512 single-ray kernels,
// RayBoxes in kernels.inl): a plane at p is entered at fma(p, inv, near) and left at
// fma(p, inv, far). c = -origin * inv rounds by at most |c| 2^-24, so near and far are c less
// and plus |c| 2^-21, and a few of the smallest denormals, where the relative margin vanishes
// and the roundings do not. (Infinite or NaN terms give NaN, which never culls.)
// The margin's relative and absolute parts, shared with the tile's lane-by-lane copy.
inline constexpr float kFusedMargin = 1.0f / (1 << 21), kFusedFloor = 0x1p-146f;
struct FusedSlab {
    float near, far;
};
inline FusedSlab fused_slab(float origin, float inv) {
    const float c = -(origin * inv);
    const float margin = std::abs(c) * kFusedMargin + kFusedFloor;
    return {c - margin, c + margin};
}

// Whether the fused box test keeps a box that the two-rounding test finds entered at `entry`
// and left at `exit` (the box not behind the origin), without computing it. Per axis the
// fused near distance is at most the exact (q - o) * inv plus 2^-24 of it (the margins of
// fused_slab outweigh the rounding of c) and 2^-145, and the two-rounding one within 2 * 2^-24
// of it and 2^-150 (a subnormal difference q - o is exact): so the fused entry is at most
// entry (1 + 2^-22) + 2^-145, and likewise the fused exit at least exit (1 - 2^-22) - 2^-145.
// With entry <= exit (1 + 2^-22) (a flat box has entry = exit) and exit within [2^-100,
// 2^100], where the absolute terms vanish and nothing overflows, the fused test's kBoxSlack
// (1 + 2^-20) then covers both. An axis the ray does not move on (an infinite inverse) enters
// neither interval unless the box is behind or its entry is infinite; one where c overflows
// only widens the fused interval. The bound assumes finite corners relative to the origin: a
// difference q - o that overflows can leave the interval vouched for while the fused test
// culls the box, but then the watertight test has no hit to hold (its sheared corners are
// infinite or NaN, so its t is NaN). The caller computes the fused test where this fails.
// Its constants are shared with the tile's lane-by-lane copy (group_held_to_box).
inline constexpr float kVouchedExitMin = 0x1p-100f, kVouchedExitMax = 0x1p100f,
                       kVouchedRoom = 1.0f + 0x1p-22f;
inline bool fused_test_keeps(float entry, float exit) {
    return exit >= kVouchedExitMin && exit <= kVouchedExitMax && entry <= exit * kVouchedRoom;
}

// A triangle's box as a box test finds it: where the ray enters and leaves it, and (for the
// two-rounding test) whether it lies behind the origin; see held_to_box.
struct BoxInterval {
    float entry = 0.0f, exit = std::numeric_limits<float>::infinity();
    bool behind = false;
    /// Not culled by the box test, with no hit yet.
    [[nodiscard]] bool kept() const { return entry <= exit * kBoxSlack; }
};

// The two-rounding test's interval of the box of corners `q` for origin `o` and inverse
// direction `inv` (all in the ray's kx, ky, kz order), with "behind" decided from the signs of
// the corners relative to the origin.
inline BoxInterval two_rounding_interval(const float (&q)[3][3], const float (&o)[3],
                                         const float (&inv)[3]) {
    BoxInterval box;
    for (int axis = 0; axis < 3; ++axis) {
        const float p0 = q[0][axis] - o[axis], p1 = q[1][axis] - o[axis], p2 = q[2][axis] - o[axis];
        const float lo = lane_min(lane_min(p0, p1), p2), hi = lane_max(lane_max(p0, p1), p2);
        const bool negative = std::signbit(inv[axis]);
        if (std::isinf(inv[axis])) box.behind = box.behind || lo > 0.0f || hi < 0.0f;
        else box.behind = box.behind || (negative ? lo > 0.0f : hi < 0.0f);
        box.entry = lane_max((negative ? hi : lo) * inv[axis], box.entry);
        box.exit = lane_min((negative ? lo : hi) * inv[axis], box.exit);
    }
    return box;
}

// The fused test's interval of the same box (its `behind` is not computed).
inline BoxInterval fused_interval(const float (&q)[3][3], const float (&o)[3],
                                  const float (&inv)[3]) {
    BoxInterval box;
    for (int axis = 0; axis < 3; ++axis) {
        const bool negative = std::signbit(inv[axis]);
        const float lo = lane_min(lane_min(q[0][axis], q[1][axis]), q[2][axis]);
        const float hi = lane_max(lane_max(q[0][axis], q[1][axis]), q[2][axis]);
        const FusedSlab slab = fused_slab(o[axis], inv[axis]);
        box.entry = lane_max(std::fma(negative ? hi : lo, inv[axis], slab.near), box.entry);
        box.exit = lane_min(std::fma(negative ? lo : hi, inv[axis], slab.far), box.exit);
    }
    return box;
}

// A hit's t held to its triangle's box, or NaN (no hit: every comparison with it fails) when
// the box refuses it. `q` holds the corners, `o` the origin and `inv` the inverse direction,
// all in the ray's kx, ky, kz order. Per axis, with the corners
// relative to the origin p = q - o, the box's near side is its lowest corner (the highest when
// the inverse direction's sign bit is set, so that -0 counts as negative as -inf does).
//
// - Entry: t is raised to at least the ray's entry into the box less kEntrySlack, as the box
//   tests find a box's entry: the farthest of 0 and the near sides' p * inv (a NaN, 0 * inf
//   from a corner in the plane of a zero direction component, is ignored as the box tests
//   ignore it). A regular tile group computes the same per lane (group_held_to_box).
// - Behind: refused when the box lies wholly behind the origin along some axis (its far side
//   on the origin's near side; along an axis the ray does not move on, an infinite inverse,
//   either side). No point of the triangle is then at t >= 0; a positive t from the watertight
//   test is its rounding (an origin within an ulp of the triangle's plane, the ray leaving
//   it). Signs of float differences are exact, so this is decided the same way on every path.
// - Culled: refused when a box test would cull the box with no hit yet: the two-rounding test
//   of the SSE kernels and of the tiles' intervals, p * inv, or the fused test,
//   fma(q, inv, slab), each with kBoxSlack, as the kernels do them. Both tests are monotonic in
//   the box, so a box either culls holds no triangle whose box both keep: whichever test a path
//   runs, it never culls a hit that another path takes. Only a hit whose rounding puts it on a
//   ray that misses its box is refused (the eye within a rounding of a long triangle's edge).
//   The fused test is computed only where fused_test_keeps cannot vouch for it.
//
// Either only raises t or refuses it, so a lane refused by its t before is refused after.
inline float held_to_box(float t, const float (&q)[3][3], const float (&o)[3],
                         const float (&inv)[3]) {
    const BoxInterval box = two_rounding_interval(q, o, inv);
    if (box.behind || !box.kept()) return std::numeric_limits<float>::quiet_NaN();
    if (!fused_test_keeps(box.entry, box.exit) && !fused_interval(q, o, inv).kept())
        return std::numeric_limits<float>::quiet_NaN();
    const float bound = box.entry * kEntrySlack;
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
    const float corners[3][3] = {{v0[r.kx], v0[r.ky], v0[r.kz]},
                                 {v1[r.kx], v1[r.ky], v1[r.kz]},
                                 {v2[r.kx], v2[r.ky], v2[r.kz]}};
    const float origin[3] = {r.origin[r.kx], r.origin[r.ky], r.origin[r.kz]};
    const float inv_dir[3] = {r.ix, r.iy, r.sz};
    t = held_to_box(t, corners, origin, inv_dir);
    return t <= tmax;
}

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
