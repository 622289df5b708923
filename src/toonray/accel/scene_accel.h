#pragma once
/// The accelerator of a whole scene in one call: its own triangles and its instances (each
/// distinct mesh's tree built once). Renderers that draw several frames keep theirs across
/// frames instead (frame/animation_accel.h).

#include "toonray/accel/triangle_accel.h"
#include "toonray/scene/scene.h"

namespace toonray {

/// A TriangleAccel over `scene`'s own triangles with its instances set (Hit::instance names
/// them, Hit::prim is the triangle in the instance's mesh).
[[nodiscard]] TriangleAccel build_scene_accel(const Scene& scene, const Bvh::Config& config = {});

}  // namespace toonray
