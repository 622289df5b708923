#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

#include "cli/cli_test_util.h"
#include "toonray/core/image.h"
#include "toonray/io/file.h"
#include "toonray/io/png.h"

namespace fs = std::filesystem;
using toonray::read_file;
using toonray::read_png;

namespace {
const std::string kData = TOONRAY_TEST_DATA_DIR;
}

TEST(RenderCli, HelpDocumentsEveryOptionAndItsDefault) {
    CommandResult r = run_toonray("render --help");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    for (const char* opt : {"--output", "--size", "--light", "--camera", "--background", "--edges",
                            "--depth-threshold", "--normal-threshold", "--aov", "--threads",
                            "--bvh-leaf-size", "--png-level"})
        EXPECT_NE(r.output.find(opt), std::string::npos) << opt;
    for (const char* opt :
         {"--lines", "--crease-angle", "--depth-step", "--line-width", "--line-color", "--samples"})
        EXPECT_NE(r.output.find(opt), std::string::npos) << opt;
    for (const char* def : {"1280x720", "=ink", "classic", "=8", "=4"})
        EXPECT_NE(r.output.find(def), std::string::npos) << def << "\n" << r.output;
}

TEST(RenderCli, RendersTheTeapotAtTheDefaultSize) {
    TempDir dir("cli_render");
    CommandResult r = run_toonray("render " + kData + "/teapot.obj -o " + (dir / "t.png").string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    auto png = read_png(dir / "t.png");
    EXPECT_EQ(png.width, 1280);
    EXPECT_EQ(png.height, 720);
}

TEST(RenderCli, SizeLightThresholdsAndAovs) {
    TempDir dir("cli_opts");
    CommandResult r =
        run_toonray("render " + kData + "/teapot.obj -o " + (dir / "f.png").string() +
                    " --size 320x200 --light 4,6,10 --aov " + (dir / "aov").string() +
                    " --depth-threshold 8 --normal-threshold 4 --edges classic --threads 2");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(read_png(dir / "f.png").width, 320);
    for (const char* name : {"depth", "normal", "edges_depth", "edges_normal", "edges", "cel"})
        EXPECT_TRUE(fs::exists(dir / "aov" / (std::string("f_") + name + ".png"))) << name;
}

TEST(RenderCli, BadSceneIsAnErrorWithFileAndLineAndNoOutput) {
    TempDir dir("cli_bad");
    dir.write("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
    CommandResult r =
        run_toonray("render " + (dir / "bad.obj").string() + " -o " + (dir / "out.png").string());
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.output.find("bad.obj:4: face vertex index 4 out of range"), std::string::npos)
        << r.output;
    EXPECT_FALSE(fs::exists(dir / "out.png"));
}

TEST(RenderCli, BadCameraIsAnErrorAndNoOutput) {
    TempDir dir("cli_cam");
    CommandResult r = run_toonray("render " + kData + "/teapot.obj -o " +
                                  (dir / "out.png").string() + " --camera 0,0,5,0,0,5,0,1,0");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.output.find("eye and gaze point are the same"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "out.png"));
}

TEST(RenderCli, BadOptionValuesAreRejected) {
    TempDir dir("cli_opt");
    std::string base = "render " + kData + "/teapot.obj -o " + (dir / "o.png").string();
    for (const char* bad : {" --size 0x10", " --light 1,2", " --edges fancy", " --threads -1",
                            " --background 2,0,0"}) {
        CommandResult r = run_toonray(base + bad);
        EXPECT_NE(r.exit_code, 0) << bad;
        EXPECT_FALSE(fs::exists(dir / "o.png")) << bad;
    }
    EXPECT_NE(run_toonray("render /nonexistent.obj -o x.png").exit_code, 0);
}

TEST(RenderCli, MissingMaterialLibraryWarnsAndRenders) {
    TempDir dir("cli_warn");
    dir.write("s.obj", "mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n");
    CommandResult r = run_toonray("render " + (dir / "s.obj").string() + " -o " +
                                  (dir / "o.png").string() + " --size 64x64");
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("warning"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("gone.mtl"), std::string::npos) << r.output;
    EXPECT_TRUE(fs::exists(dir / "o.png"));
}

TEST(RenderCli, UnwritableOutputIsAnError) {
    CommandResult r =
        run_toonray("render " + kData + "/teapot.obj -o /nonexistent-dir/o.png --size 32x32");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.output.find("/nonexistent-dir/o.png"), std::string::npos) << r.output;
}

