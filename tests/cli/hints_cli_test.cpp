// The library says what went wrong; the command line adds which flag was at fault and which
// option gets past a limit.

#include <gtest/gtest.h>

#include <fstream>
#include <utility>

#include "cli/cli_test_util.h"

namespace fs = std::filesystem;

namespace {

const std::string kData = TOONRAY_TEST_DATA_DIR;

/// The "toonray: error: " line of `output`, without that prefix.
std::string error_line(const std::string& output) {
    const std::string prefix = "toonray: error: ";
    const std::size_t at = output.find(prefix);
    if (at == std::string::npos) return "(no error line)";
    const std::size_t end = output.find('\n', at);
    return output.substr(at + prefix.size(),
                         end == std::string::npos ? std::string::npos : end - at - prefix.size());
}

}  // namespace

TEST(HintsCli, BadOptionValuesNameTheirFlag) {
    TempDir dir("cli_hint_flags");
    const std::string render =
        "render " + kData + "/teapot.obj -o " + (dir / "o.png").string() + " --size 32x24";
    const std::pair<std::string, std::string> cases[] = {
        {render + " --ramp 0.2@x", "--ramp"},
        {render + " --ramp 0.5,1@0.6,0.2", "--ramp"},
        {render + " --light foo", "--light"},
        {render + " --light dir:0,0,0", "--light"},
        {render + " --camera 1,2", "--camera"},
        {render + " --lines outline", "--lines"},
        {render + " --background q", "--background"},
        {"batch keys 1 2 --shard 3/2 --input " + dir.path.string(), "--shard"},
    };
    for (const auto& [args, flag] : cases) {
        CommandResult r = run_toonray(args);
        EXPECT_EQ(r.exit_code, 1) << args << "\n" << r.output;
        const std::string error = error_line(r.output);
        EXPECT_EQ(error.rfind(flag, 0), 0u) << args << "\n" << r.output;
        EXPECT_EQ(error.find(flag, flag.size()), std::string::npos)
            << "flag named twice: " << error;
    }
    EXPECT_FALSE(fs::exists(dir / "o.png"));
    EXPECT_EQ(error_line(run_toonray(render + " --max-memory lots").output),
              "--max-memory: expected a positive size such as 512M or 8G, got 'lots'");
    EXPECT_EQ(error_line(run_toonray(render + " --max-vertices 0").output),
              "--max-vertices: expected a positive number such as 50000000 or 50M, got '0'");
}

TEST(HintsCli, LimitsNameOnlyTheOptionsOfTheCommand) {
    TempDir dir("cli_hint_limits");
    // `render` has no --jobs: only the limit helps.
    CommandResult r = run_toonray("render " + kData + "/teapot.obj -o " + (dir / "o.png").string() +
                                  " --size 640x480 --max-memory 1M");
    EXPECT_EQ(r.exit_code, 1);
    std::string error = error_line(r.output);
    EXPECT_EQ(error.rfind("a 640x480 frame needs about ", 0), 0u) << error;
    EXPECT_TRUE(
        error.ends_with(" of memory, more than the limit of 1.0 MiB (--max-memory raises it)"))
        << error;
    // `piano` has: its frames in flight can be fewer.
    r = run_toonray("piano -o " + (dir / "p").string() +
                    " --seconds 1 --size 1024x1024 --jobs 8 --max-memory 64M");
    EXPECT_EQ(r.exit_code, 1);
    error = error_line(r.output);
    EXPECT_EQ(error.rfind("8 frames at once", 0), 0u) << error;
    EXPECT_NE(error.find("(--max-memory raises it, or render fewer frames at once with --jobs)"),
              std::string::npos)
        << error;
    EXPECT_FALSE(fs::exists(dir / "o.png"));
}

TEST(HintsCli, FramesOverALimitSayHowToRaiseIt) {
    TempDir dir("cli_hint_frames");
    std::ifstream in(kData + "/teapot.obj");
    std::string teapot((std::istreambuf_iterator<char>(in)), {});
    fs::create_directories(dir / "in");
    dir.write("in/keys_000001.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    dir.write("in/keys_000002.obj", teapot);
    CommandResult r =
        run_toonray("batch keys 1 2 --input " + (dir / "in").string() + " --output " +
                    (dir / "png").string() + " --size 32x24 --quiet --max-triangles 100");
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find("frame 2 failed: " + (dir / "in" / "keys_000002.obj").string()),
              std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("--max-triangles raises it"), std::string::npos) << r.output;
    EXPECT_TRUE(fs::exists(dir / "png" / "keys_000001.png"));
}

TEST(HintsCli, MissingSoundFontSaysHowToChooseAnother) {
    TempDir dir("cli_hint_soundfont");
    const std::string soundfont = (dir / "gone.sf2").string();
    CommandResult r = run_toonray("piano -o " + (dir / "frames").string() +
                                  " --seconds 0.1 --size 32x24 --quiet --audio " +
                                  (dir / "a.wav").string() + " --soundfont " + soundfont);
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_EQ(error_line(r.output),
              soundfont + ": SoundFont not found; --soundfont chooses another");
    EXPECT_FALSE(fs::exists(dir / "a.wav"));
}
