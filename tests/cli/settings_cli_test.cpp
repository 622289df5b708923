// The settings document on the command line: `toonray settings` prints it, `--settings FILE`
// reads it back on render, batch, piano and demo, options given override its keys, and every
// output records it.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "cli/cli_test_util.h"
#include "scene/gltf_test_files.h"
#include "toonray/io/exr.h"
#include "toonray/io/file.h"

namespace fs = std::filesystem;

namespace {

const std::string kData = TOONRAY_TEST_DATA_DIR;

std::string bytes_of(const fs::path& path) { return toonray::read_file(path); }

// Prints the settings of `options` into `file`.
void write_settings(const fs::path& file, const std::string& options) {
    const CommandResult r = run_toonray("settings" + options);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    std::ofstream(file) << r.output;
}

// A glTF sphere of 16 x 8 quads without normals (auto-smooth makes it round), with an animated
// translation so that frames differ.
std::string sphere_gltf() {
    using namespace toonray::gltf_test;
    std::vector<std::uint8_t> bin;
    const int cols = 16, rows = 8;
    for (int j = 0; j <= rows; ++j)
        for (int i = 0; i <= cols; ++i) {
            const float t = 3.14159265f * static_cast<float>(j) / rows,
                        p = 2.0f * 3.14159265f * static_cast<float>(i) / cols;
            put<float>(bin, {std::sin(t) * std::cos(p), std::cos(t), std::sin(t) * std::sin(p)});
        }
    const std::size_t positions = bin.size();
    for (int j = 0; j < rows; ++j)
        for (int i = 0; i < cols; ++i) {
            const int a = j * (cols + 1) + i, b = a + 1, c = a + cols + 1, d = c + 1;
            for (int v : {a, c, b, b, c, d})
                put<std::uint16_t>(bin, {static_cast<std::uint16_t>(v)});
        }
    const std::size_t indices = bin.size() - positions;
    put<float>(bin, {0.0f, 1.0f});
    put<float>(bin, {0, 0, 0, 0.5f, 0, 0});
    const std::string count = std::to_string((cols + 1) * (rows + 1));
    return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],
"nodes":[{"mesh":0}],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],
"animations":[{"channels":[{"sampler":0,"target":{"node":0,"path":"translation"}}],
"samplers":[{"input":2,"output":3}]}],
"accessors":[
{"bufferView":0,"componentType":5126,"count":)" +
           count + R"(,"type":"VEC3","min":[-1,-1,-1],"max":[1,1,1]},
{"bufferView":1,"componentType":5123,"count":)" +
           std::to_string(indices / 2) + R"(,"type":"SCALAR"},
{"bufferView":2,"componentType":5126,"count":2,"type":"SCALAR","min":[0],"max":[1]},
{"bufferView":3,"componentType":5126,"count":2,"type":"VEC3"}],
"bufferViews":[{"buffer":0,"byteLength":)" +
           std::to_string(positions) + R"(},
{"buffer":0,"byteOffset":)" +
           std::to_string(positions) + R"(,"byteLength":)" + std::to_string(indices) + R"(},
{"buffer":0,"byteOffset":)" +
           std::to_string(positions + indices) +
           R"(,"byteLength":8},
{"buffer":0,"byteOffset":)" +
           std::to_string(positions + indices + 8) +
           R"(,"byteLength":24}],
"buffers":[{"byteLength":)" +
           std::to_string(bin.size()) + R"(,"uri":")" + data_uri(bin) + R"("}]})";
}

}  // namespace

