#include "toonray/accel/scene_accel.h"

#include <memory>
#include <vector>

namespace toonray {

TriangleAccel build_scene_accel(const Scene& scene, const Bvh::Config& config) {
    TriangleAccel accel;
    accel.build(scene.positions, scene.tri_positions, config);
    if (scene.instances.empty()) return accel;
    std::vector<std::shared_ptr<const TriangleAccel>> meshes(scene.meshes.size());
    std::vector<AccelInstance> instances;
    instances.reserve(scene.instances.size());
    for (const Instance& instance : scene.instances) {
        auto& mesh = meshes[instance.mesh];
        if (!mesh) {
            auto built = std::make_shared<TriangleAccel>();
            built->build(scene.meshes[instance.mesh]->positions,
                         scene.meshes[instance.mesh]->tri_positions, config);
            mesh = std::move(built);
        }
        instances.push_back({mesh, instance.to_world});
    }
    accel.set_instances(instances, config);
    return accel;
}

}  // namespace toonray
