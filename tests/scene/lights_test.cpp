#include "toonray/scene/light.h"
#include "toonray/scene/scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "support/test_support.h"

using namespace toonray;

TEST(LightsFile, ParsesPointAndDirectionalLightsWithComments) {
    auto lights =
        parse_lights("# key and fill\npoint 1 2 3\ndirectional 0 -1 0 0.25  # fill\n", "l.txt");
    ASSERT_EQ(lights.size(), 2u);
    EXPECT_EQ(lights[0].kind, Light::Kind::Point);
    EXPECT_EQ(lights[0].vector, Vec3f(1, 2, 3));
    EXPECT_EQ(lights[1].kind, Light::Kind::Directional);
    EXPECT_EQ(lights[1].intensity, 0.25f);
    try {
        (void)parse_lights("point 1 2 3\nspot 1 2 3\n", "l.txt");
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("l.txt:2: unknown light 'spot'"), std::string::npos)
            << e.what();
    }
    EXPECT_THROW((void)parse_lights("point 1 2\n", "l.txt"), Error);
    EXPECT_THROW((void)parse_lights("directional 0 0 0\n", "l.txt"), Error);
    EXPECT_THROW((void)parse_lights("point 1 2 3 -1\n", "l.txt"), Error);
    EXPECT_THROW((void)parse_lights("# nothing\n", "l.txt"), Error);
}

TEST(LightsFile, LoadsAFileAndNamesItInErrors) {
    test_support::TempDir dir("lights");
    std::ofstream(dir.path / "good.lights") << "point 4 5 6 0.5\n";
    auto lights = load_lights(dir.path / "good.lights");
    ASSERT_EQ(lights.size(), 1u);
    EXPECT_EQ(lights[0].vector, Vec3f(4, 5, 6));
    EXPECT_EQ(lights[0].intensity, 0.5f);
    std::ofstream(dir.path / "bad.lights") << "\npoint x 5 6\n";
    try {
        (void)load_lights(dir.path / "bad.lights");
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("bad.lights:2: malformed number 'x'"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_THROW((void)load_lights(dir.path / "missing.lights"), Error);
}

TEST(LightsFile, ASceneFileHasTheLightsFileOfItsName) {
    test_support::TempDir dir("frame_lights");
    const auto obj = dir.path / "keys_000030.obj";
    EXPECT_EQ(scene_lights_path(obj), dir.path / "keys_000030.lights");
    EXPECT_TRUE(scene_file_lights(obj).empty());
    std::ofstream(dir.path / "keys_000030.lights")
        << "# toonray lights\ndirectional 0.5 -1 0 1    # sun 'Sun'\npoint 1 2 3 0.25\n";
    auto lights = scene_file_lights(obj);
    ASSERT_EQ(lights.size(), 2u);
    EXPECT_EQ(lights[0].kind, Light::Kind::Directional);
    EXPECT_EQ(lights[0].vector, Vec3f(0.5f, -1, 0));
    EXPECT_EQ(lights[1].intensity, 0.25f);
}

TEST(Light, FormatReadsBackExactly) {
    for (const char* text : {"point:1,2,3@1", "dir:0.1,-1,0.3333333@0.25", "1e-07,2,3"}) {
        const Light light = parse_light(text);
        EXPECT_EQ(parse_light(format_light(light)), light) << text << " -> " << format_light(light);
    }
    EXPECT_EQ(format_light(parse_light("dir:0,-1,0@0.5")), "dir:0,-1,0@0.5");
}

TEST(Light, TheDefaultLightIsTheEyeMovedAlongUpAndRight) {
    Scene s;
    s.positions = {{-3, -3, 0}, {3, -3, 0}, {3, 3, 0}, {-3, 3, 0}};
    s.add_triangle({0, 1, 2}, 0, 0);
    s.add_triangle({0, 2, 3}, 0, 0);
    const CameraSpec cam{{0, 0, 4}, {0, 0, 3}, {0, 1, 0}};
    // The radius is half the diagonal of the 6 x 6 x 0 bounds.
    const float half_radius = 0.5f * std::sqrt(72.0f) * 0.5f;
    const Light light = default_light(s, cam);
    EXPECT_EQ(light.kind, Light::Kind::Point);
    EXPECT_EQ(light.intensity, 1.0f);
    EXPECT_NEAR(light.vector.x, half_radius, 1e-5f);
    EXPECT_NEAR(light.vector.y, half_radius, 1e-5f);
    EXPECT_NEAR(light.vector.z, 4.0f, 1e-5f);
}