// Rendering with the printed settings gives the same files, byte for byte, as the options did:
// spot with many keys changed, a glTF frame, and piano frames.
TEST(SettingsCli, RenderingWithThePrintedSettingsGivesByteIdenticalFrames) {
    TempDir dir("cli_settings_round");
    const std::string options =
        " --size 200x120 --shadows --specular --rim 0.2 --light dir:-1,-1,-1 --light 3,4,5@0.5"
        " --line-width 3 --line-color '#402010' --lines silhouette,crease --crease-angle 50"
        " --samples 9 --ramp 0.3,0.6,0.9,1@0.2,0.4,0.7 --line-taper 4 --auto-smooth 30";
    write_settings(dir / "spot.toml", options);
    for (const char* mode : {"ink", "robust", "classic"}) {
        const std::string edges = std::string(" --edges ") + mode;
        CommandResult r =
            run_toonray("render " + kData + "/spot.obj -o " + (dir / "a.png").string() + options +
                        edges + " --svg " + (dir / "a.svg").string());
        ASSERT_EQ(r.exit_code, 0) << r.output;
        r = run_toonray("render " + kData + "/spot.obj -o " + (dir / "b.png").string() +
                        " --settings " + (dir / "spot.toml").string() + edges + " --svg " +
                        (dir / "b.svg").string());
        ASSERT_EQ(r.exit_code, 0) << r.output;
        EXPECT_EQ(bytes_of(dir / "a.png"), bytes_of(dir / "b.png")) << mode;
        EXPECT_EQ(bytes_of(dir / "a.svg"), bytes_of(dir / "b.svg")) << mode;
    }

    const fs::path gltf = dir.write("ball.gltf", sphere_gltf());
    write_settings(dir / "ball.toml", " --size 160x120 --auto-smooth 40 --edges robust");
    ASSERT_EQ(
        run_toonray("render " + gltf.string() + " --time 0.5 -o " + (dir / "g1.png").string() +
                    " --size 160x120 --auto-smooth 40 --edges robust")
            .exit_code,
        0);
    ASSERT_EQ(run_toonray("render " + gltf.string() + " --time 0.5 -o " +
                          (dir / "g2.png").string() + " --settings " + (dir / "ball.toml").string())
                  .exit_code,
              0);
    EXPECT_EQ(bytes_of(dir / "g1.png"), bytes_of(dir / "g2.png"));

    const std::string piano = " --start 30 --seconds 0.09 --jobs 1 --quiet";
    write_settings(dir / "piano.toml", " --size 320x180 --edges classic --shadows");
    ASSERT_EQ(run_toonray("piano -o " + (dir / "p1").string() + piano +
                          " --size 320x180 --edges classic --shadows")
                  .exit_code,
              0);
    ASSERT_EQ(run_toonray("piano -o " + (dir / "p2").string() + piano + " --settings " +
                          (dir / "piano.toml").string())
                  .exit_code,
              0);
    for (const char* frame : {"keys_000001.png", "keys_000002.png", "keys_000003.png"})
        EXPECT_EQ(bytes_of(dir / "p1" / frame), bytes_of(dir / "p2" / frame)) << frame;
}

TEST(SettingsCli, OptionsGivenOverrideTheDocument) {
    TempDir dir("cli_settings_override");
    dir.write("s.toml", "[image]\nsize = \"64x48\"\n[lines]\nmode = \"classic\"\nwidth = 5\n");
    CommandResult r = run_toonray("settings --settings " + (dir / "s.toml").string() +
                                  " --line-width 2.5 --samples 9");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("size = \"64x48\""), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("mode = \"classic\""), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("width = 2.5"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("samples = 9"), std::string::npos) << r.output;
    // The document's own errors name it, the line and the key; nothing is written.
    dir.write("bad.toml", "[lines]\nwidth = \"wide\"\n");
    r = run_toonray("render " + kData + "/teapot.obj -o " + (dir / "o.png").string() +
                    " --settings " + (dir / "bad.toml").string());
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.output.find("bad.toml:2:9: lines.width: expected a number, got 'wide'"),
              std::string::npos)
        << r.output;
    EXPECT_FALSE(fs::exists(dir / "o.png"));
    // --settings on batch, piano and demo too.
    for (const char* command : {"batch keys 1 1", "piano", "demo"}) {
        r = run_toonray(std::string(command) + " --settings " + (dir / "bad.toml").string() +
                        " -o " + (dir / "out").string());
        EXPECT_EQ(r.exit_code, 1) << command;
        EXPECT_NE(r.output.find("bad.toml:2:9"), std::string::npos) << command << r.output;
    }
}

