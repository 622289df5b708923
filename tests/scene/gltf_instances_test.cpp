// Instances from glTF: nodes that share a mesh and EXT_mesh_gpu_instancing, with the limits
// counting what is stored.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/core/limits.h"
#include "toonray/scene/gltf_animation.h"
#include "toonray/scene/gltf_loader.h"
#include "toonray/scene/scene.h"
#include "scene/gltf_test_files.h"

using namespace toonray;

namespace {

// A glTF file of one mesh (a `side` x `side` grid of quads in z = 0 with a normal per vertex)
// and `nodes` (JSON); the scene shows nodes `roots`. Accessors: 0 positions, 1 normals, 2
// indices, then 3 translations, 4 rotations and 5 scales of `gpu` instances when given, and a
// morph target (accessor 6, zero displacements) when `morph`.
struct GpuInstances {
    std::vector<Vec3f> translation;
    std::vector<std::array<float, 4>> rotation;
    std::vector<Vec3f> scale;
};
std::string grid_gltf(int side, const std::string& nodes, const std::string& roots,
                      const GpuInstances* gpu = nullptr, bool morph = false) {
    using gltf_test::put;
    std::vector<std::uint8_t> bin;
    const int n = side + 1;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
            put<float>(bin, {static_cast<float>(x) / side, static_cast<float>(y) / side, 0.0f});
    const std::size_t normals_at = bin.size();
    for (int i = 0; i < n * n; ++i) put<float>(bin, {0.0f, 0.0f, 1.0f});
    const std::size_t indices_at = bin.size();
    for (int y = 0; y < side; ++y)
        for (int x = 0; x < side; ++x) {
            const auto a = static_cast<std::uint32_t>(y * n + x), b = a + 1,
                       c = a + static_cast<std::uint32_t>(n), d = c + 1;
            put<std::uint32_t>(bin, {a, b, d, a, d, c});
        }
    const std::size_t end = bin.size();
    std::string views =
        "{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": " + std::to_string(normals_at) +
        "}, {\"buffer\": 0, \"byteOffset\": " + std::to_string(normals_at) +
        ", \"byteLength\": " + std::to_string(indices_at - normals_at) +
        "}, {\"buffer\": 0, \"byteOffset\": " + std::to_string(indices_at) +
        ", \"byteLength\": " + std::to_string(end - indices_at) + "}";
    const int vertices = n * n, indices = 6 * side * side;
    std::string accessors =
        "{\"bufferView\": 0, \"componentType\": 5126, \"count\": " + std::to_string(vertices) +
        ", \"type\": \"VEC3\"}, {\"bufferView\": 1, \"componentType\": 5126, \"count\": " +
        std::to_string(vertices) +
        ", \"type\": \"VEC3\"}, {\"bufferView\": 2, \"componentType\": 5125, \"count\": " +
        std::to_string(indices) + ", \"type\": \"SCALAR\"}";
    auto add_view = [&](std::size_t from, std::size_t to) {
        views += ", {\"buffer\": 0, \"byteOffset\": " + std::to_string(from) +
                 ", \"byteLength\": " + std::to_string(to - from) + "}";
    };
    int view_count = 3;
    if (gpu) {
        const std::size_t t0 = bin.size();
        for (const Vec3f& t : gpu->translation) put<float>(bin, {t.x, t.y, t.z});
        const std::size_t r0 = bin.size();
        for (const auto& r : gpu->rotation) put<float>(bin, {r[0], r[1], r[2], r[3]});
        const std::size_t s0 = bin.size();
        for (const Vec3f& s : gpu->scale) put<float>(bin, {s.x, s.y, s.z});
        add_view(t0, r0);
        add_view(r0, s0);
        add_view(s0, bin.size());
        const std::string count = std::to_string(gpu->translation.size());
        accessors += ", {\"bufferView\": 3, \"componentType\": 5126, \"count\": " + count +
                     ", \"type\": \"VEC3\"}, {\"bufferView\": 4, \"componentType\": 5126, "
                     "\"count\": " +
                     count +
                     ", \"type\": \"VEC4\"}, {\"bufferView\": 5, \"componentType\": 5126, "
                     "\"count\": " +
                     count + ", \"type\": \"VEC3\"}";
        view_count = 6;
    }
    std::string targets;
    if (morph) {
        const std::size_t m0 = bin.size();
        for (int i = 0; i < vertices; ++i) put<float>(bin, {0.0f, 0.0f, 0.0f});
        add_view(m0, bin.size());
        if (!gpu)
            accessors +=
                ", {\"bufferView\": 3, \"componentType\": 5126, \"count\": 0, "
                "\"type\": \"VEC3\"}, {\"bufferView\": 3, \"componentType\": 5126, "
                "\"count\": 0, \"type\": \"VEC4\"}, {\"bufferView\": 3, "
                "\"componentType\": 5126, \"count\": 0, \"type\": \"VEC3\"}";
        accessors += ", {\"bufferView\": " + std::to_string(view_count) +
                     ", \"componentType\": 5126, \"count\": " + std::to_string(vertices) +
                     ", \"type\": \"VEC3\"}";
        targets = ", \"targets\": [{\"POSITION\": 6}]";
    }
    return "{\"asset\": {\"version\": \"2.0\"}, \"extensionsUsed\": [\"EXT_mesh_gpu_instancing\"], "
           "\"scene\": 0, \"scenes\": [{\"nodes\": " +
           roots + "}], \"nodes\": " + nodes +
           ", \"meshes\": [{\"name\": \"grid\", \"primitives\": [{\"attributes\": {\"POSITION\": "
           "0, \"NORMAL\": 1}, \"indices\": 2" +
           targets + "}]" + (morph ? ", \"weights\": [0]" : "") + "}], \"accessors\": [" +
           accessors + "], \"bufferViews\": [" + views +
           "], \"buffers\": [{\"byteLength\": " + std::to_string(bin.size()) + ", \"uri\": \"" +
           gltf_test::data_uri(bin) + "\"}]}";
}

std::filesystem::path write_temp(const std::string& name, const std::string& text) {
    const auto path = std::filesystem::temp_directory_path() / name;
    std::ofstream(path, std::ios::binary) << text;
    return path;
}

Scene pose(const std::filesystem::path& path, GltfDocument* doc_out = nullptr) {
    Warnings warnings;
    GltfDocument doc = load_gltf(path, warnings);
    if (doc_out) *doc_out = doc;
    GltfAnimator animator(std::move(doc), {});
    Scene scene;
    std::vector<Light> lights;
    animator.pose(0.0, 64, 64, scene, lights);
    return scene;
}

TEST(GltfInstances, NodesThatShareAMeshAreInstances) {
    const std::string nodes = R"([{"name": "a", "mesh": 0, "translation": [2, 0, 0]},
        {"name": "b", "mesh": 0, "rotation": [0, 0, 0.7071067811865476, 0.7071067811865476]},
        {"name": "holder", "children": [0, 1], "scale": [2, 2, 2]}])";
    GltfDocument doc;
    const Scene scene = pose(write_temp("instances_shared.gltf", grid_gltf(2, nodes, "[2]")), &doc);
    EXPECT_EQ(doc.triangles, 8u);  // the mesh once
    EXPECT_EQ(doc.instances, 2u);
    EXPECT_EQ(scene.triangle_count(), 0u);
    ASSERT_EQ(scene.meshes.size(), 1u);
    ASSERT_EQ(scene.instances.size(), 2u);
    EXPECT_EQ(scene.objects[scene.instances[0].object], "a");
    EXPECT_EQ(scene.objects[scene.instances[1].object], "b");
    // Flattened, they are where the nodes put them: a at (4, 0, 0) + 2p, b turned a quarter
    // about z and doubled.
    const Scene flat = flatten_instances(scene);
    ASSERT_EQ(flat.triangle_count(), 16u);
    EXPECT_EQ(flat.positions[flat.tri_positions[0][1]], Vec3f(5, 0, 0));  // (0.5, 0, 0)
    const Vec3f b = flat.positions[flat.tri_positions[8][1]];
    EXPECT_NEAR(b.x, 0.0f, 1e-6f);
    EXPECT_NEAR(b.y, 1.0f, 1e-6f);
    // A mesh used once is flattened as before.
    const Scene single = pose(
        write_temp("instances_single.gltf", grid_gltf(2, R"([{"name": "a", "mesh": 0}])", "[0]")));
    EXPECT_TRUE(single.instances.empty());
    EXPECT_EQ(single.triangle_count(), 8u);
}