TEST(RenderCli, ToonShadingOptions) {
    TempDir dir("cli_shading");
    std::string base = "render " + kData + "/teapot.obj --size 160x90 -o ";
    CommandResult r = run_toonray(
        base + (dir / "a.png").string() +
        " --ramp 0.3,0.6,0.9,1@0.2,0.4,0.7 --light dir:-1,-1,-1 --light 3,4,5@0.5"
        " --shadows --specular --rim 0.3 --samples 9 --line-width 3 --line-color '#402010'"
        " --lines silhouette,crease --crease-angle 60");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_TRUE(fs::exists(dir / "a.png"));
    dir.write("lights.txt", "point 1 2 3\nsun 1 2 3\n");
    r = run_toonray(base + (dir / "b.png").string() + " --lights " + (dir / "lights.txt").string());
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.output.find("lights.txt:2: unknown light 'sun'"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "b.png"));
    for (const char* bad : {" --ramp 1,2", " --lines outline", " --samples 3", " --rim 1.5"}) {
        r = run_toonray(base + (dir / "c.png").string() + bad);
        EXPECT_NE(r.exit_code, 0) << bad;
    }
}

TEST(RenderCli, TexturedObjRendersItsTextureAndAMissingOneWarns) {
    TempDir dir("cli_texture");
    toonray::ImageRgb8 tex(8, 8, toonray::Rgb8{0, 200, 0});
    toonray::write_png(dir / "green.png", tex);
    dir.write(
        "t.mtl",
        "newmtl tex\nKd 1 1 1\nmap_Kd green.png\nnewmtl gone\nKd 0.5 0.5 0.5\nmap_Kd nothere.png\n");
    dir.write(
        "t.obj",
        "mtllib t.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
        "usemtl tex\nf 1/1 2/2 3/3\nusemtl gone\nf 1/1 3/3 4/4\n");
    CommandResult r =
        run_toonray("render " + (dir / "t.obj").string() + " -o " + (dir / "t.png").string() +
                    " --size 64x64 --camera 0,0,3,0,0,2,0,1,0 --light 0,0,10 --lines none");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("nothere.png"), std::string::npos) << r.output;
    auto png = toonray::read_png(dir / "t.png");
    EXPECT_EQ(png.rgb(40, 40), (toonray::Rgb8{0, 200, 0}));  // the textured triangle (lower right)
    EXPECT_EQ(png.rgb(22, 22), (toonray::Rgb8{128, 128, 128}));  // the other keeps its Kd
}

TEST(RenderCli, InkLinesWithSvg) {
    TempDir dir("cli_ink");
    CommandResult r = run_toonray("render " + kData + "/teapot.obj -o " + (dir / "t.png").string() +
                                  " --size 320x180 --edges ink --svg " + (dir / "t.svg").string() +
                                  " --svg-hidden --aov " + (dir / "aov").string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(read_png(dir / "t.png").width, 320);
    EXPECT_TRUE(fs::exists(dir / "t.svg"));
    EXPECT_TRUE(fs::exists(dir / "aov" / "t_edges.png"));
    EXPECT_FALSE(fs::exists(dir / "aov" / "t_lines_depth.png"));
    // Any line mode writes the ink lines' SVG; --hidden-lines is the option's other name.
    r = run_toonray("render " + kData + "/teapot.obj -o " + (dir / "u.png").string() +
                    " --size 320x180 --edges classic --hidden-lines --svg " +
                    (dir / "u.svg").string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(read_file(dir / "u.svg").find("<g id=\"hidden\""), std::string::npos);
    r = run_toonray("render " + kData + "/teapot.obj -o " + (dir / "v.png").string() +
                    " --hidden-lines");
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.output.find("--hidden-lines needs --svg"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "v.png"));
}

TEST(RenderCli, LineStyles) {
    TempDir dir("cli_line_style");
    dir.write("dashed.style",
              "# every line red and dashed, hidden ones too\n"
              "match lines=all draw=yes color=#ff0000 dash=6,4 opacity=0.5\n");
    CommandResult r =
        run_toonray("render " + kData + "/teapot.obj -o " + (dir / "t.png").string() +
                    " --size 320x180 --edges ink --line-style " + (dir / "dashed.style").string() +
                    " --svg " + (dir / "t.svg").string() + " --hidden-lines");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const std::string svg = read_file(dir / "t.svg");
    EXPECT_NE(
        svg.find("stroke=\"#ff0000\" stroke-opacity=\"0.500\" stroke-dasharray=\"1.500,1.000\""),
        std::string::npos);
    // The lines are red now, never black.
    const auto png = read_png(dir / "t.png");
    int red = 0, black = 0;
    for (int y = 0; y < png.height; ++y)
        for (int x = 0; x < png.width; ++x) {
            const auto c = png.rgb(x, y);
            red += c[0] > 200 && c[1] < 190 && c[2] < 190;
            black += c[0] < 40 && c[1] < 40 && c[2] < 40;
        }
    EXPECT_GT(red, 200);
    EXPECT_EQ(black, 0);
    // A bad rule names the file and line; nothing is written.
    dir.write("bad.style", "match color=#ff0000\nmatch width=wide\n");
    r = run_toonray("render " + kData + "/teapot.obj -o " + (dir / "u.png").string() +
                    " --edges ink --line-style " + (dir / "bad.style").string());
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.output.find("bad.style:2: width: expected a number, got 'wide'"), std::string::npos)
        << r.output;
    EXPECT_FALSE(fs::exists(dir / "u.png"));
}

