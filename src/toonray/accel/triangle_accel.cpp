#include "toonray/accel/triangle_accel.h"

#include <algorithm>

namespace toonray {
namespace {

inline bool mt_test(const Vec3f& org, const Vec3f& dir, const Vec3f& v0, const Vec3f& e1,
                    const Vec3f& e2, float tmax, float& t, float& u, float& v) {
    Vec3f p = cross(dir, e2);
    float det = dot(e1, p);
    if (det == 0.0f) return false;
    float inv = 1.0f / det;
    Vec3f s = org - v0;
    u = dot(s, p) * inv;
    if (u < 0.0f || u > 1.0f) return false;
    Vec3f q = cross(s, e1);
    v = dot(dir, q) * inv;
    if (v < 0.0f || u + v > 1.0f) return false;
    t = dot(e2, q) * inv;
    return t > 0.0f && t <= tmax;
}

// Slab test; returns the entry distance or +inf for a miss.
inline float box_entry(const BBox& b, const Vec3f& org, const Vec3f& inv_dir, float tmax) {
    float tx0 = (b.lo.x - org.x) * inv_dir.x, tx1 = (b.hi.x - org.x) * inv_dir.x;
    float ty0 = (b.lo.y - org.y) * inv_dir.y, ty1 = (b.hi.y - org.y) * inv_dir.y;
    float tz0 = (b.lo.z - org.z) * inv_dir.z, tz1 = (b.hi.z - org.z) * inv_dir.z;
    float tnear = std::max({std::min(tx0, tx1), std::min(ty0, ty1), std::min(tz0, tz1), 0.0f});
    float tfar = std::min({std::max(tx0, tx1), std::max(ty0, ty1), std::max(tz0, tz1), tmax});
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
    return mt_test(ray.origin, ray.dir, v0, v1 - v0, v2 - v0, ray.tmax, t, u, v) && t < ray.tmax;
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
        const Vec3f& v0 = positions[tri[0]];
        tris_[i] = {v0, positions[tri[1]] - v0, positions[tri[2]] - v0};
    }
}

template <typename Stack>
bool TriangleAccel::traverse(const Ray& ray, Hit& hit, Stack& stack) const {
    const Vec3f inv_dir(1.0f / ray.dir.x, 1.0f / ray.dir.y, 1.0f / ray.dir.z);
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
                if (mt_test(ray.origin, ray.dir, tri.v0, tri.e1, tri.e2, tmax, t, u, v) &&
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