TEST(GltfInstances, GpuInstancingPlacesEachEntry) {
    GpuInstances gpu;
    gpu.translation = {{0, 0, 0}, {1, 2, 3}, {-1, 0, 0}};
    gpu.rotation = {{0, 0, 0, 1}, {0, 0, 0, 1}, {0, 0, 1, 0}};  // the last: half a turn about z
    gpu.scale = {{1, 1, 1}, {2, 2, 2}, {1, 1, 1}};
    const std::string nodes = R"([{"name": "crowd", "mesh": 0, "translation": [10, 0, 0],
        "extensions": {"EXT_mesh_gpu_instancing": {"attributes":
            {"TRANSLATION": 3, "ROTATION": 4, "SCALE": 5}}}}])";
    GltfDocument doc;
    const Scene scene =
        pose(write_temp("instances_gpu.gltf", grid_gltf(1, nodes, "[0]", &gpu)), &doc);
    EXPECT_EQ(doc.instances, 3u);
    EXPECT_EQ(doc.triangles, 2u);
    ASSERT_EQ(scene.instances.size(), 3u);
    EXPECT_EQ(scene.objects[scene.instances[1].object], "crowd.1");
    // Entry 1: node (10, 0, 0) then (1, 2, 3) and scale 2: (1, 1, 0) -> (13, 4, 3).
    EXPECT_EQ(scene.instances[1].to_world.point({1, 1, 0}), Vec3f(13, 4, 3));
    const Vec3f turned = scene.instances[2].to_world.point({1, 0, 0});
    EXPECT_NEAR(turned.x, 8.0f, 1e-6f);
    EXPECT_NEAR(turned.y, 0.0f, 1e-6f);
}

