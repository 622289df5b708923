#include <gtest/gtest.h>

#include "cli/cli_test_util.h"

namespace fs = std::filesystem;

namespace {
std::string probe(const fs::path& file, const std::string& entries) {
    fs::path out = file.parent_path() / "probe.txt";
    std::string cmd = "ffprobe -v error -count_frames -show_entries " + entries + " -of csv=p=0 " +
                      file.string() + " > " + out.string();
    if (std::system(cmd.c_str()) != 0) return "(ffprobe failed)";
    std::ifstream f(out);
    return {std::istreambuf_iterator<char>(f), {}};
}
}  // namespace

TEST(DemoCli, MakesAMovieWithPictureAndSoundOfTheRightLength) {
    // The README's main job, shortened: one second at a small size.
    TempDir dir("cli_demo");
    CommandResult r =
        run_toonray("demo -o " + dir.path.string() + " --seconds 1 --size 320x180 --quiet");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    fs::path movie = dir / "entertainer.mp4";
    ASSERT_TRUE(fs::exists(movie));
    std::string streams = probe(movie, "stream=codec_type,codec_name,nb_read_frames");
    EXPECT_NE(streams.find("h264,video,24"), std::string::npos) << streams;
    EXPECT_NE(streams.find("aac,audio"), std::string::npos) << streams;
    std::string duration = probe(movie, "format=duration");
    EXPECT_NEAR(std::stod(duration), 1.0, 0.05) << duration;
    EXPECT_TRUE(fs::exists(dir / "frames/entertainer_000024.png"));
    EXPECT_FALSE(fs::exists(dir / "frames/entertainer_000025.png"));
}

TEST(PianoCli, ExportsObjFramesThatBatchRendersIdentically) {
    TempDir dir("cli_piano");
    std::string common = " --start 20 --seconds 0.125 --size 160x90 --quiet";
    ASSERT_EQ(run_toonray("piano -o " + (dir / "mem").string() + common).exit_code, 0);
    CommandResult r = run_toonray("piano --export-obj " + (dir / "frames").string() + common);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    r = run_toonray("batch keys 1 3 --input " + (dir / "frames").string() + " --output " +
                    (dir / "png").string() + " --size 160x90 --quiet");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    for (const char* name : {"keys_000001.png", "keys_000002.png", "keys_000003.png"}) {
        std::ifstream a(dir / "mem" / name, std::ios::binary),
            b(dir / "png" / name, std::ios::binary);
        std::string sa((std::istreambuf_iterator<char>(a)), {}),
            sb((std::istreambuf_iterator<char>(b)), {});
        EXPECT_FALSE(sa.empty());
        EXPECT_EQ(sa, sb) << name;
    }
}

TEST(PianoCli, NeedsExactlyOneOutputAndAValidScore) {
    TempDir dir("cli_piano_bad");
    EXPECT_NE(run_toonray("piano --seconds 1").exit_code, 0);
    dir.write("bad.notes", "E:w26\nE:w99\n");
    CommandResult r = run_toonray("piano --score " + (dir / "bad.notes").string() + " -o " +
                                  (dir / "o").string());
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.output.find("bad.notes:2:"), std::string::npos) << r.output;
}
