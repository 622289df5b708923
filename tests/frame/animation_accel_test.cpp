// The BVH an animation keeps across frames, with instances: each distinct mesh's tree is built
// once while frames use the same mesh object, moving instances only rebuilds the top level,
// and the hits are always those of an accelerator built afresh for the frame.

#include <gtest/gtest.h>

#include <bit>
#include <vector>

#include "toonray/accel/scene_accel.h"
#include "toonray/frame/animation_accel.h"
#include "support/instance_scenes.h"

using namespace toonray;

namespace {

// The hits of a fan of rays from above through both accelerators: equal bit for bit.
void expect_same_hits(const TriangleAccel& a, const TriangleAccel& b) {
    int hits = 0;
    for (int y = 0; y < 40; ++y)
        for (int x = 0; x < 40; ++x) {
            const Ray ray{Vec3f(0, 20, 0),
                          Vec3f(float(x - 20) * 0.03f, -1.0f, float(y - 20) * 0.03f)};
            Hit ha, hb;
            const bool fa = a.intersect(ray, ha), fb = b.intersect(ray, hb);
            ASSERT_EQ(fa, fb);
            if (!fa) continue;
            ++hits;
            EXPECT_EQ(std::bit_cast<std::uint32_t>(ha.t), std::bit_cast<std::uint32_t>(hb.t));
            EXPECT_EQ(ha.prim, hb.prim);
            EXPECT_EQ(ha.instance, hb.instance);
        }
    EXPECT_GT(hits, 1000);
}

TEST(AnimationAccelInstances, MeshTreesAreKeptWhileTheMeshesAreTheSame) {
    Scene scene = test_support::instanced_test_scene();
    AnimationAccel animation;
    for (int frame = 0; frame < 5; ++frame) {
        for (Instance& instance : scene.instances) instance.to_world.m[1][3] += 0.05;
        const TriangleAccel& accel = animation.update(scene, {});
        EXPECT_EQ(animation.mesh_builds(), 2u);  // the teapot and the sphere, once
        expect_same_hits(accel, build_scene_accel(scene));
    }
    // A new mesh object (even with the same triangles) is a new mesh; an instance less is a
    // new list of instances.
    scene.meshes[1] = std::make_shared<TriangleMesh>(*scene.meshes[1]);
    scene.instances.pop_back();
    const TriangleAccel& accel = animation.update(scene, {});
    EXPECT_EQ(animation.mesh_builds(), 3u);
    expect_same_hits(accel, build_scene_accel(scene));
    // Without instances the accelerator has none left.
    scene.instances.clear();
    scene.meshes.clear();
    EXPECT_EQ(animation.update(scene, {}).instance_count(), 0u);
}

}  // namespace
