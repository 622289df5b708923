#include <gtest/gtest.h>

#include <fstream>

#include "cli/cli_test_util.h"

namespace fs = std::filesystem;

namespace {

const std::string kSamples = std::string(TOONRAY_TEST_DATA_DIR) + "/gltf/";

std::string bytes_of(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}

TEST(GltfCli, RendersAFrameAtATime) {
    TempDir dir("gltf_cli");
    const std::string scene = kSamples + "BoxAnimated.gltf";
    const std::string common = " --size 96x72 --threads 1 -o ";
    auto a = run_toonray("render " + scene + " --frame 0" + common + (dir / "a.png").string());
    ASSERT_EQ(a.exit_code, 0) << a.output;
    auto b =
        run_toonray("render " + scene + " --frame 15 --fps 24" + common + (dir / "b.png").string());
    ASSERT_EQ(b.exit_code, 0) << b.output;
    auto c = run_toonray("render " + scene + " --time 0.625" + common + (dir / "c.png").string());
    ASSERT_EQ(c.exit_code, 0) << c.output;
    EXPECT_NE(bytes_of(dir / "a.png"), bytes_of(dir / "b.png"));
    EXPECT_EQ(bytes_of(dir / "b.png"), bytes_of(dir / "c.png"));  // frame 15 at 24 fps = 0.625 s

    auto wrong =
        run_toonray("render " + scene + " --animation walk" + common + (dir / "d.png").string());
    EXPECT_EQ(wrong.exit_code, 1);
    EXPECT_NE(wrong.output.find("BoxAnimated.gltf: no animation 'walk'"), std::string::npos)
        << wrong.output;
    auto obj = run_toonray("render " + std::string(TOONRAY_TEST_DATA_DIR) + "/spot.obj --time 1" +
                           common + (dir / "e.png").string());
    EXPECT_EQ(obj.exit_code, 1);
    EXPECT_NE(obj.output.find("need a glTF scene"), std::string::npos) << obj.output;
    EXPECT_FALSE(fs::exists(dir / "d.png") || fs::exists(dir / "e.png"));
}

TEST(GltfCli, BadFileIsAClearErrorAndWritesNothing) {
    TempDir dir("gltf_cli");
    std::string text = bytes_of(kSamples + "Box.gltf");
    const std::string count = "\"count\": 36";
    const auto at = text.find(count);
    ASSERT_NE(at, std::string::npos);
    text.replace(at, count.size(), "\"count\": 4294967295");
    const fs::path bad = dir.write("bad.gltf", text);
    auto r = run_toonray("render " + bad.string() + " --size 64x48 -o " + (dir / "x.png").string());
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.output.find("bad.gltf: accessors[0].count: 4294967295 exceeds the buffer view"),
              std::string::npos)
        << r.output;
    EXPECT_FALSE(fs::exists(dir / "x.png"));
}

TEST(GltfCli, BatchRendersTheAnimationTheSameForAnyJobs) {
    TempDir dir("gltf_cli");
    const std::string scene = kSamples + "RiggedSimple.gltf";
    for (const char* jobs : {"1", "2"}) {
        auto r = run_toonray("batch " + scene + " 0 5 --fps 4 --size 64x48 --quiet --jobs " + jobs +
                             " --output " + (dir / jobs).string());
        ASSERT_EQ(r.exit_code, 0) << r.output;
    }
    for (int f = 0; f <= 5; ++f) {
        char name[64];
        std::snprintf(name, sizeof name, "RiggedSimple_%06d.png", f);
        ASSERT_TRUE(fs::exists(dir / "1" / name)) << name;
        EXPECT_EQ(bytes_of(dir / "1" / name), bytes_of(dir / "2" / name)) << name;
    }
    EXPECT_NE(bytes_of(dir / "1" / "RiggedSimple_000000.png"),
              bytes_of(dir / "1" / "RiggedSimple_000002.png"));
}

}  // namespace

TEST(GltfCli, InstancesRenderWithTheirNamesInTheSvg) {
    // instances.gltf: a ball mesh on seven placements, a box mesh on three nodes.
    TempDir dir("gltf_cli");
    const std::string scene = kSamples + "instances.gltf";
    auto r = run_toonray("render " + scene + " --size 160x90 --threads 2 --shadows -o " +
                         (dir / "a.png").string() + " --line-style " +
                         dir.write("red.style", "match object=box.c color=#ff0000\n").string() +
                         " --svg " + (dir / "a.svg").string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const std::string svg = bytes_of(dir / "a.svg");
    EXPECT_NE(svg.find("#ff0000"), std::string::npos);  // box.c's strokes, styled by its name
    // The same frame on one thread.
    auto one =
        run_toonray("render " + scene + " --size 160x90 --threads 1 --shadows -o " +
                    (dir / "b.png").string() + " --line-style " + (dir / "red.style").string());
    ASSERT_EQ(one.exit_code, 0) << one.output;
    EXPECT_EQ(bytes_of(dir / "a.png"), bytes_of(dir / "b.png"));
}
