#include "toonray/accel/triangle_accel.h"

#include <algorithm>

namespace toonray {
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

    explicit ShearedRay(const Ray& ray) : origin(ray.origin) {
        float ax = std::abs(ray.dir.x), ay = std::abs(ray.dir.y), az = std::abs(ray.dir.z);
        kz = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
        kx = (kz + 1) % 3;
        ky = (kx + 1) % 3;
        if (ray.dir[kz] < 0.0f) std::swap(kx, ky);  // keep the winding
        sx = ray.dir[kx] / ray.dir[kz];
        sy = ray.dir[ky] / ray.dir[kz];
        sz = 1.0f / ray.dir[kz];
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
    if ((e0 < 0.0f || e1 < 0.0f || e2 < 0.0f) && (e0 > 0.0f || e1 > 0.0f || e2 > 0.0f)) return false;
    const float det = e0 + e1 + e2;
    if (det == 0.0f) return false;
    const float az = r.sz * a[r.kz], bz = r.sz * b[r.kz], cz = r.sz * c[r.kz];
    const float scaled_t = e0 * az + e1 * bz + e2 * cz;
    // Reject most misses before the division, on scaled values with some slack (rounding of
    // tmax * det must not reject a hit at exactly tmax); the exact test is on t below.
    const float bound = tmax * det * (1.0f + 1.0f / (1 << 20));
    if (det > 0.0f ? (scaled_t <= 0.0f || scaled_t > bound) : (scaled_t >= 0.0f || scaled_t < bound))
        return false;
    const float inv = 1.0f / det;
    t = scaled_t * inv;
    u = e1 * inv;
    v = e2 * inv;
    return t > 0.0f && t <= tmax;
}

// Slab test; returns the entry distance or +inf for a miss. The far distance is widened by a
// few ulps (pbrt's 1 + 2 gamma(3), rounded up) so that rounding never culls a box whose
// triangle is hit at exactly tmax: ties must reach the triangle test to be broken by index.
inline float box_entry(const BBox& b, const Vec3f& org, const Vec3f& inv_dir, float tmax) {
    constexpr float kWiden = 1.0f + 1.0f / (1 << 20);
    float tx0 = (b.lo.x - org.x) * inv_dir.x, tx1 = (b.hi.x - org.x) * inv_dir.x;
    float ty0 = (b.lo.y - org.y) * inv_dir.y, ty1 = (b.hi.y - org.y) * inv_dir.y;
    float tz0 = (b.lo.z - org.z) * inv_dir.z, tz1 = (b.hi.z - org.z) * inv_dir.z;
    float tnear = std::max({std::min(tx0, tx1), std::min(ty0, ty1), std::min(tz0, tz1), 0.0f});
    float tfar = std::min({std::max(tx0, tx1), std::max(ty0, ty1), std::max(tz0, tz1), tmax}) * kWiden;
    return tnear <= tfar ? tnear : std::numeric_limits<float>::infinity();
}

template <int N>
struct FixedStack {
    std::uint32_t items[N];
    int size = 0;
    void push(std::uint32_t v) { items[size++] = v; }
    std::uint32_t pop() { return items[--size]; }
    bool empty() const { return size == 0; }
};

struct HeapStack {
    std::vector<std::uint32_t> items;
    void push(std::uint32_t v) { items.push_back(v); }
    std::uint32_t pop() { std::uint32_t v = items.back(); items.pop_back(); return v; }
    bool empty() const { return items.empty(); }
};

}  // namespace

bool intersect_triangle(const Ray& ray, const Vec3f& v0, const Vec3f& v1, const Vec3f& v2,
                        float& t, float& u, float& v) {
    return watertight_test(ShearedRay(ray), v0, v1, v2, ray.tmax, t, u, v) && t < ray.tmax;
}

