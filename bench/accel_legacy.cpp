#include "accel_legacy.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>

namespace toonray::legacy {

namespace {

struct Builder {
    std::span<const BBox> boxes;
    std::span<const Vec3f> centers;
    const Bvh::Config& config;
    Bvh& bvh;

    static constexpr int kMaxBins = 64;

    struct Bin {
        BBox box;
        std::uint32_t count = 0;
    };

    BBox range_bounds(std::uint32_t first, std::uint32_t count, BBox* centroid_bounds) const {
        BBox box, cbox;
        for (std::uint32_t i = first; i < first + count; ++i) {
            std::uint32_t p = bvh.prim_indices[i];
            box.extend(boxes[p]);
            cbox.extend(centers[p]);
        }
        *centroid_bounds = cbox;
        return box;
    }

    // Finds the cheapest binned SAH split. Returns false when no split beats a leaf (and the
    // leaf is allowed), or all centroids coincide.
    bool find_split(const BvhNode& node, const BBox& cbox, int& best_axis, float& best_pos,
                    float& best_cost) const {
        const int bins = std::clamp(config.bin_count, 2, kMaxBins);
        best_cost = std::numeric_limits<float>::infinity();
        best_axis = -1;
        std::array<Bin, kMaxBins> bin;
        std::array<float, kMaxBins> right_area;
        std::array<std::uint32_t, kMaxBins> right_count;
        for (int axis = 0; axis < 3; ++axis) {
            float lo = cbox.lo[axis], hi = cbox.hi[axis];
            if (!(hi > lo)) continue;
            float scale = bins / (hi - lo);
            std::fill(bin.begin(), bin.begin() + bins, Bin{});
            for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
                std::uint32_t p = bvh.prim_indices[i];
                int b = std::min(bins - 1, static_cast<int>((centers[p][axis] - lo) * scale));
                bin[b].box.extend(boxes[p]);
                bin[b].count++;
            }
            // Sweep from the right to get the cost of each right side, then from the left.
            BBox acc;
            std::uint32_t n = 0;
            for (int b = bins - 1; b > 0; --b) {
                acc.extend(bin[b].box);
                n += bin[b].count;
                right_area[b] = acc.empty() ? 0.0f : acc.half_area();
                right_count[b] = n;
            }
            acc = BBox{};
            n = 0;
            for (int b = 0; b < bins - 1; ++b) {
                acc.extend(bin[b].box);
                n += bin[b].count;
                if (n == 0 || right_count[b + 1] == 0) continue;
                float cost = acc.half_area() * n + right_area[b + 1] * right_count[b + 1];
                if (cost < best_cost) {
                    best_cost = cost;
                    best_axis = axis;
                    best_pos = lo + (b + 1) / scale;
                }
            }
        }
        return best_axis >= 0;
    }

    // Builds the subtree at `index`, iteratively: a degenerate mesh could otherwise recurse
    // as deep as it has triangles.
    void build(std::uint32_t root) {
        std::vector<std::uint32_t> todo{root};
        while (!todo.empty()) {
            std::uint32_t index = todo.back();
            todo.pop_back();
            if (split_node(index)) {
                std::uint32_t left = bvh.nodes[index].first;
                todo.push_back(left + 1);
                todo.push_back(left);
            }
        }
    }

    // Computes the node's bounds and splits it into two new children when that pays.
    // Returns true when it split.
    bool split_node(std::uint32_t index) {
        BvhNode& node = bvh.nodes[index];
        BBox cbox;
        node.bounds = range_bounds(node.first, node.count, &cbox);
        if (node.count <= 1) return false;

        int axis;
        float pos, split_cost;
        bool found = find_split(node, cbox, axis, pos, split_cost);
        const float leaf_cost = config.intersection_cost * node.count;
        std::uint32_t mid;
        if (found) {
            float cost = config.traversal_cost +
                         config.intersection_cost * split_cost / node.bounds.half_area();
            if (cost >= leaf_cost && node.count <= static_cast<std::uint32_t>(config.max_leaf_size))
                return false;
            auto begin = bvh.prim_indices.begin() + node.first;
            auto it = std::partition(begin, begin + node.count,
                                     [&](std::uint32_t p) { return centers[p][axis] < pos; });
            mid = static_cast<std::uint32_t>(it - bvh.prim_indices.begin());
            if (mid == node.first || mid == node.first + node.count)
                mid = node.first + node.count / 2;  // float edge case: fall back to a median cut
        } else {
            if (node.count <= static_cast<std::uint32_t>(config.max_leaf_size)) return false;
            mid = node.first + node.count / 2;  // identical centroids: split the list in two
        }

        std::uint32_t left = static_cast<std::uint32_t>(bvh.nodes.size());
        std::uint32_t first = node.first, count = node.count;
        bvh.nodes.emplace_back();
        bvh.nodes.emplace_back();
        // `node` may dangle after emplace_back: index again.
        bvh.nodes[left] = BvhNode{BBox{}, first, mid - first};
        bvh.nodes[left + 1] = BvhNode{BBox{}, mid, first + count - mid};
        bvh.nodes[index].first = left;
        bvh.nodes[index].count = 0;
        return true;
    }
};

}  // namespace

