#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <chrono>
#include <fstream>
#include <thread>

#include "cli/cli_test_util.h"
#include "toonray/io/png.h"

namespace fs = std::filesystem;
extern char** environ;

namespace {

// Frames that differ by camera position; each a copy of the teapot with a camera block.
void write_frames(const TempDir& dir, int count) {
    std::ifstream in(std::string(TOONRAY_TEST_DATA_DIR) + "/teapot.obj");
    std::string teapot((std::istreambuf_iterator<char>(in)), {});
    fs::create_directories(dir.path / "in");
    for (int f = 1; f <= count; ++f) {
        char name[64];
        std::snprintf(name, sizeof name, "in/keys_%06d.obj", f);
        float x = 0.02f * f;
        std::string camera = "v " + std::to_string(x) + " 2 8\nv " + std::to_string(x) +
                             " 1.8 7\nvn 0 1 0\nc -2 -1 -1\n";
        dir.write(name, teapot + camera);
    }
}

int count_files(const fs::path& dir, const std::string& needle) {
    int n = 0;
    for (auto& e : fs::directory_iterator(dir))
        if (e.path().filename().string().find(needle) != std::string::npos) ++n;
    return n;
}

}  // namespace

TEST(BatchCli, RendersASequenceAndReportsFailuresWithExitCode) {
    TempDir dir("cli_batch");
    write_frames(dir, 4);
    dir.write("in/keys_000003.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n");
    CommandResult r = run_toonray("batch keys 1 4 --input " + (dir / "in").string() + " --output " +
                                  (dir / "png").string() + " --size 160x90 --quiet");
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find("frame 3 failed"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("keys_000003.obj:4: face vertex index 0"), std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("3 rendered, 0 skipped, 1 failed of 4 frames"), std::string::npos)
        << r.output;
    EXPECT_EQ(count_files(dir / "png", ".png"), 3);
}

TEST(BatchCli, SvgPerFrameNamedLikeItsPngAndResumable) {
    TempDir dir("cli_batch_svg");
    write_frames(dir, 3);
    const std::string command = "batch keys 1 3 --input " + (dir / "in").string() + " --output " +
                                (dir / "png").string() + " --svg " + (dir / "svg").string() +
                                " --size 96x54";
    CommandResult r = run_toonray(command + " --quiet");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(count_files(dir / "svg", ".svg"), 3);
    for (const char* name : {"keys_000001.svg", "keys_000002.svg", "keys_000003.svg"})
        EXPECT_TRUE(fs::exists(dir / "svg" / name)) << name;
    // A frame counts as done only with both its PNG and its SVG: resume renders just frame 2.
    fs::remove(dir / "svg" / "keys_000002.svg");
    r = run_toonray(command + " --resume");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("1 rendered, 2 skipped, 0 failed of 3 frames"), std::string::npos)
        << r.output;
    EXPECT_TRUE(fs::exists(dir / "svg" / "keys_000002.svg"));
}

TEST(BatchCli, ShardsTogetherRenderEveryFrameOnce) {
    TempDir dir("cli_shard");
    write_frames(dir, 7);
    for (int k = 1; k <= 3; ++k) {
        CommandResult r = run_toonray("batch keys 1 7 --input " + (dir / "in").string() +
                                      " --output " + (dir / "png").string() +
                                      " --size 64x36 --quiet --shard " + std::to_string(k) + "/3");
        ASSERT_EQ(r.exit_code, 0) << r.output;
    }
    EXPECT_EQ(count_files(dir / "png", ".png"), 7);
    CommandResult env =
        run_toonray("batch keys 1 7 --input " + (dir / "in").string() + " --output " +
                    (dir / "png2").string() + " --size 64x36 --quiet");
    ASSERT_EQ(env.exit_code, 0);
    // Slurm variables pick the shard when --shard is absent.
    std::string cmd = std::string("env SLURM_ARRAY_TASK_ID=2 SLURM_ARRAY_TASK_COUNT=3 ") +
                      TOONRAY_CLI + " batch keys 1 7 --input " + (dir / "in").string() +
                      " --output " + (dir / "png3").string() + " --size 64x36 --quiet";
    ASSERT_EQ(std::system(cmd.c_str()), 0);
    EXPECT_EQ(count_files(dir / "png3", ".png"), 2);  // frames 2 and 5
    EXPECT_TRUE(fs::exists(dir / "png3/keys_000005.png"));
}

