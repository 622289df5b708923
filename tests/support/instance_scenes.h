#pragma once
/// An instanced scene the test suites share: a ground of the scene's own triangles, and
/// instances of the teapot (polygonal: no normals) and of a smooth sphere (vertex normals),
/// turned, scaled unevenly, one mirrored, two of them overlapping so that they cross.

#include <cmath>
#include <memory>
#include <numbers>
#include <string>

#include "toonray/core/affine.h"
#include "toonray/scene/scene.h"
#include "support/test_scenes.h"

namespace toonray::test_support {

/// A rotation about the unit axis (x, y, z) by `angle` radians, scaled per axis, then moved.
inline Affine3 placed(double x, double y, double z, double angle, Vec3f scale, Vec3f move) {
    const double len = std::sqrt(x * x + y * y + z * z);
    x /= len;
    y /= len;
    z /= len;
    const double c = std::cos(angle), s = std::sin(angle), t = 1 - c;
    const double r[3][3] = {{t * x * x + c, t * x * y - s * z, t * x * z + s * y},
                            {t * x * y + s * z, t * y * y + c, t * y * z - s * x},
                            {t * x * z - s * y, t * y * z + s * x, t * z * z + c}};
    Affine3 a;
    for (int i = 0; i < 3; ++i) {
        for (int k = 0; k < 3; ++k) a.m[i][k] = r[i][k] * scale[k];
        a.m[i][3] = move[i];
    }
    return a;
}

/// A UV sphere of unit radius with unit vertex normals, in one material.
inline std::shared_ptr<TriangleMesh> sphere_mesh(int rings, int segments, std::uint32_t material) {
    auto m = std::make_shared<TriangleMesh>();
    const double pi = std::numbers::pi;
    for (int r = 0; r <= rings; ++r)
        for (int k = 0; k < segments; ++k) {
            const double theta = pi * r / rings, phi = 2 * pi * k / segments;
            Vec3f n(static_cast<float>(std::sin(theta) * std::cos(phi)),
                    static_cast<float>(std::cos(theta)),
                    static_cast<float>(std::sin(theta) * std::sin(phi)));
            if (r == 0 || r == rings) n = Vec3f(0.0f, r == 0 ? 1.0f : -1.0f, 0.0f);
            m->positions.push_back(n);
            m->normals.push_back(n);
        }
    auto id = [&](int r, int k) { return static_cast<std::uint32_t>(r * segments + k % segments); };
    for (int r = 0; r < rings; ++r)
        for (int k = 0; k < segments; ++k) {
            const std::uint32_t a = id(r, k), b = id(r, k + 1), c = id(r + 1, k + 1),
                                d = id(r + 1, k);
            if (r > 0) m->add_triangle({a, b, c}, material, 0, {a, b, c});
            if (r + 1 < rings) m->add_triangle({a, c, d}, material, 0, {a, c, d});
        }
    return m;
}

/// The shared scene: a ground quad (own triangles, material 0), teapots "pot.0".."pot.5" of
/// material 1 and spheres "ball.0".."ball.2" of material 2; pot.1 and pot.2 overlap.
inline Scene instanced_test_scene() {
    Scene scene;
    scene.materials.emplace_back("teapot");
    scene.materials.back().kd = Vec3f(0.9f, 0.7f, 0.5f);
    scene.materials.emplace_back("ball");
    scene.materials.back().kd = Vec3f(0.4f, 0.6f, 0.9f);
    scene.positions = {{-12, 0, -12}, {12, 0, -12}, {12, 0, 12}, {-12, 0, 12}};
    scene.objects.push_back("ground");
    scene.add_triangle({0, 2, 1}, 0, 1);
    scene.add_triangle({0, 3, 2}, 0, 1);
    const Scene teapot = load_test_scene("teapot.obj");
    auto pot = std::make_shared<TriangleMesh>(static_cast<const TriangleMesh&>(teapot));
    std::fill(pot->tri_material.begin(), pot->tri_material.end(), 1u);
    const std::uint32_t pot_mesh = scene.add_mesh(pot);
    const std::uint32_t ball_mesh = scene.add_mesh(sphere_mesh(12, 24, 2));
    const Vec3f turns[6][2] = {
        {{0, 1, 0}, {-6, 0, -3}}, {{0.2f, 1, 0}, {0, 0, 0}}, {{0, 1, 0.3f}, {1.2f, 0.4f, 0.5f}},
        {{1, 1, 0}, {6, 0, -2}},  {{0, 1, 0}, {-4, 0, 5}},   {{0, 1, 0.1f}, {4, 0, 6}}};
    for (int i = 0; i < 6; ++i) {
        Vec3f scale(0.9f + 0.1f * static_cast<float>(i % 3), 1.0f,
                    1.1f - 0.05f * static_cast<float>(i));
        if (i == 3) scale.x = -scale.x;  // mirrored
        scene.add_instance(
            pot_mesh,
            placed(turns[i][0].x, turns[i][0].y, turns[i][0].z, 0.7 * i, scale, turns[i][1]),
            "pot." + std::to_string(i));
    }
    for (int i = 0; i < 3; ++i)
        scene.add_instance(ball_mesh,
                           placed(1, 0.5, 0, 0.3 * i, Vec3f(1.5f, 1.0f + 0.3f * i, 1.5f),
                                  Vec3f(-3.0f + 4.0f * i, 1.5f, 3.0f)),
                           "ball." + std::to_string(i));
    return scene;
}

/// A camera from `eye` toward `target` with a 60-degree horizontal field of view (the length
/// from the eye to the gaze point sets it: 1 / tan 30 degrees).
inline CameraSpec looking_at(const Vec3f& eye, const Vec3f& target) {
    return CameraSpec{eye, eye + normalize(target - eye) * 1.7320508f, Vec3f(0, 1, 0)};
}

/// A camera on the instanced test scene from above and to the side.
inline CameraSpec instanced_test_camera() { return looking_at(Vec3f(9, 9, 16), Vec3f(0, 1, 0)); }

}  // namespace toonray::test_support
