#include <gtest/gtest.h>

#include "cli/cli_test_util.h"

namespace fs = std::filesystem;

TEST(EncodeCli, RendersThenEncodesAProbedMp4) {
    TempDir dir("cli_encode");
    fs::create_directories(dir / "in");
    // Six frames of the teapot from a moving camera.
    std::ifstream in(std::string(TOONRAY_TEST_DATA_DIR) + "/teapot.obj");
    std::string teapot((std::istreambuf_iterator<char>(in)), {});
    for (int f = 1; f <= 6; ++f)
        dir.write("in/keys_" + std::to_string(f) + ".obj",
                  teapot + "v " + std::to_string(0.1 * f) + " 2 8\nv " + std::to_string(0.1 * f) +
                      " 1.8 7\nvn 0 1 0\nc -2 -1 -1\n");
    CommandResult r = run_toonray("batch keys 1 6 -i " + (dir / "in").string() + " -o " +
                                  (dir / "png").string() + " --size 96x64 --quiet");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    r = run_toonray("encode " + (dir / "png").string() + " -o " + (dir / "keys.mp4").string() +
                    " --fps 24");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    std::string probe =
        "ffprobe -v error -count_frames -show_entries stream=codec_name,nb_read_frames,pix_fmt -of csv=p=0 " +
        (dir / "keys.mp4").string() + " > " + (dir / "probe.txt").string();
    ASSERT_EQ(std::system(probe.c_str()), 0);
    std::ifstream p(dir / "probe.txt");
    std::string line;
    std::getline(p, line);
    EXPECT_EQ(line, "h264,yuv420p,6");
}

TEST(EncodeCli, GapInTheSequenceIsAnError) {
    TempDir dir("cli_gap");
    fs::create_directories(dir / "png");
    CommandResult r =
        run_toonray("render " + std::string(TOONRAY_TEST_DATA_DIR) + "/teapot.obj -o " +
                    (dir / "png/f_0001.png").string() + " --size 32x32");
    ASSERT_EQ(r.exit_code, 0);
    fs::copy_file(dir / "png/f_0001.png", dir / "png/f_0003.png");
    r = run_toonray("encode " + (dir / "png").string() + " -o " + (dir / "out.mp4").string());
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.output.find("f_0002.png"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "out.mp4"));
}

TEST(ScoreCli, ConvertsMidiToScriptAndBackLosslessly) {
    TempDir dir("cli_score");
    std::string midi = std::string(TOONRAY_DATA_DIR) + "/entertainer.midi";
    ASSERT_EQ(run_toonray("score convert " + midi + " " + (dir / "e.notes").string()).exit_code, 0);
    ASSERT_EQ(
        run_toonray("score convert " + (dir / "e.notes").string() + " " + (dir / "a.mid").string())
            .exit_code,
        0);
    ASSERT_EQ(run_toonray("score convert " + midi + " " + (dir / "b.mid").string()).exit_code, 0);
    std::ifstream a(dir / "a.mid", std::ios::binary), b(dir / "b.mid", std::ios::binary);
    std::string sa((std::istreambuf_iterator<char>(a)), {}),
        sb((std::istreambuf_iterator<char>(b)), {});
    EXPECT_FALSE(sa.empty());
    EXPECT_EQ(sa, sb);
}

TEST(ScoreCli, BadScoreNamesTheLine) {
    TempDir dir("cli_badscore");
    dir.write("bad.notes", "E:w26,w28\nQ:w53\n");
    CommandResult r = run_toonray("score convert " + (dir / "bad.notes").string() + " " +
                                  (dir / "o.mid").string());
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.output.find("bad.notes:2:"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("w53"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir / "o.mid"));
}