void TriangleAccel::build(std::span<const Vec3f> positions,
                          std::span<const std::array<std::uint32_t, 3>> tris, const Bvh::Config& config) {
    std::vector<BBox> boxes(tris.size());
    std::vector<Vec3f> centers(tris.size());
    for (std::size_t i = 0; i < tris.size(); ++i) {
        BBox b;
        for (std::uint32_t v : tris[i]) b.extend(positions[v]);
        boxes[i] = b;
        centers[i] = b.center();
    }
    bvh_ = Bvh::build(boxes, centers, config);
    depth_ = bvh_.depth();
    pack(positions, tris);
}

void TriangleAccel::refit(std::span<const Vec3f> positions,
                          std::span<const std::array<std::uint32_t, 3>> tris) {
    std::vector<BBox> boxes(tris.size());
    for (std::size_t i = 0; i < tris.size(); ++i)
        for (std::uint32_t v : tris[i]) boxes[i].extend(positions[v]);
    bvh_.refit(boxes);
    pack(positions, tris);
}

void TriangleAccel::pack(std::span<const Vec3f> positions,
                         std::span<const std::array<std::uint32_t, 3>> tris) {
    tris_.resize(tris.size());
    for (std::size_t i = 0; i < bvh_.prim_indices.size(); ++i) {
        const auto& tri = tris[bvh_.prim_indices[i]];
        tris_[i] = {positions[tri[0]], positions[tri[1]], positions[tri[2]]};
    }
}

template <typename Stack>
bool TriangleAccel::traverse(const Ray& ray, Hit& hit, Stack& stack) const {
    const Vec3f inv_dir(1.0f / ray.dir.x, 1.0f / ray.dir.y, 1.0f / ray.dir.z);
    const ShearedRay sheared(ray);
    float tmax = ray.tmax;
    std::uint32_t best = 0xffffffffu, best_prim = 0xffffffffu;
    const BvhNode* nodes = bvh_.nodes.data();
    if (box_entry(nodes[0].bounds, ray.origin, inv_dir, tmax) == std::numeric_limits<float>::infinity())
        return false;
    stack.push(0);
    while (!stack.empty()) {
        const BvhNode& node = nodes[stack.pop()];
        if (node.is_leaf()) {
            for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
                const PackedTriangle& tri = tris_[i];
                float t, u, v;
                // Accept t == tmax too, and break the tie by the lower input index: the hit
                // then does not depend on the tree's shape, so a refitted BVH and a fresh one
                // give the same image.
                if (watertight_test(sheared, tri.v0, tri.v1, tri.v2, tmax, t, u, v) &&
                    (t < tmax || (best_prim != 0xffffffffu && bvh_.prim_indices[i] < best_prim))) {
                    tmax = t;
                    best = i;
                    best_prim = bvh_.prim_indices[i];
                    hit.u = u;
                    hit.v = v;
                }
            }
            continue;
        }
        // Visit the nearer child first; push the farther one only if it is hit.
        float t_left = box_entry(nodes[node.first].bounds, ray.origin, inv_dir, tmax);
        float t_right = box_entry(nodes[node.first + 1].bounds, ray.origin, inv_dir, tmax);
        std::uint32_t near = node.first, far = node.first + 1;
        if (t_right < t_left) {
            std::swap(t_left, t_right);
            std::swap(near, far);
        }
        if (t_right != std::numeric_limits<float>::infinity()) stack.push(far);
        if (t_left != std::numeric_limits<float>::infinity()) stack.push(near);
    }
    if (best == 0xffffffffu) return false;
    hit.t = tmax;
    hit.prim = bvh_.prim_indices[best];
    return true;
}

bool TriangleAccel::intersect(const Ray& ray, Hit& hit) const {
    if (tris_.empty()) return false;
    // A binary tree needs at most one pending sibling per level.
    if (depth_ <= 64) {
        FixedStack<64> stack;
        return traverse(ray, hit, stack);
    }
    HeapStack stack;
    return traverse(ray, hit, stack);
}

}  // namespace toonray