TEST(SettingsCli, EveryOutputRecordsTheVersionAndTheSettings) {
    TempDir dir("cli_settings_record");
    // Builds without OpenEXR (the aarch64 one) refuse --aov-exr; they record in the others.
    const bool exr = toonray::exr_available();
    CommandResult r = run_toonray("render " + kData + "/teapot.obj -o " + (dir / "f.png").string() +
                                  " --size 96x64 --shadows --aov " + (dir / "aov").string() +
                                  (exr ? " --aov-exr " + (dir / "f.exr").string() : std::string()) +
                                  " --svg " + (dir / "f.svg").string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const std::string version = run_toonray("--version").output;
    ASSERT_EQ(version.rfind("toonray ", 0), 0u) << version;
    const std::string software = version.substr(0, version.find('\n'));
    for (const fs::path& png : {dir / "f.png", dir / "aov" / "f_depth.png"}) {
        const std::string bytes = bytes_of(png);
        EXPECT_NE(bytes.find("tEXtSoftware" + std::string(1, '\0') + software), std::string::npos)
            << png;
        EXPECT_NE(bytes.find("tEXttoonray settings"), std::string::npos) << png;
        EXPECT_NE(bytes.find("shadows = true"), std::string::npos) << png;
    }
    const std::string svg = bytes_of(dir / "f.svg");
    EXPECT_NE(svg.find("<metadata id=\"toonray\" data-software=\"" + software + "\">"),
              std::string::npos)
        << svg.substr(0, 400);
    EXPECT_NE(svg.find("shadows = true"), std::string::npos);
    if (!exr) return;
    // The EXR's header, as a second reader (OpenImageIO) sees it.
    FILE* pipe = ::popen(("oiiotool --info -v " + (dir / "f.exr").string() + " 2>&1").c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    std::string info;
    char buffer[4096];
    while (std::size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) info.append(buffer, n);
    ASSERT_EQ(::pclose(pipe), 0) << info;
    EXPECT_NE(info.find("toonraySettings"), std::string::npos) << info;
    EXPECT_NE(info.find(software), std::string::npos) << info;
}

TEST(SettingsCli, InkLinesRefuseDepthLinesAskedByName) {
    TempDir dir("cli_ink_depth");
    const CommandResult r = run_toonray("render " + kData + "/teapot.obj -o " +
                                        (dir / "o.png").string() + " --edges ink --lines depth");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.output.find("--lines: lines.types: the ink mode finds no depth lines"),
              std::string::npos)
        << r.output;
    EXPECT_FALSE(fs::exists(dir / "o.png"));
    EXPECT_EQ(run_toonray("render " + kData + "/teapot.obj -o " + (dir / "o.png").string() +
                          " --size 32x32 --edges robust --lines depth")
                  .exit_code,
              0);
}

// Before, batch accepted --auto-smooth for a glTF scene and ignored it.
TEST(SettingsCli, BatchSmoothsAGltfSceneAsRenderDoes) {
    TempDir dir("cli_gltf_smooth");
    const fs::path gltf = dir.write("ball.gltf", sphere_gltf());
    const std::string common = " --size 160x120 --edges classic --auto-smooth 30";
    ASSERT_EQ(run_toonray("render " + gltf.string() + " --frame 12 -o " +
                          (dir / "render.png").string() + common)
                  .exit_code,
              0);
    ASSERT_EQ(run_toonray("render " + gltf.string() + " --frame 12 -o " +
                          (dir / "flat.png").string() + " --size 160x120 --edges classic")
                  .exit_code,
              0);
    const CommandResult r =
        run_toonray("batch " + gltf.string() + " 12 12 -q -o " + (dir / "b").string() + common);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(png_pixels(dir / "render.png"), png_pixels(dir / "flat.png"))
        << "auto-smooth changes nothing here: the test scene needs curved faces without normals";
    EXPECT_EQ(bytes_of(dir / "b" / "ball_000012.png"), bytes_of(dir / "render.png"));
}
