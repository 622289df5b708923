#pragma once
/// Axis-aligned bounding box.

#include <limits>

#include "toonray/core/math.h"

namespace toonray {

struct BBox {
    Vec3f lo{std::numeric_limits<float>::infinity()};
    Vec3f hi{-std::numeric_limits<float>::infinity()};

    void extend(const Vec3f& p) {
        lo = min(lo, p);
        hi = max(hi, p);
    }
    void extend(const BBox& b) {
        lo = min(lo, b.lo);
        hi = max(hi, b.hi);
    }
    [[nodiscard]] bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
    [[nodiscard]] Vec3f extent() const { return hi - lo; }
    [[nodiscard]] Vec3f center() const { return (lo + hi) * 0.5f; }
    [[nodiscard]] float half_area() const {
        Vec3f e = extent();
        return e.x * e.y + e.y * e.z + e.z * e.x;
    }
    [[nodiscard]] int largest_axis() const {
        Vec3f e = extent();
        return e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
    }
};

}  // namespace toonray
