#include "toonray/accel/bvh.h"

#include <algorithm>
#include <array>
#include <limits>
#include <numeric>

namespace toonray {
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

}  // namespace toonray