// The ink lines are the default line mode: no --edges draws what --edges ink draws, and
// writes an SVG.
TEST(RenderCli, InkLinesAreTheDefault) {
    TempDir dir("cli_default_lines");
    auto bytes = [](const fs::path& path) {
        std::ifstream in(path, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    const std::string scene = "render " + kData + "/teapot.obj --size 320x180 -o ";
    CommandResult r = run_toonray(scene + (dir / "default.png").string() + " --svg " +
                                  (dir / "default.svg").string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    r = run_toonray(scene + (dir / "ink.png").string() + " --edges ink");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    r = run_toonray(scene + (dir / "robust.png").string() + " --edges robust");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_FALSE(bytes(dir / "default.png").empty());
    EXPECT_EQ(bytes(dir / "default.png"), bytes(dir / "ink.png"));
    EXPECT_NE(bytes(dir / "default.png"), bytes(dir / "robust.png"));
    EXPECT_TRUE(fs::exists(dir / "default.svg"));
}


TEST(RenderCli, TheScenesLightsFileLightsItUnlessLightsAreGiven) {
    TempDir dir("cli_scene_lights");
    fs::copy_file(kData + "/teapot.obj", dir / "pot.obj");
    const std::string common = " --size 160x100 --edges classic --threads 2";
    auto render = [&](const std::string& out, const std::string& extra) {
        CommandResult r = run_toonray("render " + (dir / "pot.obj").string() + " -o " +
                                      (dir / out).string() + common + extra);
        EXPECT_EQ(r.exit_code, 0) << r.output;
        return png_pixels(dir / out);
    };
    const std::string plain = render("default.png", "");
    const std::string given = render("given.png", " --light dir:1,-1,-0.5");
    ASSERT_NE(plain, given);
    dir.write("pot.lights", "# from the exporter\ndirectional 1 -1 -0.5 1   # sun\n");
    EXPECT_EQ(render("file.png", ""), given);  // read with no option
    // The command line wins over the file.
    const std::string overridden = render("override.png", " --light dir:0,0,-1");
    EXPECT_NE(overridden, given);
    fs::remove(dir / "pot.lights");
    EXPECT_EQ(render("explicit.png", " --light dir:0,0,-1"), overridden);
    dir.write("pot.lights", "directional 1 -1 -0.5\npoint 1 2\n");
    CommandResult r = run_toonray("render " + (dir / "pot.obj").string() + " -o " +
                                  (dir / "bad.png").string() + common);
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.output.find("pot.lights:2: expected x y z [intensity]"), std::string::npos)
        << r.output;
    EXPECT_FALSE(fs::exists(dir / "bad.png"));
}

TEST(RenderCli, AutoSmoothChangesOnlyMeshesWithoutNormalsAndChecksTheAngle) {
    TempDir dir("cli_auto_smooth");
    const std::string common = " --size 160x100 --threads 2";
    auto render = [&](const std::string& out, const std::string& extra) {
        CommandResult r = run_toonray("render " + kData + "/teapot.obj -o " + (dir / out).string() +
                                      common + extra);
        EXPECT_EQ(r.exit_code, 0) << r.output;
        return png_pixels(dir / out);
    };
    const std::string flat = render("flat.png", "");
    const std::string smooth = render("smooth.png", " --auto-smooth 30");
    EXPECT_NE(flat, smooth);
    EXPECT_EQ(render("smooth2.png", " --auto-smooth 30"), smooth);
    CommandResult r = run_toonray("render " + kData + "/teapot.obj -o " +
                                  (dir / "bad.png").string() + " --auto-smooth 200");
    EXPECT_NE(r.exit_code, 0);
    EXPECT_NE(r.output.find("--auto-smooth"), std::string::npos) << r.output;
}
