#include "toonray/frame/lights.h"

#include <gtest/gtest.h>

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
        parse_lights("point 1 2 3\nspot 1 2 3\n", "l.txt");
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("l.txt:2: unknown light 'spot'"), std::string::npos)
            << e.what();
    }
    EXPECT_THROW(parse_lights("point 1 2\n", "l.txt"), Error);
    EXPECT_THROW(parse_lights("directional 0 0 0\n", "l.txt"), Error);
    EXPECT_THROW(parse_lights("point 1 2 3 -1\n", "l.txt"), Error);
    EXPECT_THROW(parse_lights("# nothing\n", "l.txt"), Error);
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
        load_lights(dir.path / "bad.lights");
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("bad.lights:2: malformed number 'x'"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_THROW(load_lights(dir.path / "missing.lights"), Error);
}

TEST(LightsFile, AFrameIsLitByItsLightsFileUnlessLightsAreGiven) {
    test_support::TempDir dir("frame_lights");
    const auto obj = dir.path / "keys_000030.obj";
    EXPECT_EQ(scene_lights_path(obj), dir.path / "keys_000030.lights");
    // No lights file: no lights (the renderer's default light).
    EXPECT_TRUE(frame_lights(obj, {}).empty());
    std::ofstream(dir.path / "keys_000030.lights")
        << "# toonray lights\ndirectional 0.5 -1 0 1    # sun 'Sun'\npoint 1 2 3 0.25\n";
    auto lights = frame_lights(obj, {});
    ASSERT_EQ(lights.size(), 2u);
    EXPECT_EQ(lights[0].kind, Light::Kind::Directional);
    EXPECT_EQ(lights[0].vector, Vec3f(0.5f, -1, 0));
    EXPECT_EQ(lights[1].intensity, 0.25f);
    // Lights given (--light, --lights) win; the file is not even read.
    std::ofstream(dir.path / "keys_000031.lights") << "spot 1 2 3\n";
    const std::vector<Light> given{parse_light("dir:0,0,-1")};
    lights = frame_lights(dir.path / "keys_000031.obj", given);
    ASSERT_EQ(lights.size(), 1u);
    EXPECT_EQ(lights[0].vector, Vec3f(0, 0, -1));
    try {
        frame_lights(dir.path / "keys_000031.obj", {});
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("keys_000031.lights:1: unknown light 'spot'"),
                  std::string::npos)
            << e.what();
    }
}