TEST(BatchCli, ProgressLinesWhenNotATerminal) {
    TempDir dir("cli_progress");
    write_frames(dir, 2);
    CommandResult r = run_toonray("batch keys 1 2 --input " + (dir / "in").string() + " --output " +
                                  (dir / "png").string() + " --size 64x36");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("2/2 frames"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("\r"), std::string::npos) << "no bar redraws in a log";
}

TEST(BatchCli, InterruptStopsCleanlyAndResumeCompletes) {
    TempDir dir("cli_interrupt");
    const int frames = 150;
    write_frames(dir, frames);
    std::string in = (dir / "in").string(), out = (dir / "png").string();
    std::vector<std::string> args = {
        TOONRAY_CLI, "batch",   "keys",     "1", std::to_string(frames),
        "--input",   in,        "--output", out, "--size",
        "640x360",   "--quiet", "--jobs",   "2"};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    pid_t pid;
    ASSERT_EQ(posix_spawn(&pid, TOONRAY_CLI, nullptr, nullptr, argv.data(), environ), 0);
    // Wait until some frames exist, then interrupt.
    for (int i = 0; i < 500 && (!fs::exists(out) || count_files(out, ".png") < 5); ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    ::kill(pid, SIGINT);
    int status = 0;
    ::waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFEXITED(status));
    int done = count_files(out, ".png");
    EXPECT_EQ(WEXITSTATUS(status), 130);
    EXPECT_GE(done, 5);
    EXPECT_LT(done, frames) << "the run should have been stopped early";
    EXPECT_EQ(count_files(out, ".tmp"), 0) << "no partial files";
    for (auto& e : fs::directory_iterator(out))
        EXPECT_TRUE(toonray::is_valid_png(e.path())) << e.path();
    CommandResult r = run_toonray("batch keys 1 " + std::to_string(frames) + " --input " + in +
                                  " --output " + out + " --size 640x360 --quiet --resume");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(count_files(out, ".png"), frames);
}

TEST(BatchCli, RangeErrors) {
    CommandResult r = run_toonray("batch keys 5 4 --quiet");
    EXPECT_NE(r.exit_code, 0);
    EXPECT_NE(r.output.find("first frame is after the last"), std::string::npos) << r.output;
}

TEST(BatchCli, EachFrameIsLitByItsOwnLightsFile) {
    TempDir dir("cli_batch_lights");
    write_frames(dir, 2);
    dir.write("in/keys_000001.lights", "directional 1 -1 -0.5\n");
    dir.write("in/keys_000002.lights", "directional -1 -1 -0.5\n");
    const std::string common = " --size 160x90 --edges classic --quiet --auto-smooth 30";
    CommandResult r = run_toonray("batch keys 1 2 --input " + (dir / "in").string() + " --output " +
                                  (dir / "png").string() + common);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    for (auto [frame, light] : {std::pair{1, "dir:1,-1,-0.5"}, std::pair{2, "dir:-1,-1,-0.5"}}) {
        const std::string name = "keys_00000" + std::to_string(frame);
        r = run_toonray("render " + (dir / "in" / (name + ".obj")).string() + " -o " +
                        (dir / (name + ".png")).string() + " --light " + light +
                        " --size 160x90 --edges classic --auto-smooth 30");
        ASSERT_EQ(r.exit_code, 0) << r.output;
        EXPECT_EQ(png_pixels(dir / "png" / (name + ".png")), png_pixels(dir / (name + ".png")))
            << "frame " << frame;
    }
}
