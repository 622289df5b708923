#pragma once
/// Closest-hit ray queries against a triangle mesh, on top of the generic Bvh.

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "toonray/accel/bvh.h"
#include "toonray/core/math.h"

namespace toonray {

struct Ray {
    Vec3f origin;
    Vec3f dir;  ///< need not be unit length; hit distances are in units of |dir|
    float tmax = std::numeric_limits<float>::infinity();
};

struct Hit {
    float t = std::numeric_limits<float>::infinity();
    std::uint32_t prim = 0xffffffffu;  ///< triangle index in the input order
    float u = 0, v = 0;                ///< barycentrics of corners 1 and 2

    [[nodiscard]] bool valid() const { return prim != 0xffffffffu; }
};

class TriangleAccel {
public:
    /// Builds the BVH over the triangles and copies them in leaf order for traversal.
    void build(std::span<const Vec3f> positions, std::span<const std::array<std::uint32_t, 3>> tris,
               const Bvh::Config& config = {});
    /// Updates for moved vertices with the same triangles (topology kept).
    void refit(std::span<const Vec3f> positions, std::span<const std::array<std::uint32_t, 3>> tris);

    /// Closest hit with 0 < t < ray.tmax. Returns true and fills `hit` when there is one.
    /// Among hits at the same distance the lowest triangle index wins, whatever the tree.
    bool intersect(const Ray& ray, Hit& hit) const;

    [[nodiscard]] const Bvh& bvh() const { return bvh_; }
    [[nodiscard]] std::size_t triangle_count() const { return tris_.size(); }

private:
    struct PackedTriangle {
        Vec3f v0, v1, v2;
    };
    void pack(std::span<const Vec3f> positions, std::span<const std::array<std::uint32_t, 3>> tris);
    template <typename Stack>
    bool traverse(const Ray& ray, Hit& hit, Stack& stack) const;

    Bvh bvh_;
    std::vector<PackedTriangle> tris_;  ///< in bvh_.prim_indices order
    int depth_ = 0;
};

/// The watertight ray/triangle test the traversal uses (Woop et al. 2013): 0 < t < ray.tmax.
/// Exposed for brute-force reference checks in tests.
bool intersect_triangle(const Ray& ray, const Vec3f& v0, const Vec3f& v1, const Vec3f& v2,
                        float& t, float& u, float& v);

}  // namespace toonray
