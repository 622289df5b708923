// Instances in scenes: the Scene API a binding fills (meshes, instances, flattening, bounds,
// memory).

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/scene/scene.h"

using namespace toonray;

namespace {

// A unit quad (two triangles) with normals, texture coordinates and material 1.
std::shared_ptr<TriangleMesh> quad_mesh() {
    auto m = std::make_shared<TriangleMesh>();
    m->positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    m->normals = {{0, 0, 2}};
    m->texcoords = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    m->add_triangle({0, 1, 2}, 1, 0, {0, 0, 0}, {0, 1, 2});
    m->add_triangle({0, 2, 3}, 1, 0, {0, 0, 0}, {0, 2, 3});
    return m;
}

Affine3 turned_and_moved() {
    Affine3 a;
    a.m = {{{0, -2, 0, 5}, {1, 0, 0, -1}, {0, 0, 3, 0.5}}};  // x -> y, y -> -2x, z * 3
    return a;
}

TEST(SceneInstances, FlattenPlacesEachInstanceAsItsObject) {
    Scene scene;
    scene.materials.emplace_back("paint");
    scene.positions = {{9, 9, 9}, {9, 10, 9}, {10, 9, 9}};
    scene.add_triangle({0, 1, 2}, 0, 0);
    const std::uint32_t m = scene.add_mesh(quad_mesh());
    EXPECT_EQ(scene.add_instance(m, Affine3{}, "left"), 0u);
    EXPECT_EQ(scene.add_instance(m, turned_and_moved(), "right"), 1u);
    ASSERT_EQ(scene.objects.size(), 3u);
    EXPECT_EQ(scene.objects[2], "right");
    EXPECT_EQ(scene.instanced_triangle_count(), 4u);
    EXPECT_EQ(scene.stored_triangle_count(), 3u);

    const Scene flat = flatten_instances(scene);
    EXPECT_TRUE(flat.instances.empty());
    EXPECT_TRUE(flat.meshes.empty());
    ASSERT_EQ(flat.triangle_count(), 5u);
    // The second instance's first triangle: object "right", material 1, positions by point().
    EXPECT_EQ(flat.tri_object[3], 2u);
    EXPECT_EQ(flat.tri_material[3], 1u);
    const auto& t = flat.tri_positions[3];
    EXPECT_EQ(flat.positions[t[1]], Vec3f(5, 0, 0.5f));  // (1, 0, 0) -> (5, 0, 0.5)
    EXPECT_EQ(flat.positions[t[2]], Vec3f(3, 0, 0.5f));  // (1, 1, 0)
    // Normals by the cofactor matrix, unit length: (0, 0, 2) stays along z.
    EXPECT_EQ(flat.normals[flat.tri_normals[3][0]], Vec3f(0, 0, 1));
    EXPECT_EQ(flat.texcoords[flat.tri_texcoords[3][1]].x, 1.0f);
    // Bounds take the instances' boxes.
    const BBox b = scene.bounds();
    EXPECT_EQ(b.lo, Vec3f(0, -1, 0));
    EXPECT_EQ(b.hi, Vec3f(10, 10, 9));
}

TEST(SceneInstances, BadMeshesAndTransformsAreRefused) {
    Scene scene;
    auto bad = quad_mesh();
    bad->tri_positions[1][2] = 7;  // no position 7
    EXPECT_THROW(scene.add_mesh(bad), Error);
    auto no_material = quad_mesh();  // material 1 does not exist in this scene
    EXPECT_THROW(scene.add_mesh(no_material), Error);
    scene.materials.emplace_back("paint");
    const std::uint32_t m = scene.add_mesh(quad_mesh());
    Affine3 flat;
    flat.m[1] = {0, 0, 0, 0};
    EXPECT_THROW(scene.add_instance(m, flat, "flat"), Error);
    EXPECT_EQ(scene.objects.size(), 1u);  // the refused instance's object is not kept
    EXPECT_THROW(scene.add_instance(m + 1, Affine3{}, "nothing"), Error);
    EXPECT_NO_THROW(scene.add_instance(m, Affine3{}, "ok"));
}

TEST(SceneInstances, ColoursAreWhiteWhereAMeshHasNone) {
    Scene scene;
    scene.materials.emplace_back("paint");
    auto coloured = quad_mesh();
    coloured->colours.assign(4, Vec3f(0.5f, 0.25f, 1.0f));
    scene.add_instance(scene.add_mesh(coloured), Affine3{}, "a");
    scene.add_instance(scene.add_mesh(quad_mesh()), Affine3::translation({2, 0, 0}), "b");
    EXPECT_TRUE(scene.has_colours());
    const Scene flat = flatten_instances(scene);
    ASSERT_EQ(flat.colours.size(), flat.positions.size());
    EXPECT_EQ(flat.colours[0], Vec3f(0.5f, 0.25f, 1.0f));
    EXPECT_EQ(flat.colours.back(), Vec3f(1.0f));
}

TEST(SceneInstances, MemoryCountsWhatIsStored) {
    // 10,000 instances of a 70,000-triangle mesh are a few tens of MB; the same triangles
    // flattened are far beyond any default memory limit.
    const std::uint64_t instanced = scene_bytes(35'000, 70'000, 10'000);
    const std::uint64_t flattened = scene_bytes(350'000'000, 700'000'000);
    EXPECT_LT(instanced, 32ull * 1000 * 1000);
    EXPECT_GT(flattened, 100ull * 1000 * 1000 * 1000);
    EXPECT_GT(scene_bytes(35'000, 70'000, 10'000), scene_bytes(35'000, 70'000, 0));
    Scene scene;
    scene.materials.emplace_back("paint");
    scene.add_instance(scene.add_mesh(quad_mesh()), Affine3{}, "a");
    EXPECT_EQ(scene_bytes(scene), scene_bytes(4, 2, 1));
}

}  // namespace
