#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <unistd.h>

#include "toonray/io/file.h"
#include "toonray/score/score_io.h"
#include "support/test_support.h"

namespace toonray {
namespace {

using toonray::test_support::error_of;

namespace fs = std::filesystem;

/// A fresh directory per test, removed afterwards.
class ScoreIo : public testing::Test {
protected:
    void SetUp() override {
        std::string tmpl = (fs::temp_directory_path() / "toonray_score_XXXXXX").string();
        ASSERT_NE(::mkdtemp(tmpl.data()), nullptr);
        dir_ = tmpl;
    }
    void TearDown() override { fs::remove_all(dir_); }

    void write(const fs::path& path, std::string_view text) {
        write_file_atomic(
            path, std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
    }

    fs::path dir_;
};

const char* const kEntertainer = TOONRAY_DATA_DIR "/entertainer.midi";

TEST_F(ScoreIo, ConvertMidiToNotesAndBack) {
    const fs::path notes = dir_ / "entertainer.notes";
    const fs::path midi = dir_ / "entertainer.mid";
    Warnings warnings;
    convert_score(kEntertainer, notes, &warnings);
    convert_score(notes, midi, &warnings);
    EXPECT_TRUE(warnings.empty());
    EXPECT_THAT(read_file(notes), testing::StartsWith("# toonray note script"));
    const TimedScore original = load_timed_score(kEntertainer);
    EXPECT_EQ(load_timed_score(notes), original);
    EXPECT_EQ(load_timed_score(midi), original);
    // Not the same bytes as LilyPond wrote (track names, key signature and the like are
    // dropped), but the same notes.
    const Score a = load_score(kEntertainer), b = load_score(midi);
    ASSERT_EQ(a.notes.size(), b.notes.size());
    for (std::size_t i = 0; i < a.notes.size(); ++i) {
        EXPECT_EQ(a.notes[i].start, b.notes[i].start);
        EXPECT_EQ(a.notes[i].end, b.notes[i].end);
        EXPECT_EQ(a.notes[i].key, b.notes[i].key);
    }
}

TEST_F(ScoreIo, FormatByContentOnLoadAndByExtensionOnSave) {
    // A note script named .mid still loads as a note script, and MIDI named .notes as MIDI.
    const fs::path script_named_mid = dir_ / "script.mid";
    write(script_named_mid, "E:w24\n");
    EXPECT_EQ(load_score(script_named_mid).notes.at(0).key, 60);
    const fs::path midi_named_notes = dir_ / "midi.notes";
    fs::copy_file(kEntertainer, midi_named_notes);
    EXPECT_EQ(load_score(midi_named_notes).notes.size(), 2621u);

    const fs::path upper = dir_ / "UPPER.MIDI";
    convert_score(script_named_mid, upper);
    EXPECT_THAT(read_file(upper), testing::StartsWith("MThd"));
    EXPECT_EQ(load_timed_score(upper), load_timed_score(script_named_mid));
}

TEST_F(ScoreIo, Errors) {
    const fs::path out = dir_ / "out.txt";
    EXPECT_EQ(error_of([&] { convert_score(kEntertainer, out); }),
              out.string() + ": unknown score extension '.txt' (use .mid, .midi or .notes)");
    EXPECT_FALSE(fs::exists(out));
    EXPECT_THAT(error_of([&] { (void)load_score(dir_ / "missing.notes"); }),
                testing::StartsWith((dir_ / "missing.notes").string() + ": cannot open"));

    // A truncated MIDI file names itself and the byte.
    const std::string bytes = read_file(kEntertainer);
    const fs::path cut = dir_ / "cut.mid";
    write(cut, std::string_view(bytes).substr(0, 5000));
    EXPECT_EQ(error_of([&] { (void)load_score(cut); }),
              cut.string() +
                  ": byte 123: truncated track chunk: length 11431 but only 4873 "
                  "bytes left");

    // Nothing is written when the input is bad.
    const fs::path bad = dir_ / "bad.notes";
    write(bad, "E:w1\nQ:b37\n");
    const fs::path target = dir_ / "target.mid";
    EXPECT_EQ(error_of([&] { convert_score(bad, target); }),
              bad.string() + ":2: unknown key 'b37': black keys are b1..b36");
    EXPECT_FALSE(fs::exists(target));
}

TEST(Score, Duration) {
    Score s;
    EXPECT_EQ(s.duration(), 0.0);
    s.notes = {{0.0, 5.0, 60, 80, 0}, {1.0, 2.0, 62, 80, 0}};
    EXPECT_EQ(s.duration(), 5.0);  // the longest, not the last to start
    s.sustain = {{0.5, true}, {6.5, false}};
    EXPECT_EQ(s.duration(), 6.5);
}

}  // namespace
}  // namespace toonray
