#include "toonray/frame/animation_accel.h"

#include <algorithm>

namespace toonray {

std::shared_ptr<const TriangleAccel> AnimationAccel::mesh_accel(
    const std::shared_ptr<const TriangleMesh>& mesh, const Bvh::Config& config) {
    for (MeshEntry& entry : meshes_)
        if (entry.mesh == mesh && entry.config == config) {
            entry.used = true;
            return entry.accel;
        }
    auto accel = std::make_shared<TriangleAccel>();
    accel->build(mesh->positions, mesh->tri_positions, config);
    meshes_.push_back({mesh, accel, config, true});
    ++mesh_builds_;
    return accel;
}

const TriangleAccel& AnimationAccel::update(const Scene& scene, const Bvh::Config& config) {
    const bool same_triangles = valid_ && config == config_ && scene.tri_positions == triangles_;
    if (same_triangles && refits_in_a_row_ < kMaxRefitsInARow) {
        accel_.refit(scene.positions, scene.tri_positions);
        ++refits_in_a_row_;
    } else {
        valid_ = false;  // stays false if the build throws
        accel_.build(scene.positions, scene.tri_positions, config);
        triangles_ = scene.tri_positions;
        config_ = config;
        refits_in_a_row_ = 0;
        valid_ = true;
    }
    update_instances(scene, config);
    return accel_;
}

void AnimationAccel::update_instances(const Scene& scene, const Bvh::Config& config) {
    if (scene.instances.empty()) {
        if (accel_.instance_count() != 0) accel_.set_instances({});
        instance_meshes_.clear();
        meshes_.clear();
        return;
    }
    for (MeshEntry& entry : meshes_) entry.used = false;
    std::vector<std::shared_ptr<const TriangleAccel>> by_mesh(scene.meshes.size());
    std::vector<const TriangleAccel*> instance_meshes;
    instance_meshes.reserve(scene.instances.size());
    std::vector<AccelInstance> instances;
    instances.reserve(scene.instances.size());
    for (const Instance& instance : scene.instances) {
        auto& accel = by_mesh[instance.mesh];
        if (!accel) accel = mesh_accel(scene.meshes[instance.mesh], config);
        instances.push_back({accel, instance.to_world});
        instance_meshes.push_back(accel.get());
    }
    // Meshes no instance uses any more are let go.
    std::erase_if(meshes_, [](const MeshEntry& e) { return !e.used; });
    if (instance_meshes == instance_meshes_ && accel_.instance_count() == instances.size() &&
        config == instance_config_) {
        std::vector<Affine3> to_world;
        to_world.reserve(instances.size());
        for (const AccelInstance& i : instances) to_world.push_back(i.to_world);
        accel_.move_instances(to_world);
        return;
    }
    instance_meshes_.clear();  // stays empty if set_instances throws
    accel_.set_instances(instances, config);
    instance_meshes_ = std::move(instance_meshes);
    instance_config_ = config;
}

}  // namespace toonray
