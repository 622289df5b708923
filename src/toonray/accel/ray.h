#pragma once
/// A ray and the closest hit on it, as TriangleAccel's queries take and return them.

#include <cstdint>
#include <limits>

#include "toonray/core/index.h"
#include "toonray/core/math.h"

namespace toonray {

struct Ray {
    Vec3f origin;
    Vec3f dir;  ///< need not be unit length; hit distances are in units of |dir|
    float tmax = std::numeric_limits<float>::infinity();
};

struct Hit {
    float t = std::numeric_limits<float>::infinity();
    std::uint32_t prim = kNoIndex;  ///< triangle index in the input order
    float u = 0, v = 0;             ///< barycentrics of corners 1 and 2

    [[nodiscard]] bool valid() const { return prim != kNoIndex; }
};

}  // namespace toonray
