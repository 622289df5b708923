// The piano's keys as instances of their shapes: the same geometry as the flat model, posed the
// same way, rendered the same but along edges.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "toonray/accel/scene_accel.h"
#include "toonray/piano/piano_pose.h"
#include "toonray/render/renderer.h"

namespace toonray {
namespace {

const PianoModel& piano() {
    static const PianoModel model = build_piano();
    return model;
}

// The largest distance between the flattened instanced scene's key vertices and the flat
// model's, triangle corner by triangle corner (the keys' triangles come last when flattened,
// in key order, as in the model).
float largest_key_gap(const Scene& flat_model, const Scene& instanced) {
    const Scene flat = flatten_instances(instanced);
    EXPECT_EQ(flat.triangle_count(), flat_model.triangle_count());
    std::vector<std::size_t> model_keys, flat_keys;
    for (std::size_t k = 0; k < piano().keys.size(); ++k)
        for (std::size_t t = 0; t < flat_model.triangle_count(); ++t)
            if (flat_model.tri_object[t] == piano().keys[k].object) model_keys.push_back(t);
    for (std::size_t t = instanced.triangle_count(); t < flat.triangle_count(); ++t)
        flat_keys.push_back(t);
    EXPECT_EQ(model_keys.size(), flat_keys.size());
    float gap = 0.0f;
    for (std::size_t i = 0; i < std::min(model_keys.size(), flat_keys.size()); ++i) {
        EXPECT_EQ(flat.tri_object[flat_keys[i]], flat_model.tri_object[model_keys[i]]);
        for (int c = 0; c < 3; ++c) {
            const Vec3f d = flat.positions[flat.tri_positions[flat_keys[i]][c]] -
                            flat_model.positions[flat_model.tri_positions[model_keys[i]][c]];
            gap = std::max({gap, std::abs(d.x), std::abs(d.y), std::abs(d.z)});
        }
    }
    return gap;
}

TEST(PianoInstances, KeysShareAFewShapes) {
    const Scene keyed = instance_keys(piano());
    EXPECT_EQ(keyed.instances.size(), 88u);
    EXPECT_LE(keyed.meshes.size(), 12u);  // one black shape, a few white ones
    EXPECT_GE(keyed.meshes.size(), 4u);
    EXPECT_LT(keyed.stored_triangle_count(), piano().scene.triangle_count());
    for (std::size_t k = 0; k < 88; ++k)
        EXPECT_EQ(keyed.objects[keyed.instances[k].object],
                  key_object_name(static_cast<int>(k) + kLowestKey));
    EXPECT_LT(largest_key_gap(piano().scene, keyed), 2e-6f);
}

TEST(PianoInstances, PosedLikeTheFlatKeys) {
    PianoPose pose;
    for (std::size_t k = 0; k < 88; k += 7) pose.key_angle[k] = kKeyDipAngle * (k % 3 + 1) / 3.0f;
    Scene flat = piano().scene;
    pose_piano(piano(), pose, nullptr, flat);
    Scene keyed = instance_keys(piano());
    pose_piano(piano(), pose, nullptr, keyed);
    pose_key_instances(piano(), pose, keyed);
    EXPECT_LT(largest_key_gap(flat, keyed), 2e-6f);
}

TEST(PianoInstances, FramesDifferOnlyAlongEdges) {
    PianoPose pose;
    pose.key_angle[39] = kKeyDipAngle;
    Scene flat = piano().scene;
    pose_piano(piano(), pose, nullptr, flat);
    Scene keyed = instance_keys(piano());
    pose_piano(piano(), pose, nullptr, keyed);
    pose_key_instances(piano(), pose, keyed);
    const CameraSpec camera =
        look_at(piano().keyboard_center + Vec3f(0.25f, 0.3f, 0.45f), piano().keyboard_center, 50);
    RenderSettings settings;
    settings.width = 320;
    settings.height = 180;
    settings.layers = true;
    const std::vector<Light> lights{default_light(flat, camera)};
    Renderer a, b;
    const TriangleAccel fa = build_scene_accel(flat), ka = build_scene_accel(keyed);
    a.render(flat, fa, camera, lights, settings);
    b.render(keyed, ka, camera, lights, settings);
    const FrameLayers &la = a.layers(), &lb = b.layers();
    int differ = 0, elsewhere = 0;
    const int w = settings.width, h = settings.height;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (la.image(x, y) == lb.image(x, y)) continue;
            ++differ;
            bool edge = false;
            for (int dy = -2; dy <= 2; ++dy)
                for (int dx = -2; dx <= 2; ++dx) {
                    const int u = std::clamp(x + dx, 0, w - 1), v = std::clamp(y + dy, 0, h - 1);
                    edge = edge || la.lines(u, v) > 0 || lb.lines(u, v) > 0 ||
                           la.band(u, v) != la.band(x, y) || la.object(u, v) != la.object(x, y);
                }
            elsewhere += !edge;
        }
    EXPECT_LT(differ * 100, w * h) << differ;
    EXPECT_EQ(elsewhere, 0);
}

}  // namespace
}  // namespace toonray
