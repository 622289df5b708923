// `--aov-exr` through the command line: one file for render, one a frame for batch (named like
// the PNGs, kept on --resume), and a clear error where the build has no OpenEXR.

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "cli_test_util.h"
#include "toonray/io/exr.h"

namespace fs = std::filesystem;

namespace {

const std::string kSpot = std::string(TOONRAY_TEST_DATA_DIR) + "/spot.obj";

}  // namespace

TEST(ExrCli, RenderWritesOneFile) {
    TempDir dir("cli_exr_render");
    const CommandResult r = run_toonray("render " + kSpot + " -o " + (dir / "f.png").string() +
                                        " --size 64x48 --aov-exr " + (dir / "aov/f.exr").string());
    if (toonray::exr_available()) {
        ASSERT_EQ(r.exit_code, 0) << r.output;
        EXPECT_GT(fs::file_size(dir / "aov/f.exr"), 1000u);
        EXPECT_TRUE(fs::exists(dir / "f.png"));
    } else {
        EXPECT_EQ(r.exit_code, 1) << r.output;
        EXPECT_NE(r.output.find("built without OpenEXR"), std::string::npos) << r.output;
        EXPECT_FALSE(fs::exists(dir / "f.png"));
    }
}

TEST(ExrCli, BatchWritesOneFileAFrameAndResumes) {
    TempDir dir("cli_exr_batch");
    fs::create_directories(dir / "in");
    for (int frame : {1, 2})
        fs::copy_file(kSpot, dir / ("in/keys_00000" + std::to_string(frame) + ".obj"));
    const std::string batch = "batch keys 1 2 --input " + (dir / "in").string() + " --output " +
                              (dir / "png").string() + " --size 48x36 --quiet --aov-exr ";
    // One .exr file cannot hold a sequence: refused before any frame.
    const CommandResult one = run_toonray(batch + (dir / "one.exr").string());
    EXPECT_EQ(one.exit_code, 1) << one.output;
    EXPECT_FALSE(fs::exists(dir / "png/keys_000001.png"));
    const CommandResult r = run_toonray(batch + (dir / "exr").string());
    if (!toonray::exr_available()) {
        EXPECT_NE(r.output.find("built without OpenEXR"), std::string::npos) << r.output;
        return;
    }
    EXPECT_NE(one.output.find("go to a directory"), std::string::npos) << one.output;
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_TRUE(fs::exists(dir / "exr/keys_000001.exr"));
    EXPECT_TRUE(fs::exists(dir / "exr/keys_000002.exr"));
    const auto written = fs::last_write_time(dir / "exr/keys_000001.exr");
    const CommandResult resumed = run_toonray(batch + (dir / "exr").string() + " --resume");
    ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
    EXPECT_EQ(fs::last_write_time(dir / "exr/keys_000001.exr"), written);
}
