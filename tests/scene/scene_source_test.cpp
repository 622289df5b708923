#include "toonray/scene/scene_source.h"

#include <gtest/gtest.h>

#include <fstream>

#include "support/test_support.h"

using namespace toonray;

namespace {

// A unit square in the z = 0 plane, two triangles without normals, folded along its diagonal
// by `fold` in z so that auto-smooth has an edge to smooth.
void write_square(const std::filesystem::path& path, const char* camera_block = "") {
    std::ofstream(path) << "v 0 0 0\nv 1 0 0\nv 1 1 0.1\nv 0 1 0\nf 1 2 3\nf 1 3 4\n"
                        << camera_block;
}

}  // namespace

TEST(SceneSource, SettingsLightsWinAndTheLightsFileIsNotRead) {
    test_support::TempDir dir("source_lights");
    write_square(dir.path / "a.obj");
    std::ofstream(dir.path / "a.lights") << "spot 1 2 3\n";  // bad: must not be read
    SceneSetup setup;
    setup.lights = {parse_light("dir:0,0,-1")};
    SceneFrame frame;
    Warnings warnings;
    ObjFileSource(dir.path / "a.obj", setup).load(1, frame, warnings);
    ASSERT_EQ(frame.lights.size(), 1u);
    EXPECT_EQ(frame.lights[0], setup.lights[0]);
    // Without lights in the settings the bad file is read, and named in the error.
    try {
        ObjFileSource(dir.path / "a.obj", SceneSetup{}).load(1, frame, warnings);
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("a.lights:1: unknown light 'spot'"), std::string::npos)
            << e.what();
    }
}

TEST(SceneSource, TheLightsFileLightsTheSceneElseTheDefaultLight) {
    test_support::TempDir dir("source_default_light");
    write_square(dir.path / "lit.obj");
    std::ofstream(dir.path / "lit.lights") << "point 1 2 3 0.25\n";
    write_square(dir.path / "dark.obj");
    SceneFrame lit, dark;
    Warnings warnings;
    ObjFileSource(dir.path / "lit.obj", SceneSetup{}).load(1, lit, warnings);
    ASSERT_EQ(lit.lights.size(), 1u);
    EXPECT_EQ(lit.lights[0].vector, Vec3f(1, 2, 3));
    ObjFileSource(dir.path / "dark.obj", SceneSetup{}).load(1, dark, warnings);
    ASSERT_EQ(dark.lights.size(), 1u);
    EXPECT_EQ(dark.lights[0], default_light(dark.scene, dark.camera));
}

TEST(SceneSource, CameraFromSettingsElseTheCameraBlockElseAutomatic) {
    test_support::TempDir dir("source_camera");
    write_square(dir.path / "block.obj", "v 0 0 5\nv 0 0 4\nvn 0 1 0\nc 5 6 1\n");
    write_square(dir.path / "plain.obj");
    Warnings warnings;
    SceneFrame frame;
    ObjFileSource(dir.path / "block.obj", SceneSetup{}).load(1, frame, warnings);
    EXPECT_EQ(frame.camera.eye, Vec3f(0, 0, 5));
    SceneSetup setup;
    setup.camera = CameraSpec{{1, 1, 9}, {1, 1, 8}, {0, 1, 0}};
    ObjFileSource(dir.path / "block.obj", setup).load(1, frame, warnings);
    EXPECT_EQ(frame.camera.eye, Vec3f(1, 1, 9));
    ObjFileSource(dir.path / "plain.obj", SceneSetup{}).load(1, frame, warnings);
    const Vec3f points[] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0.1f}, {0, 1, 0}};
    const CameraSpec automatic = auto_camera(points, 1280, 720);
    EXPECT_EQ(frame.camera.eye, automatic.eye);
    EXPECT_EQ(frame.camera.gaze, automatic.gaze);
}

TEST(SceneSource, AutoSmoothGivesNormalsToEveryCorner) {
    test_support::TempDir dir("source_smooth");
    write_square(dir.path / "a.obj");
    SceneSetup setup;
    setup.auto_smooth = 30.0f;
    SceneFrame frame;
    Warnings warnings;
    ObjFileSource(dir.path / "a.obj", SceneSetup{}).load(1, frame, warnings);
    EXPECT_EQ(frame.scene.tri_normals[0][0], kNoIndex);
    ObjFileSource(dir.path / "a.obj", setup).load(1, frame, warnings);
    for (const auto& corners : frame.scene.tri_normals)
        for (std::uint32_t n : corners) EXPECT_NE(n, kNoIndex);
}

TEST(SceneSource, ChooseLightsSettingsThenOwnThenDefault) {
    toonray::Scene scene;
    scene.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    scene.add_triangle({0, 1, 2}, 0, 0);
    const toonray::CameraSpec camera{{0, 0, 5}, {0, 0, 4}, {0, 1, 0}};
    const toonray::Light own{toonray::Light::Kind::Directional, {0, 0, -1}, 0.5f};
    const toonray::Light given{toonray::Light::Kind::Point, {1, 2, 3}, 1.0f};
    toonray::SceneSetup setup;
    EXPECT_EQ(toonray::choose_lights(scene, camera, {}, setup),
              std::vector<toonray::Light>{toonray::default_light(scene, camera)});
    EXPECT_EQ(toonray::choose_lights(scene, camera, {own}, setup),
              std::vector<toonray::Light>{own});
    setup.lights = {given};
    EXPECT_EQ(toonray::choose_lights(scene, camera, {own}, setup),
              std::vector<toonray::Light>{given});
}
