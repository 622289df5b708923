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

/// The closest hit of a ray. Among hits at the same distance the accelerator's own triangles
/// come first, then instances by index, and within either the lowest triangle index: the
/// result is the lowest (t, instance + 1, prim), whatever the tree, the thread count or the
/// CPU.
struct Hit {
    float t = std::numeric_limits<float>::infinity();
    std::uint32_t prim = kNoIndex;  ///< triangle index in the input order (of its mesh)
    float u = 0, v = 0;             ///< barycentrics of corners 1 and 2
    /// The instance whose mesh's triangle `prim` is (TriangleAccel::set_instances), or
    /// kNoIndex for the accelerator's own triangles.
    std::uint32_t instance = kNoIndex;

    [[nodiscard]] bool valid() const { return prim != kNoIndex; }
};

}  // namespace toonray
