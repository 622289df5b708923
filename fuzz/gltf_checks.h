#pragma once
// What the glTF targets check of a file that loads: posing it at a few times gives a consistent
// scene (every index in range, every vertex finite), a valid camera and finite lights.

#include <cmath>
#include <filesystem>
#include <span>

#include "fuzz_util.h"
#include "toonray/scene/gltf_animation.h"
#include "toonray/core/error.h"
#include "toonray/scene/camera.h"

namespace toonray_fuzz {

inline void load_and_pose_gltf(std::span<const std::uint8_t> bytes, const char* name) {
    using namespace toonray;
    GltfOptions options;
    options.limits.max_vertices = 1'000'000;
    options.limits.max_triangles = 1'000'000;
    options.limits.max_memory = 1ull << 30;
    options.limits.max_input_bytes = 1 << 20;
    options.limits.max_image_pixels = 1 << 20;
    Warnings warnings;
    GltfDocument document;
    try {
        // A directory that does not exist: the fuzzer must not read files.
        document = parse_gltf(bytes, std::filesystem::path("/nonexistent-toonray-fuzz") / name,
                              warnings, options);
    } catch (const Error&) {
        return;
    }
    std::optional<GltfAnimator> animator;
    try {
        animator.emplace(std::move(document), GltfPoseOptions{});
    } catch (const Error&) {
        return;
    }
    Scene scene;
    std::vector<Light> lights;
    for (double t : {0.0, 0.37, 1.0, 1e6}) {
        animator->pose(t, 64, 48, scene, lights);
        const std::size_t n = scene.triangle_count();
        FUZZ_CHECK(scene.tri_normals.size() == n && scene.tri_texcoords.size() == n);
        FUZZ_CHECK(scene.colours.empty() || scene.colours.size() == scene.positions.size());
        for (std::size_t i = 0; i < n; ++i) {
            for (int c = 0; c < 3; ++c) {
                FUZZ_CHECK(scene.tri_positions[i][c] < scene.positions.size());
                FUZZ_CHECK(scene.tri_normals[i][c] == kNoIndex ||
                           scene.tri_normals[i][c] < scene.normals.size());
                FUZZ_CHECK(scene.tri_texcoords[i][c] == kNoIndex ||
                           scene.tri_texcoords[i][c] < scene.texcoords.size());
            }
            FUZZ_CHECK(scene.tri_material[i] < scene.materials.size());
            FUZZ_CHECK(scene.tri_object[i] < scene.objects.size());
        }
        for (const Vec3f& p : scene.positions) FUZZ_CHECK(is_finite(p));
        for (const Light& l : lights) FUZZ_CHECK(is_finite(l.vector) && std::isfinite(l.intensity));
        if (scene.camera) {
            try {
                (void)make_view_plane(*scene.camera, 64, 48);
            } catch (const Error&) {
            }
        }
    }
}

}  // namespace toonray_fuzz
