#include "toonray/scene/scene.h"

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
    tri_positions.clear();
    tri_normals.clear();
    tri_texcoords.clear();
    tri_material.clear();
    tri_object.clear();
    materials.assign(1, Material{"(default)"});
    objects.assign(1, "(default)");
    camera.reset();
}

}  // namespace toonray
