#include "toonray/frame/animation_accel.h"

namespace toonray {

const TriangleAccel& AnimationAccel::update(const Scene& scene, const Bvh::Config& config) {
    const bool same_triangles = valid_ && config == config_ && scene.tri_positions == triangles_;
    if (same_triangles && refits_in_a_row_ < kMaxRefitsInARow) {
        accel_.refit(scene.positions, scene.tri_positions);
        ++refits_in_a_row_;
        return accel_;
    }
    valid_ = false;  // stays false if the build throws
    accel_.build(scene.positions, scene.tri_positions, config);
    triangles_ = scene.tri_positions;
    config_ = config;
    refits_in_a_row_ = 0;
    valid_ = true;
    return accel_;
}

}  // namespace toonray
