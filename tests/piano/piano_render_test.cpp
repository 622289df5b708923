// The piano end to end: written as OBJ and read back exactly, rendered, and re-rendered after a
// pose with a refitted BVH.

#include <gtest/gtest.h>

#include <bit>
#include <cstring>
#include <filesystem>
#include <set>
#include <unistd.h>

#include "toonray/accel/triangle_accel.h"
#include "toonray/piano/piano_animation.h"
#include "toonray/piano/piano_model.h"
#include "toonray/piano/piano_pose.h"
#include "toonray/render/renderer.h"
#include "toonray/scene/obj_loader.h"
#include "toonray/scene/obj_writer.h"
#include "support/test_scenes.h"
#include "support/image_compare.h"
#include "support/same_bits.h"

namespace toonray {
namespace {

namespace fs = std::filesystem;

using test_support::same_bits;

// Forty overlapping notes over four seconds.
Score forty_notes() {
    Score score;
    for (int i = 0; i < 40; ++i)
        score.notes.push_back({0.1 * i, 0.1 * i + 0.25, 40 + (i * 5) % 40, 80, 0});
    return score;
}

// The piano playing forty_notes(), posed at `seconds` (with the roll's holes), and what the pose
// showed.
struct PosedPiano {
    Scene scene;
    PoseStats stats;
};
PosedPiano pose_forty_notes(double seconds) {
    const PianoPlayback play(forty_notes());
    PianoOptions options;
    options.hole_capacity = play.hole_capacity();
    const PianoModel model = build_piano(options);
    PosedPiano posed{model.scene, {}};
    posed.stats = pose_piano(model, play.pose_at(seconds), &play.roll(), posed.scene);
    return posed;
}

TEST(PianoRender, PosedPianoRoundTripsThroughObj) {
    const PosedPiano piano = pose_forty_notes(2.0);
    const Scene& posed = piano.scene;
    EXPECT_GT(piano.stats.visible_holes, 0u);

    const fs::path dir =
        fs::temp_directory_path() / ("toonray_piano_obj_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    write_obj(dir / "piano.obj", posed);
    Scene back;
    Warnings warnings;
    load_obj(dir / "piano.obj", back, warnings);
    fs::remove_all(dir);
    EXPECT_TRUE(warnings.empty());

    ASSERT_EQ(back.positions.size(), posed.positions.size() + 2);  // + camera eye and gaze
    for (std::size_t i = 0; i < posed.positions.size(); ++i)
        ASSERT_TRUE(same_bits(back.positions[i], posed.positions[i])) << i;
    ASSERT_EQ(back.normals.size(), posed.normals.size() + 1);  // + camera up
    for (std::size_t i = 0; i < posed.normals.size(); ++i)
        ASSERT_TRUE(same_bits(back.normals[i], posed.normals[i])) << i;
    EXPECT_EQ(back.tri_positions, posed.tri_positions);
    EXPECT_EQ(back.tri_normals, posed.tri_normals);
    EXPECT_EQ(back.tri_object, posed.tri_object);
    EXPECT_EQ(back.tri_material, posed.tri_material);
    EXPECT_EQ(back.objects, posed.objects);
    ASSERT_EQ(back.materials.size(), posed.materials.size());
    for (std::size_t i = 1; i < posed.materials.size(); ++i) {
        EXPECT_EQ(back.materials[i].name, posed.materials[i].name);
        EXPECT_EQ(back.materials[i].kd, posed.materials[i].kd);
    }
    ASSERT_TRUE(back.camera.has_value());
    EXPECT_TRUE(same_bits(back.camera->eye, posed.camera->eye));
    EXPECT_TRUE(same_bits(back.camera->gaze, posed.camera->gaze));
    EXPECT_TRUE(same_bits(back.camera->up, posed.camera->up));
}

TEST(PianoRender, KeysAreVisibleAndAPressShowsAfterRefit) {
    const PianoModel model = build_piano();
    Scene scene = model.scene;
    TriangleAccel accel;
    accel.build(scene.positions, scene.tri_positions);
    RenderSettings settings;
    settings.lines.mode = LineMode::Classic;  // one sample at each pixel's centre
    settings.layers = true;                   // the distances and objects seen
    settings.width = 480;
    settings.height = 200;
    settings.threads = 1;
    // From the player's seat, looking down at the middle of the keyboard.
    const CameraSpec camera = look_at({0.0f, 1.15f, 0.95f}, model.keyboard_center, 75.0f);
    Renderer renderer;
    renderer.render(scene, accel, camera, test_support::default_lights(scene, camera), settings);
    const FrameLayers& g = renderer.layers();
    std::set<std::uint32_t> keys_seen;
    std::set<std::uint32_t> key_objects;
    for (const PianoKey& k : model.keys) key_objects.insert(k.object);
    for (std::size_t i = 0; i < g.object.size(); ++i)
        if (key_objects.count(g.object.data()[i])) keys_seen.insert(g.object.data()[i]);
    EXPECT_GT(keys_seen.size(), 70u) << "keys hidden by the case";

    // Press middle C, refit, render again: the key's pixels change, and the refitted BVH gives
    // exactly what a fresh build gives.
    const PianoKey& c4 = model.keys[60 - kLowestKey];
    auto key_pixels = [&](const FrameLayers& gb) {
        std::vector<float> depth;
        for (std::size_t i = 0; i < gb.object.size(); ++i)
            if (gb.object.data()[i] == c4.object) depth.push_back(gb.distance.data()[i]);
        return depth;
    };
    const std::vector<float> before = key_pixels(g);
    ASSERT_GT(before.size(), 100u);
    PianoPose pose;
    pose.key_angle[60 - kLowestKey] = kKeyDipAngle;
    pose_piano(model, pose, nullptr, scene);
    accel.refit(scene.positions, scene.tri_positions);
    renderer.render(scene, accel, camera, test_support::default_lights(scene, camera), settings);
    const std::vector<float> after = key_pixels(renderer.layers());
    EXPECT_NE(before, after);
    const Image<float> refitted = renderer.layers().distance;

    TriangleAccel fresh;
    fresh.build(scene.positions, scene.tri_positions);
    Renderer other;
    other.render(scene, fresh, camera, test_support::default_lights(scene, camera), settings);
    for (std::size_t i = 0; i < refitted.size(); ++i)
        ASSERT_EQ(refitted.data()[i], other.layers().distance.data()[i]) << "pixel " << i;
}

TEST(PianoRender, EverySurfaceSeenFromOutsideFacesTheViewer) {
    // Outward winding, checked where it matters: from many viewpoints around the piano, the
    // first surface each ray meets must face back toward the ray (the renderer would hide a
    // wrong winding by flipping normals, so this looks at the triangles themselves).
    const PianoModel model = build_piano();
    const Scene& s = model.scene;
    TriangleAccel accel;
    accel.build(s.positions, s.tri_positions);
    const Vec3f eyes[] = {{0.0f, 1.0f, 3.0f},  {2.5f, 1.2f, 2.0f},   {-2.5f, 0.9f, 1.5f},
                          {3.0f, 0.7f, -0.2f}, {-3.0f, 1.4f, -0.5f}, {0.5f, 3.0f, 0.8f},
                          {0.3f, 0.25f, 1.2f}, {0.0f, 1.0f, 0.7f},   {1.0f, 1.5f, -3.0f},
                          {0.2f, 0.95f, 0.45f}};
    std::size_t hits = 0, wrong = 0;
    for (const Vec3f& eye : eyes) {
        for (int i = 0; i < 120; ++i)
            for (int j = 0; j < 120; ++j) {
                // Aim across the piano's bounds.
                const Vec3f e = model.bounds.extent();
                Vec3f target = model.bounds.lo + Vec3f(e.x * (i + 0.5f) / 120.0f,
                                                       e.y * (j + 0.5f) / 120.0f, e.z * 0.5f);
                Ray ray{eye, normalize(target - eye)};
                Hit hit;
                if (!accel.intersect(ray, hit)) continue;
                ++hits;
                const auto& t = s.tri_positions[hit.prim];
                const Vec3f n = cross(s.positions[t[1]] - s.positions[t[0]],
                                      s.positions[t[2]] - s.positions[t[0]]);
                if (dot(n, ray.dir) >= 0.0f) {
                    ++wrong;
                    if (wrong < 5)
                        ADD_FAILURE()
                            << "back face of " << s.objects[s.tri_object[hit.prim]]
                            << " seen from (" << eye.x << ", " << eye.y << ", " << eye.z << ")";
                }
            }
    }
    EXPECT_GT(hits, 100000u);
    EXPECT_EQ(wrong, 0u);
}

// A piano frame adaptively sampled against full supersampling (--adaptive off): at most 0.5% of
// pixels may differ by more than 2/255.
TEST(PianoRender, AdaptiveSamplingStaysWithinFullSupersampling) {
    const Scene scene = pose_forty_notes(1.25).scene;
    TriangleAccel accel;
    accel.build(scene.positions, scene.tri_positions);
    // At 1280x720 the ink lines are wide enough to hide pixels, which take one sample.
    struct Case {
        LineMode mode;
        int width, height;
    };
    for (const Case& c : {Case{LineMode::Ink, 640, 360}, Case{LineMode::Robust, 640, 360},
                          Case{LineMode::Ink, 1280, 720}}) {
        const LineMode mode = c.mode;
        RenderSettings settings;
        settings.lines.mode = mode;
        settings.width = c.width;
        settings.height = c.height;
        Renderer adaptive, full;
        const ImageRgb8 a =
            adaptive.render(scene, accel, *scene.camera,
                            test_support::default_lights(scene, *scene.camera), settings);
        settings.sampling.adaptive = false;
        const ImageRgb8& b =
            full.render(scene, accel, *scene.camera,
                        test_support::default_lights(scene, *scene.camera), settings);
        const double share = test_support::share_differing(a, b, 2);
        std::printf(
            "piano, %s, %dx%d: %.3f%% of pixels differ by more than 2/255; %.1f%% refined\n",
            mode == LineMode::Ink ? "ink" : "robust", c.width, c.height, 100 * share,
            100.0 * static_cast<double>(adaptive.refined_pixels()) / a.size());
        EXPECT_LE(share, 0.005);
        EXPECT_LT(adaptive.refined_pixels(), a.size() / 2);
    }
}

}  // namespace
}  // namespace toonray