TEST(GltfInstances, LimitsCountStoredTrianglesAndInstances) {
    // 10,000 GPU instances of a 70,688-triangle grid: stored once, accepted by the default
    // limits (triangles and the memory estimate the render command checks).
    GpuInstances gpu;
    for (int i = 0; i < 10'000; ++i) {
        gpu.translation.push_back({static_cast<float>(i % 100), 0, static_cast<float>(i / 100)});
        gpu.rotation.push_back({0, 0, 0, 1});
        gpu.scale.push_back({1, 1, 1});
    }
    const std::string nodes = R"([{"name": "crowd", "mesh": 0,
        "extensions": {"EXT_mesh_gpu_instancing": {"attributes":
            {"TRANSLATION": 3, "ROTATION": 4, "SCALE": 5}}}}])";
    Warnings warnings;
    const GltfDocument doc =
        load_gltf(write_temp("instances_crowd.gltf", grid_gltf(188, nodes, "[0]", &gpu)), warnings);
    EXPECT_EQ(doc.triangles, 70'688u);
    EXPECT_EQ(doc.instances, 10'000u);
    EXPECT_NO_THROW(check_memory(scene_bytes(doc.vertices, doc.triangles, doc.instances), "crowd"));
    // The same 707 million triangles on 10,000 nodes of a mesh that cannot be instanced (it
    // has a morph target, so each node is flattened) are refused.
    std::string many = "[";
    std::string roots = "[";
    for (int i = 0; i < 10'000; ++i) {
        many += (i ? ", " : "") + std::string(R"({"mesh": 0, "translation": [)") +
                std::to_string(i) + ", 0, 0]}";
        roots += (i ? ", " : "") + std::to_string(i);
    }
    many += "]";
    roots += "]";
    try {
        (void)load_gltf(
            write_temp("instances_flat.gltf", grid_gltf(188, many, roots, nullptr, true)),
            warnings);
        FAIL() << "a flattened scene of 707 million triangles was accepted";
    } catch (const LimitError& e) {
        EXPECT_NE(std::string(e.what()).find("706880000 triangles"), std::string::npos) << e.what();
    }
}

TEST(GltfInstances, BadGpuInstancingNamesThePlace) {
    GpuInstances gpu;
    gpu.translation = {{0, 0, 0}, {1, 0, 0}};
    gpu.rotation = {{0, 0, 0, 1}, {0, 0, 0, 1}};
    gpu.scale = {{1, 1, 1}, {1, 1, 1}};
    const std::string nodes = R"([{"mesh": 0, "extensions": {"EXT_mesh_gpu_instancing":
        {"attributes": {"TRANSLATION": 3, "SCALE": 9}}}}])";
    Warnings warnings;
    try {
        (void)load_gltf(write_temp("instances_bad.gltf", grid_gltf(1, nodes, "[0]", &gpu)),
                        warnings);
        FAIL() << "accepted an attribute without an accessor";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("nodes[0].extensions.EXT_mesh_gpu_instancing"),
                  std::string::npos)
            << e.what();
    }
}

}  // namespace