Bvh Bvh::build(std::span<const BBox> boxes, std::span<const Vec3f> centers, const Config& config) {
    Bvh bvh;
    const auto n = static_cast<std::uint32_t>(boxes.size());
    if (n == 0) return bvh;  // no nodes at all: a zero-count node would read as an inner node
    bvh.prim_indices.resize(n);
    std::iota(bvh.prim_indices.begin(), bvh.prim_indices.end(), 0u);
    bvh.nodes.reserve(2 * n);
    bvh.nodes.push_back(BvhNode{BBox{}, 0, n});
    Builder builder{boxes, centers, config, bvh};
    builder.build(0);
    bvh.nodes.shrink_to_fit();
    return bvh;
}

void Bvh::refit(std::span<const BBox> boxes) {
    // Children always have larger indices than their parent, so a reverse sweep sees children first.
    for (std::size_t i = nodes.size(); i-- > 0;) {
        BvhNode& node = nodes[i];
        BBox box;
        if (node.is_leaf()) {
            for (std::uint32_t k = node.first; k < node.first + node.count; ++k)
                box.extend(boxes[prim_indices[k]]);
        } else {
            box = nodes[node.first].bounds;
            box.extend(nodes[node.first + 1].bounds);
        }
        node.bounds = box;
    }
}

int Bvh::depth() const {
    if (nodes.empty()) return 0;
    std::vector<std::pair<std::uint32_t, int>> stack{{0u, 1}};
    int deepest = 0;
    while (!stack.empty()) {
        auto [i, d] = stack.back();
        stack.pop_back();
        deepest = std::max(deepest, d);
        if (!nodes[i].is_leaf()) {
            stack.push_back({nodes[i].first, d + 1});
            stack.push_back({nodes[i].first + 1, d + 1});
        }
    }
    return deepest;
}

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
    if ((e0 < 0.0f || e1 < 0.0f || e2 < 0.0f) && (e0 > 0.0f || e1 > 0.0f || e2 > 0.0f))
        return false;
    const float det = e0 + e1 + e2;
    if (det == 0.0f) return false;
    const float az = r.sz * a[r.kz], bz = r.sz * b[r.kz], cz = r.sz * c[r.kz];
    const float scaled_t = e0 * az + e1 * bz + e2 * cz;
    // Reject most misses before the division, on scaled values with some slack (rounding of
    // tmax * det must not reject a hit at exactly tmax); the exact test is on t below.
    const float bound = tmax * det * (1.0f + 1.0f / (1 << 20));
    if (det > 0.0f ? (scaled_t <= 0.0f || scaled_t > bound)
                   : (scaled_t >= 0.0f || scaled_t < bound))
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
    float tfar =
        std::min({std::max(tx0, tx1), std::max(ty0, ty1), std::max(tz0, tz1), tmax}) * kWiden;
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
    std::uint32_t pop() {
        std::uint32_t v = items.back();
        items.pop_back();
        return v;
    }
    bool empty() const { return items.empty(); }
};

}  // namespace

void TriangleAccel::build(std::span<const Vec3f> positions,
                          std::span<const std::array<std::uint32_t, 3>> tris,
                          const Bvh::Config& config) {
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
    if (box_entry(nodes[0].bounds, ray.origin, inv_dir, tmax) ==
        std::numeric_limits<float>::infinity())
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

}  // namespace toonray::legacy
