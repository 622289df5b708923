#pragma once
/// The BVH of an animation's scenes, refitted while the triangles stay the same.

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "toonray/accel/triangle_accel.h"
#include "toonray/scene/scene.h"

namespace toonray {

/// An animation's frames usually keep their triangles while vertices move. When a scene has
/// exactly the triangles of the one before (and the same BVH settings), the BVH is refitted
/// instead of rebuilt, at most kMaxRefitsInARow frames in a row: refitting costs a tenth of a
/// build, but the tree loosens as vertices travel, so it is rebuilt now and then. Images do
/// not depend on it: among hits at the same distance the lowest triangle index wins, whatever
/// the tree.
///
/// Instances (Scene::instances): each distinct mesh's tree is built once and kept while frames
/// keep using the same mesh object (meshes are immutable, so the same object means the same
/// triangles); a frame that only moves instances rebuilds the small top level alone
/// (TriangleAccel::move_instances).
class AnimationAccel {
public:
    static constexpr int kMaxRefitsInARow = 15;

    /// The BVH of `scene`, built or refitted. Throws what TriangleAccel::build throws; the next
    /// call then builds.
    const TriangleAccel& update(const Scene& scene, const Bvh::Config& config);

    /// Whether the last update refitted rather than built.
    [[nodiscard]] bool refitted() const { return refits_in_a_row_ > 0; }
    /// How many mesh trees were built for instances so far.
    [[nodiscard]] std::size_t mesh_builds() const { return mesh_builds_; }

private:
    struct MeshEntry {
        std::shared_ptr<const TriangleMesh> mesh;  ///< held: its address stays its identity
        std::shared_ptr<const TriangleAccel> accel;
        Bvh::Config config;
        bool used = false;
    };
    std::shared_ptr<const TriangleAccel> mesh_accel(const std::shared_ptr<const TriangleMesh>& mesh,
                                                    const Bvh::Config& config);
    void update_instances(const Scene& scene, const Bvh::Config& config);

    std::vector<MeshEntry> meshes_;
    std::vector<const TriangleAccel*> instance_meshes_;  ///< the tree of each instance
    Bvh::Config instance_config_;
    std::size_t mesh_builds_ = 0;

    TriangleAccel accel_;
    std::vector<std::array<std::uint32_t, 3>> triangles_;  ///< the triangles accel_ was built for
    Bvh::Config config_;
    int refits_in_a_row_ = 0;
    bool valid_ = false;
};

}  // namespace toonray
