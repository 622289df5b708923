#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "toonray/score/midi.h"
#include "toonray/score/note_script.h"
#include "toonray/score/piano_keys.h"
#include "toonray/score/score_io.h"
#include "support/test_support.h"

namespace toonray {
namespace {

using toonray::test_support::error_of;

// One seed line: an eighth at 72 bpm, 60/72/2 s, with the quarter rounded to whole
// microseconds (833333) as MIDI stores tempo, so scripts and MIDI files agree exactly.
constexpr double kLine = 833333e-6 / 2.0;
static_assert(kLine - 60.0 / 72.0 / 2.0 < 1e-6 && kLine < 60.0 / 72.0 / 2.0);

std::string parse_error(std::string_view text) {
    return error_of([&] { (void)parse_note_script(text, "bad.notes"); });
}

struct Expected {
    int line;   // seed line the note starts on
    int lines;  // its length in lines
    int key;
};

TEST(NoteScript, SeedLinesParseToExactNotes) {
    Warnings warnings;
    const Score score = load_score(TOONRAY_TEST_DATA_DIR "/score/seed.notes", &warnings);
    // Keys worked out by hand: w26 = E4 = 64, w14 = G2 = 43, b12 = C#3 = 49, ...
    // The half note on w16 (line 3) would last to line 7, but w16 is struck again on line 6,
    // so it ends there (the overlap rule of `normalize`), with a warning.
    const Expected expected[] = {
        {0, 1, 64}, {0, 1, 67}, {0, 1, 71},                          // E:w26,w28,w30
        {1, 2, 43}, {1, 2, 49}, {1, 2, 53},                          // Q:w14,b12,w20
        {2, 1, 76},                                                  // E:w33
        {3, 3, 47}, {3, 4, 52}, {3, 4, 55}, {3, 4, 59},              // H:w16,w19,w21,w23
        {3, 1, 71}, {3, 1, 83},                                      // E:w30,w37
        {5, 1, 48}, {5, 1, 50}, {5, 2, 88},                          // E:w17,w18 | Q:w40
        {6, 1, 26}, {6, 1, 47}, {6, 1, 50}, {6, 1, 53}, {6, 1, 77},  // E:w16,w18,w20,w34,w4
    };
    ASSERT_EQ(score.notes.size(), std::size(expected));
    for (std::size_t i = 0; i < score.notes.size(); ++i) {
        const Note& n = score.notes[i];
        const Expected& e = expected[i];
        EXPECT_EQ(n.key, e.key) << i;
        EXPECT_NEAR(n.start, e.line * kLine, 1e-9) << i;
        EXPECT_NEAR(n.end, (e.line + e.lines) * kLine, 1e-9) << i;
        EXPECT_EQ(n.velocity, kScriptDefaultVelocity) << i;
        EXPECT_EQ(n.track, 0) << i;
    }
    EXPECT_TRUE(score.sustain.empty());
    EXPECT_NEAR(score.duration(), 7 * kLine, 1e-9);  // Q:w40 on line 5 and the last eighth
    EXPECT_NEAR(score.end_time, 7 * kLine, 1e-9);
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_THAT(warnings[0], testing::HasSubstr("1 note(s) overlapped"));
}

TEST(NoteScript, SeedTicksAndDefaults) {
    const TimedScore t = parse_note_script("E:w24\nEmpty\nW:w1\n", "x.notes");
    EXPECT_EQ(t.ppq, 384);
    ASSERT_EQ(t.tempo.size(), 1u);
    EXPECT_EQ(t.tempo[0], (TempoChange{0, 833333}));
    ASSERT_EQ(t.notes.size(), 2u);
    EXPECT_EQ(t.notes[0], (TimedNote{0, 192, 60, 80, 0, 0}));
    EXPECT_EQ(t.notes[1], (TimedNote{384, 384 + 1536, 21, 80, 0, 0}));
    EXPECT_EQ(t.end_tick, 384 + 1536);
    EXPECT_NEAR(t.seconds_at(192), kLine, 1e-12);
}

TEST(NoteScript, BlankLinesAndCommentsTakeNoTime) {
    const TimedScore t = parse_note_script(
        "\xEF\xBB\xBF# title\r\nE:w1\r\n\r\n   \n# note\nE:w2 # a comment\n", "x.notes");
    ASSERT_EQ(t.notes.size(), 2u);
    EXPECT_EQ(t.notes[1].start, 192);
    EXPECT_EQ(t.notes[1].key, 23);
}

TEST(NoteScript, WhitespaceAroundSeparatorsIsAllowed) {
    const TimedScore a = parse_note_script("E:w30,w37|H:w16,w19\n", "a");
    const TimedScore b = parse_note_script("  E : w30 , w37 | H: w16,w19  \n", "b");
    EXPECT_EQ(a, b);
}

TEST(NoteScript, Extension) {
    Warnings warnings;
    const TimedScore t = load_timed_score(TOONRAY_TEST_DATA_DIR "/score/extended.notes", &warnings);
    EXPECT_TRUE(warnings.empty());
    EXPECT_EQ(t.ppq, 384);
    ASSERT_EQ(t.tempo.size(), 2u);
    EXPECT_EQ(t.tempo[0], (TempoChange{0, 833333}));
    EXPECT_EQ(t.tempo[1], (TempoChange{768, 1000000}));
    ASSERT_EQ(t.time_signatures.size(), 1u);
    EXPECT_EQ(t.time_signatures[0], (TimeSignature{0, 2, 4}));
    ASSERT_EQ(t.pedal.size(), 2u);
    EXPECT_EQ(t.pedal[0], (PedalChange{768, 127, 0, 0}));
    EXPECT_EQ(t.pedal[1], (PedalChange{960, 0, 0, 0}));
    const TimedNote expected[] = {
        {0, 192, 36, 90, 2, 0},   {0, 192, 48, 90, 2, 0},     // track 2: E:w10,w17 at 0
        {0, 96, 74, 90, 0, 0},    {0, 96, 86, 90, 0, 0},      // S:w32,w39
        {96, 192, 76, 90, 0, 0},  {96, 192, 88, 90, 0, 0},    // S:w33,w40
        {192, 288, 72, 90, 0, 0}, {192, 288, 84, 90, 0, 0},   // S:w31,w38
        {288, 960, 69, 90, 0, 0}, {288, 960, 81, 127, 0, 0},  // Q.+S:w29,w36@127
        {768, 864, 62, 90, 0, 0}, {768, 1056, 63, 90, 0, 0},  // E.:b18|S:w25 after wait Q
    };
    ASSERT_EQ(t.notes.size(), std::size(expected));
    for (std::size_t i = 0; i < t.notes.size(); ++i) EXPECT_EQ(t.notes[i], expected[i]) << i;
    EXPECT_EQ(t.end_tick, 1056);

    // Seconds follow the tempo change at tick 768 (72 bpm -> 60 bpm).
    const Score s = to_score(t);
    const Note& b18 = s.notes.back();
    EXPECT_NEAR(b18.start, 768 * 0.833333 / 384, 1e-9);
    EXPECT_NEAR(b18.end, 768 * 0.833333 / 384 + 288 / 384.0, 1e-9);
    ASSERT_EQ(s.sustain.size(), 2u);
    EXPECT_TRUE(s.sustain[0].down);
    EXPECT_NEAR(s.sustain[1].time, 768 * 0.833333 / 384 + 192 / 384.0, 1e-9);
}

TEST(NoteScript, DurationsAndKeys) {
    const TimedScore t = parse_note_script(
        "ppq 96\nstep 24\n"
        "W:m0|H:m1|Q:m2|E:m3|S:m4|T:m5|X:m6|Q.:m7|Q..:m8|Q...:m9|H+E:m10|7:m11|Q+5+S:m12|"
        "W.:m127\n",
        "d.notes");
    const std::int64_t ticks[] = {384, 192, 96, 48, 24, 12, 6, 144, 168, 180, 240, 7, 125};
    ASSERT_EQ(t.notes.size(), 14u);
    for (int k = 0; k <= 12; ++k) {
        EXPECT_EQ(t.notes[static_cast<std::size_t>(k)].key, k);
        EXPECT_EQ(t.notes[static_cast<std::size_t>(k)].end, ticks[k]) << k;
    }
    EXPECT_EQ(t.notes[13].key, 127);
    EXPECT_EQ(t.notes[13].end, 576);
}

TEST(NoteScript, VoicesKeepTheirOwnCursors) {
    const TimedScore t = parse_note_script(
        "E:w1\nE:w2\ntrack 1\nE:w3\nchannel 10\nE:w4\ntrack 0\nchannel 1\nE:w5\n", "v.notes");
    ASSERT_EQ(t.notes.size(), 5u);
    auto find = [&](int key) {
        for (const TimedNote& n : t.notes)
            if (n.key == key) return n;
        return TimedNote{};
    };
    EXPECT_EQ(find(white_key(3)), (TimedNote{0, 192, 24, 80, 1, 0}));
    EXPECT_EQ(find(white_key(4)), (TimedNote{0, 192, 26, 80, 1, 9}));
    EXPECT_EQ(find(white_key(5)), (TimedNote{384, 576, 28, 80, 0, 0}));
}

TEST(NoteScript, TempoForms) {
    auto tempo = [](std::string_view line) {
        return parse_note_script(std::string(line) + "\nE:w1\n", "t").tempo.at(0).us_per_quarter;
    };
    EXPECT_EQ(tempo("tempo 72"), 833333u);
    EXPECT_EQ(tempo("tempo 120"), 500000u);
    EXPECT_EQ(tempo("tempo 72.5"), 827586u);
    EXPECT_EQ(tempo("tempo 612345us"), 612345u);
    // The later of two tempos at one time wins.
    EXPECT_EQ(tempo("tempo 60\ntempo 100"), 600000u);
}

TEST(NoteScript, WriteParsesBackExactly) {
    TimedScore t;
    t.ppq = 480;
    t.tempo = {{0, 500000}, {1000, 612345}, {5000, 833333}};
    t.time_signatures = {{0, 3, 4}, {2880, 6, 8}};
    t.notes = {
        {0, 160, 60, 80, 0, 0},         {160, 320, 62, 81, 0, 0},
        {320, 480, 64, 127, 0, 0},  // 3 in 2
        {7, 1000, 0, 1, 3, 9},          {7, 20, 127, 64, 3, 9},
        {480, 3360, 21, 100, 0, 0},     {9000, 9001, 108, 5, 1, 15},
        {100000, 200000, 61, 80, 0, 0},
    };
    t.pedal = {{0, 127, 3, 9}, {500, 70, 3, 9}, {900, 0, 3, 9}, {900, 127, 3, 9}};
    t.end_tick = 250000;
    normalize(t);
    const std::string script = write_note_script(t);
    Warnings warnings;
    const TimedScore back = parse_note_script(script, "written.notes", &warnings);
    EXPECT_TRUE(warnings.empty());
    EXPECT_EQ(back, t) << script;
    EXPECT_EQ(write_midi(back), write_midi(t));
}

TEST(NoteScript, WriterUsesTheSeedGridWhenItFits) {
    const std::string seed = "E:w26,w28,w30\nQ:w14,b12,w20\nE:w33\nEmpty\nE:w30,w37|H:w16,w19\n";
    const TimedScore t = parse_note_script(seed, "s");
    const std::string written = write_note_script(t);
    EXPECT_THAT(written, testing::HasSubstr("\nE:w26,w28,w30\nQ:w14,b12,w20\nE:w33\nEmpty\n"
                                            "E:w30,w37|H:w16,w19\n"));
    EXPECT_THAT(written, testing::Not(testing::HasSubstr("\nstep")));
    EXPECT_EQ(parse_note_script(written, "w"), t);
}

TEST(NoteScript, ErrorCatalogue) {
    EXPECT_EQ(parse_error("E:w53"), "bad.notes:1: unknown key 'w53': white keys are w1..w52");
    EXPECT_EQ(parse_error("E:b37"), "bad.notes:1: unknown key 'b37': black keys are b1..b36");
    EXPECT_EQ(parse_error("E:w0"), "bad.notes:1: unknown key 'w0': white keys are w1..w52");
    EXPECT_EQ(parse_error("E:x5"),
              "bad.notes:1: unknown key 'x5' (keys are w1..w52, b1..b36 or m0..m127)");
    EXPECT_EQ(parse_error("E:m128"), "bad.notes:1: unknown key 'm128': MIDI keys are m0..m127");
    EXPECT_EQ(parse_error("E:w99999999999"),
              "bad.notes:1: unknown key 'w99999999999': white keys are w1..w52");
    EXPECT_EQ(parse_error("E;w3"),
              "bad.notes:1: malformed note group 'E;w3': expected "
              "DURATION:KEYS such as 'E:w26,w28,w30'");
    EXPECT_EQ(parse_error("E:w1\n\n# c\nE:w1|Q;w2"),
              "bad.notes:4: malformed note group 'Q;w2': expected DURATION:KEYS such as "
              "'E:w26,w28,w30'");
    EXPECT_THAT(parse_error("Z:w3"), testing::StartsWith("bad.notes:1: unknown duration 'Z' "));
    EXPECT_THAT(parse_error("e:w3"), testing::StartsWith("bad.notes:1: unknown duration 'e' "));
    EXPECT_THAT(parse_error("Q.x:w3"), testing::StartsWith("bad.notes:1: unknown duration 'Q.x' "));
    EXPECT_EQ(parse_error("Q....:w3"), "bad.notes:1: too many dots in 'Q....' (at most 3)");
    EXPECT_EQ(parse_error("Q+:w3"), "bad.notes:1: malformed duration 'Q+'");
    EXPECT_EQ(parse_error(":w3"), "bad.notes:1: missing duration");
    EXPECT_EQ(parse_error("0:w3"), "bad.notes:1: bad duration '0': ticks are 1..2147483647");
    EXPECT_EQ(parse_error("E:"), "bad.notes:1: no keys after ':' in 'E:'");
    EXPECT_EQ(parse_error("E:w1,,w2"), "bad.notes:1: missing key in 'E:w1,,w2'");
    EXPECT_EQ(parse_error("E:w1||Q:w2"), "bad.notes:1: empty note group in 'E:w1||Q:w2'");
    EXPECT_EQ(parse_error("E:w1@0"),
              "bad.notes:1: bad velocity in 'w1@0': expected 1..127 after '@'");
    EXPECT_EQ(parse_error("E:w1@128"),
              "bad.notes:1: bad velocity in 'w1@128': expected 1..127 after '@'");
    EXPECT_EQ(parse_error("Empty now"), "bad.notes:1: 'Empty' takes nothing after it");
    EXPECT_EQ(parse_error("tempo"), "bad.notes:1: 'tempo' needs a value");
    EXPECT_THAT(parse_error("tempo fast"), testing::StartsWith("bad.notes:1: bad tempo 'fast'"));
    EXPECT_EQ(parse_error("tempo 1"),
              "bad.notes:1: tempo 1 is out of range (3.58 to 60000000 bpm)");
    EXPECT_EQ(parse_error("tempo 0us"),
              "bad.notes:1: bad tempo '0us': microseconds per quarter are 1..16777215");
    EXPECT_EQ(parse_error("tempo 72 80"), "bad.notes:1: 'tempo' takes one value, got '72 80'");
    EXPECT_THAT(parse_error("time 3/5"),
                testing::StartsWith("bad.notes:1: bad time signature '3/5'"));
    EXPECT_THAT(parse_error("time 3"), testing::StartsWith("bad.notes:1: bad time signature '3'"));
    EXPECT_EQ(parse_error("velocity 0"),
              "bad.notes:1: bad value '0' for 'velocity': expected a whole number from 1 to 127");
    EXPECT_EQ(parse_error("track 1024"),
              "bad.notes:1: bad value '1024' for 'track': expected a whole number from 0 to 1023");
    EXPECT_EQ(parse_error("channel 0"),
              "bad.notes:1: bad value '0' for 'channel': expected a whole number from 1 to 16");
    EXPECT_EQ(parse_error("pedal sideways"),
              "bad.notes:1: bad pedal value 'sideways': expected down, up or 0..127");
    EXPECT_THAT(parse_error("E:w1\nfrobnicate 3"),
                testing::StartsWith("bad.notes:2: unknown directive 'frobnicate' "));
    EXPECT_EQ(parse_error("E:w1\nppq 96"), "bad.notes:2: 'ppq' must come before every other line");
    EXPECT_EQ(parse_error("ppq 0"),
              "bad.notes:1: bad value '0' for 'ppq': expected a whole number from 1 to 32767");
    EXPECT_EQ(parse_error("ppq 95\nQ:w1"),
              "bad.notes:2: a line is an eighth note by default, which is not a whole number of "
              "ticks at ppq 95; set 'step'");
    EXPECT_EQ(parse_error("ppq 95\nstep S"),
              "bad.notes:2: duration 'S' is not a whole number of ticks at ppq 95");
    EXPECT_EQ(parse_error("wait 2147483647\n" + std::string(3000, 'X')),
              "bad.notes:2: malformed note group '" + std::string(3000, 'X') +
                  "': expected DURATION:KEYS such as 'E:w26,w28,w30'");
}

TEST(NoteScript, ErrorsNameTheFileFromLoadScore) {
    const std::string what =
        error_of([] { (void)load_score(TOONRAY_TEST_DATA_DIR "/score/bad_key.notes"); });
    EXPECT_EQ(what, TOONRAY_TEST_DATA_DIR
              "/score/bad_key.notes:3: unknown key 'w53': white keys "
              "are w1..w52");
}

TEST(NoteScript, BinaryGarbageIsAnError) {
    const std::string junk("\x01\x02\x00\xff:\x80", 6);
    EXPECT_THROW((void)parse_note_script(junk, "junk"), Error);
}

}  // namespace
}  // namespace toonray
