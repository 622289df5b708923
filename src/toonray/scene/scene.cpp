#include "toonray/scene/scene.h"

#include "toonray/core/saturating.h"

#include <limits>

namespace toonray {

BBox Scene::bounds() const {
    BBox box;
    for (const auto& tri : tri_positions)
        for (std::uint32_t v : tri) box.extend(positions[v]);
    return box;
}

void Scene::clear() {
    positions.clear();
    normals.clear();
    texcoords.clear();
    colours.clear();
    tri_positions.clear();
    tri_normals.clear();
    tri_texcoords.clear();
    tri_material.clear();
    tri_object.clear();
    materials.assign(1, Material{"(default)"});
    objects.assign(1, "(default)");
    camera.reset();
    polyline_points.clear();
    polylines.clear();
}

std::uint64_t scene_bytes(std::uint64_t vertices, std::uint64_t triangles) {
    // Per vertex: the position and, at worst, a normal and a texture coordinate. Per triangle:
    // 5 index arrays (44 bytes), the BVH build (boxes, centres, indices, nodes: ~100 bytes),
    // the packed triangles (36 bytes) and the corner list the automatic camera gathers (36
    // bytes). Measured: a 2M-triangle, 1M-vertex grid peaks at 431 MB including its 55 MB of
    // text; this estimates 518 MB.
    return add_saturated(mul_saturated(vertices, 12 + 12 + 8),
                         mul_saturated(triangles, 44 + 100 + 36 + 36));
}

}  // namespace toonray
