#include "toonray/scene/scene_arrays.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/core/index.h"

using namespace toonray;

namespace {

Affine3 rows(const std::array<std::array<double, 4>, 3>& m) {
    Affine3 a;
    a.m = m;
    return a;
}

// A unit square in z = 0 as two triangles, wound to face +z.
struct Square {
    std::vector<Vec3f> positions{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    std::vector<std::array<std::uint32_t, 3>> triangles{{0, 1, 2}, {0, 2, 3}};
    std::vector<Vec3f> normals{{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    std::vector<Vec2f> uvs{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    std::vector<std::uint32_t> materials{1, 1};

    [[nodiscard]] MeshArrays arrays() const {
        return {positions, triangles, normals, uvs, materials};
    }
};

Scene with_material() {
    Scene s;
    s.materials.emplace_back("paint");
    return s;
}

Vec3f face_normal(const Scene& s, std::size_t t) {
    const auto& tri = s.tri_positions[t];
    return cross(s.positions[tri[1]] - s.positions[tri[0]],
                 s.positions[tri[2]] - s.positions[tri[0]]);
}

std::string error_of(const Scene& scene, const MeshArrays& mesh) {
    try {
        check_mesh(mesh, scene.materials.size(), "square");
    } catch (const Error& e) {
        return e.what();
    }
    return "(valid)";
}

}  // namespace

TEST(AppendMesh, TheIdentityCopiesTheArraysExactly) {
    const Square square;
    Scene s = with_material();
    EXPECT_EQ(append_mesh(s, square.arrays(), Affine3{}, "a"), 1u);
    EXPECT_EQ(append_mesh(s, square.arrays(), Affine3{}, "b"), 2u);
    ASSERT_EQ(s.positions.size(), 8u);
    for (std::size_t i = 0; i < 4; ++i) {
        EXPECT_EQ(s.positions[i], square.positions[i]);
        EXPECT_EQ(s.positions[4 + i], square.positions[i]);
    }
    EXPECT_EQ(s.objects, (std::vector<std::string>{"(default)", "a", "b"}));
    ASSERT_EQ(s.triangle_count(), 4u);
    // The second copy's indices are offset; materials and objects per triangle.
    EXPECT_EQ(s.tri_positions[2], (std::array<std::uint32_t, 3>{4, 5, 6}));
    EXPECT_EQ(s.tri_normals[3], (std::array<std::uint32_t, 3>{4, 6, 7}));
    EXPECT_EQ(s.tri_texcoords[3], (std::array<std::uint32_t, 3>{4, 6, 7}));
    EXPECT_EQ(s.tri_material, (std::vector<std::uint32_t>{1, 1, 1, 1}));
    EXPECT_EQ(s.tri_object, (std::vector<std::uint32_t>{1, 1, 2, 2}));
}

TEST(AppendMesh, TransformsPositionsAndNormals) {
    Square square;
    // Normals of a plane x + z = c (whatever the positions), to see the scale act on them.
    square.normals.assign(4, normalize(Vec3f(1, 0, 1)));
    Scene s = with_material();
    // Scale x by 2 and y by 4, then move by (10, 20, 30).
    const Affine3 m = rows({{{2, 0, 0, 10}, {0, 4, 0, 20}, {0, 0, 1, 30}}});
    append_mesh(s, square.arrays(), m, "moved");
    EXPECT_EQ(s.positions[2], Vec3f(12, 24, 30));
    // By the inverse transpose: the plane x / 2 + z = c has normal (1/2, 0, 1), normalised.
    const Vec3f expected = normalize(Vec3f(0.5f, 0.0f, 1.0f));
    for (const Vec3f& n : s.normals) {
        EXPECT_NEAR(n.x, expected.x, 1e-6f);
        EXPECT_NEAR(n.y, expected.y, 1e-6f);
        EXPECT_NEAR(n.z, expected.z, 1e-6f);
    }
    // A quarter turn about x takes +z to -y.
    Scene turned = with_material();
    append_mesh(turned, Square{}.arrays(), rows({{{1, 0, 0, 0}, {0, 0, -1, 0}, {0, 1, 0, 0}}}),
                "turned");
    EXPECT_EQ(turned.normals[0], Vec3f(0, -1, 0));
    EXPECT_LT(face_normal(turned, 0).y, 0.0f);
}

TEST(AppendMesh, AMirrorKeepsTheWindingFacingTheNormals) {
    const Square square;
    Scene s = with_material();
    append_mesh(s, square.arrays(), Affine3{}, "plain");
    // Mirrored in z: the square faces -z now, and so must its normals and its winding.
    append_mesh(s, square.arrays(), rows({{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, -1, 0}}}), "mirror");
    EXPECT_GT(face_normal(s, 0).z, 0.0f);
    EXPECT_LT(face_normal(s, 2).z, 0.0f);
    EXPECT_LT(face_normal(s, 3).z, 0.0f);
    EXPECT_EQ(s.normals[4], Vec3f(0, 0, -1));
    // The corners' attributes follow their positions.
    for (std::size_t t = 2; t < 4; ++t)
        for (int k = 0; k < 3; ++k) {
            EXPECT_EQ(s.tri_normals[t][k], s.tri_positions[t][k]);
            EXPECT_EQ(s.tri_texcoords[t][k], s.tri_positions[t][k]);
        }
}

TEST(AppendMesh, PerCornerAttributesAndZeroNormals) {
    Square square;
    // One normal and uv per corner (6); the second triangle's first corner has no direction.
    square.normals.assign(6, Vec3f(0, 0, 1));
    square.normals[3] = Vec3f(0, 0, 0);
    square.uvs.assign(6, Vec2f{0.5f, 0.5f});
    Scene s = with_material();
    append_mesh(s, square.arrays(), Affine3{}, "corners");
    EXPECT_EQ(s.normals.size(), 6u);
    EXPECT_EQ(s.tri_normals[0], (std::array<std::uint32_t, 3>{0, 1, 2}));
    EXPECT_EQ(s.tri_texcoords[1], (std::array<std::uint32_t, 3>{3, 4, 5}));
    // A zero normal makes its triangle flat: no normals at any corner.
    EXPECT_EQ(s.tri_normals[1], (std::array<std::uint32_t, 3>{kNoIndex, kNoIndex, kNoIndex}));
}

TEST(AppendMesh, BadMeshesAndTransformsAreErrors) {
    const Scene s = with_material();
    Square bad;
    bad.triangles[1][2] = 4;
    EXPECT_EQ(error_of(s, bad.arrays()),
              "mesh 'square': triangle 1 uses position 4, but there are 4");
    bad = Square{};
    bad.normals.pop_back();
    EXPECT_EQ(error_of(s, bad.arrays()),
              "mesh 'square': 3 normals: expected none, one per position (4) or one per triangle "
              "corner (6)");
    bad = Square{};
    bad.materials = {1, 2};
    EXPECT_EQ(error_of(s, bad.arrays()),
              "mesh 'square': triangle 1 has material 2, but the scene has 2");
    bad = Square{};
    bad.materials = {1};
    EXPECT_EQ(error_of(s, bad.arrays()),
              "mesh 'square': 1 material ids for 2 triangles (one per triangle)");
    bad = Square{};
    bad.positions[2].y = NAN;
    EXPECT_EQ(error_of(s, bad.arrays()), "mesh 'square': position 2 is not finite");
    EXPECT_EQ(error_of(s, Square{}.arrays()), "(valid)");

    Scene scene = with_material();
    const Square square;
    EXPECT_THROW(append_mesh(scene, square.arrays(),
                             rows({{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 0, 0}}}), "flat"),
                 Error);
    EXPECT_THROW(append_mesh(scene, square.arrays(),
                             rows({{{1, 0, 0, NAN}, {0, 1, 0, 0}, {0, 0, 1, 0}}}), "nan"),
                 Error);
    // Nothing was added by the failed calls.
    EXPECT_EQ(scene.triangle_count(), 0u);
    EXPECT_EQ(scene.objects.size(), 1u);
}

TEST(CheckSceneLimits, TrianglesAndPositions) {
    Scene s = with_material();
    append_mesh(s, Square{}.arrays(), Affine3{}, "square");
    Limits limits;
    EXPECT_NO_THROW(check_scene_limits(s, limits));
    limits.max_triangles = 1;
    try {
        check_scene_limits(s, limits);
        FAIL() << "no limit error";
    } catch (const LimitError& e) {
        EXPECT_EQ(e.limit(), Limit::Triangles);
        EXPECT_STREQ(e.what(), "the scene has 2 triangles, more than the limit of 1");
    }
    limits = Limits{};
    limits.max_vertices = 3;
    try {
        check_scene_limits(s, limits);
        FAIL() << "no limit error";
    } catch (const LimitError& e) {
        EXPECT_EQ(e.limit(), Limit::Vertices);
        EXPECT_STREQ(e.what(), "the scene has 4 vertex positions, more than the limit of 3");
    }
}

TEST(CheckSceneLimits, AnInstancedMeshCountsOnce) {
    Scene s = with_material();
    const std::uint32_t mesh =
        s.add_mesh(instance_mesh(Square{}.arrays(), s.materials.size(), "square"));
    for (int i = 0; i < 100; ++i)
        s.add_instance(mesh, Affine3::translation({static_cast<float>(i), 0, 0}), "copy");
    EXPECT_EQ(s.instanced_triangle_count(), 200u);
    Limits limits;
    limits.max_triangles = 2;
    limits.max_vertices = 4;
    EXPECT_NO_THROW(check_scene_limits(s, limits));
    // The scene's own triangles count as well as the meshes'.
    append_mesh(s, Square{}.arrays(), Affine3{}, "own");
    try {
        check_scene_limits(s, limits);
        FAIL() << "no limit error";
    } catch (const LimitError& e) {
        EXPECT_STREQ(e.what(), "the scene has 4 triangles, more than the limit of 2");
    }
}

TEST(InstanceMesh, IsWhatTheIdentityAppends) {
    const Square square;
    Scene appended = with_material();
    append_mesh(appended, square.arrays(), Affine3{}, "a");
    const auto mesh = instance_mesh(square.arrays(), appended.materials.size(), "a");
    EXPECT_EQ(mesh->positions, appended.positions);
    EXPECT_EQ(mesh->normals, appended.normals);
    ASSERT_EQ(mesh->texcoords.size(), appended.texcoords.size());
    for (std::size_t i = 0; i < mesh->texcoords.size(); ++i)
        EXPECT_TRUE(mesh->texcoords[i].x == appended.texcoords[i].x &&
                    mesh->texcoords[i].y == appended.texcoords[i].y);
    EXPECT_EQ(mesh->tri_positions, appended.tri_positions);
    EXPECT_EQ(mesh->tri_normals, appended.tri_normals);
    EXPECT_EQ(mesh->tri_texcoords, appended.tri_texcoords);
    EXPECT_EQ(mesh->tri_material, appended.tri_material);
    // A scene with these materials takes it; the materials are checked against the count given.
    Scene s = with_material();
    EXPECT_EQ(s.add_mesh(mesh), 0u);
    EXPECT_THROW((void)instance_mesh(square.arrays(), 1, "a"), Error);
}
