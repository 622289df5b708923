#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <random>
#include <string>
#include <vector>

#include "toonray/io/file.h"
#include "toonray/score/midi.h"
#include "toonray/score/note_script.h"
#include "toonray/score/score_io.h"

namespace toonray {
namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes header(unsigned format, unsigned tracks, unsigned division) {
    return {'M',
            'T',
            'h',
            'd',
            0,
            0,
            0,
            6,
            0,
            static_cast<std::uint8_t>(format),
            static_cast<std::uint8_t>(tracks >> 8),
            static_cast<std::uint8_t>(tracks),
            static_cast<std::uint8_t>(division >> 8),
            static_cast<std::uint8_t>(division)};
}

Bytes chunk(const char* type, const Bytes& body) {
    Bytes out(type, type + 4);
    const auto n = static_cast<std::uint32_t>(body.size());
    for (int shift = 24; shift >= 0; shift -= 8)
        out.push_back(static_cast<std::uint8_t>(n >> shift));
    out.insert(out.end(), body.begin(), body.end());
    return out;
}

Bytes track(const Bytes& events) { return chunk("MTrk", events); }

Bytes cat(std::initializer_list<Bytes> parts) {
    Bytes out;
    for (const Bytes& p : parts) out.insert(out.end(), p.begin(), p.end());
    return out;
}

const Bytes kEnd = {0x00, 0xFF, 0x2F, 0x00};

TimedScore read(const Bytes& bytes, Warnings* warnings = nullptr, const MidiLimits& limits = {}) {
    return read_midi(bytes, "t.mid", warnings, limits);
}

std::string midi_error(const Bytes& bytes, const MidiLimits& limits = {}) {
    try {
        (void)read(bytes, nullptr, limits);
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

Bytes entertainer_bytes() {
    const std::string s = read_file(TOONRAY_DATA_DIR "/entertainer.midi");
    return Bytes(s.begin(), s.end());
}

constexpr double kEntertainerTick = 833333e-6 / 384;  // seconds per tick at 72 bpm

TEST(Midi, Entertainer) {
    Warnings warnings;
    const TimedScore t = load_timed_score(TOONRAY_DATA_DIR "/entertainer.midi", &warnings);
    EXPECT_TRUE(warnings.empty()) << warnings.front();
    EXPECT_EQ(t.ppq, 384);
    ASSERT_EQ(t.tempo.size(), 1u);
    EXPECT_EQ(t.tempo[0], (TempoChange{0, 833333}));
    ASSERT_EQ(t.time_signatures.size(), 1u);
    EXPECT_EQ(t.time_signatures[0], (TimeSignature{0, 2, 4}));
    EXPECT_TRUE(t.pedal.empty());
    ASSERT_EQ(t.notes.size(), 2621u);
    EXPECT_EQ(std::count_if(t.notes.begin(), t.notes.end(), [](auto& n) { return n.track == 1; }),
              1394);
    EXPECT_EQ(std::count_if(t.notes.begin(), t.notes.end(), [](auto& n) { return n.track == 2; }),
              1227);
    const auto [lo, hi] = std::minmax_element(t.notes.begin(), t.notes.end(),
                                              [](auto& a, auto& b) { return a.key < b.key; });
    EXPECT_EQ(lo->key, 29);
    EXPECT_EQ(hi->key, 90);
    std::int64_t last_end = 0;
    for (const TimedNote& n : t.notes) last_end = std::max(last_end, n.end);
    // The last notes are released at tick 116544; the tracks end a quarter later, at 116736
    // (152 bars of 2/4), after a final rest.
    EXPECT_EQ(last_end, 116544);
    EXPECT_EQ(t.end_tick, 116736);

    const Score s = to_score(t);
    ASSERT_EQ(s.notes.size(), 2621u);
    EXPECT_NEAR(s.duration(), 116544 * kEntertainerTick, 1e-9);  // 252.9166 s
    EXPECT_NEAR(s.end_time, 116736 * kEntertainerTick, 1e-9);    // 253.3332 s
    EXPECT_NEAR(s.end_time, 253.3332, 1e-3);
    for (std::size_t i = 1; i < s.notes.size(); ++i) {
        const Note& a = s.notes[i - 1];
        const Note& b = s.notes[i];
        ASSERT_TRUE(a.start < b.start || (a.start == b.start && a.key <= b.key)) << i;
    }
    for (const Note& n : s.notes) {
        ASSERT_LT(n.start, n.end);
        ASSERT_TRUE(n.velocity == 90 || n.velocity == 127);
    }
}

TEST(Midi, RoundTripKeepsEveryNote) {
    const TimedScore a = read(entertainer_bytes());
    const Bytes written = write_midi(a);
    const TimedScore b = read(written);
    EXPECT_EQ(b, a);
    const Score sa = to_score(a), sb = to_score(b);
    ASSERT_EQ(sa.notes.size(), sb.notes.size());
    for (std::size_t i = 0; i < sa.notes.size(); ++i) {
        EXPECT_EQ(sa.notes[i].start, sb.notes[i].start);
        EXPECT_EQ(sa.notes[i].end, sb.notes[i].end);
        EXPECT_EQ(sa.notes[i].key, sb.notes[i].key);
        EXPECT_EQ(sa.notes[i].velocity, sb.notes[i].velocity);
        EXPECT_EQ(sa.notes[i].track, sb.notes[i].track);
    }
    EXPECT_EQ(write_midi(b), written);  // a fixed point
}

TEST(Midi, ThroughNoteScriptAndBack) {
    const TimedScore a = read(entertainer_bytes());
    const std::string script = write_note_script(a);
    Warnings warnings;
    const TimedScore s = parse_note_script(script, "entertainer.notes", &warnings);
    EXPECT_TRUE(warnings.empty());
    EXPECT_EQ(s, a);
    const Bytes again = write_midi(s);
    EXPECT_EQ(again, write_midi(a));
    EXPECT_EQ(read(again).notes, a.notes);
    // The script reads like the seed: sixteenth steps, letter durations, w/b keys.
    EXPECT_THAT(script, testing::HasSubstr("\nstep S\n"));
    EXPECT_THAT(script, testing::HasSubstr("\ntempo 72\n"));
    EXPECT_THAT(script, testing::HasSubstr("\ntime 2/4\n"));
    EXPECT_THAT(script, testing::HasSubstr("\nvelocity 90\n"));
    EXPECT_THAT(script, testing::HasSubstr("\nE:w28@127,w30@127,w32@127,w35@127\n"));
    EXPECT_LT(script.size(), 40000u);
}

TEST(Midi, RunningStatusAndVelocityZeroNoteOff) {
    // ppq 96, no tempo event: MIDI's 120 bpm.
    const Bytes file =
        cat({header(0, 1, 96), track({0x00, 0x90, 0x3C, 0x40,  // on 60 at 0
                                      0x10, 0x3E, 0x50,        // running status: on 62 at 16
                                      0x10, 0x3C, 0x00,        // velocity 0: off 60 at 32
                                      0x10, 0x3E, 0x00,        // off 62 at 48
                                      0x00, 0x90, 0x40, 0x64,  // on 64 at 48
                                      0x60, 0x80, 0x40, 0x7F,  // note-off with release velocity
                                      0x00, 0xFF, 0x2F, 0x00})});
    const TimedScore t = read(file);
    ASSERT_EQ(t.notes.size(), 3u);
    EXPECT_EQ(t.notes[0], (TimedNote{0, 32, 60, 64, 0, 0}));
    EXPECT_EQ(t.notes[1], (TimedNote{16, 48, 62, 80, 0, 0}));
    EXPECT_EQ(t.notes[2], (TimedNote{48, 144, 64, 100, 0, 0}));
    ASSERT_EQ(t.tempo.size(), 1u);
    EXPECT_EQ(t.tempo[0].us_per_quarter, 500000u);
    const Score s = to_score(t);
    EXPECT_DOUBLE_EQ(s.notes[0].end, 32 / 96.0 * 0.5);
    EXPECT_DOUBLE_EQ(s.notes[2].end, 144 / 96.0 * 0.5);
}

TEST(Midi, TempoChangesMidPiece) {
    // Format 1: the tempo map in track 0, notes in track 1, ppq 96.
    const Bytes file =
        cat({header(1, 2, 96), track({0x00, 0xFF, 0x51, 0x03, 0x07, 0xA1, 0x20,  // 500000 at 0
                                      0x60, 0xFF, 0x51, 0x03, 0x0F, 0x42, 0x40,  // 1000000 at 96
                                      0x60, 0xFF, 0x51, 0x03, 0x03, 0xD0, 0x90,  // 250000 at 192
                                      0x00, 0xFF, 0x2F, 0x00}),
             track({0x00, 0x90, 60,   100,  0x60, 60, 0,  // 60: 0..96
                    0x00, 62,   100,  0x60, 62,   0,      // 62: 96..192
                    0x00, 64,   100,  0x60, 64,   0,      // 64: 192..288
                    0x00, 0xFF, 0x2F, 0x00})});
    const TimedScore t = read(file);
    ASSERT_EQ(t.tempo.size(), 3u);
    const Score s = to_score(t);
    ASSERT_EQ(s.notes.size(), 3u);
    EXPECT_DOUBLE_EQ(s.notes[0].start, 0.0);
    EXPECT_DOUBLE_EQ(s.notes[0].end, 0.5);
    EXPECT_DOUBLE_EQ(s.notes[1].start, 0.5);
    EXPECT_DOUBLE_EQ(s.notes[1].end, 1.5);
    EXPECT_DOUBLE_EQ(s.notes[2].start, 1.5);
    EXPECT_DOUBLE_EQ(s.notes[2].end, 1.75);
    EXPECT_EQ(s.notes[2].track, 1);
    EXPECT_DOUBLE_EQ(t.seconds_at(144), 1.0);
}

TEST(Midi, Format0WithChannelsAndSkippedEvents) {
    const Bytes file = cat(
        {header(0, 1, 480),
         track(
             {0x00, 0xFF, 0x03, 0x04, 'n',  'a',  'm',  'e',             // track name
              0x00, 0xF0, 0x05, 0x7E, 0x7F, 0x09, 0x01, 0xF7,            // sysex
              0x00, 0xC0, 0x05,                                          // program
              0x00, 0x99, 36,   90,                                      // channel 10
              0x00, 0xF7, 0x02, 0x12, 0x34,                              // escape
              0x00, 0xFF, 0x7F, 0x03, 0x00, 0x00, 0x41,                  // seq. meta
              0x00, 0xE0, 0x00, 0x40,                                    // pitch bend
              0x00, 0xD0, 0x30,                                          // pressure
              0x00, 0xA0, 60,   10,                                      // aftertouch
              0x00, 0x90, 60,   70,                                      // channel 1
              0x00, 62,   71,                                            // running
              0x83, 0x60, 0x89, 36,   0,                                 // at 480
              0x00, 0x90, 60,   0,    0x00, 0xFF, 0x01, 0x02, 'h', 'i',  // text meta
              0x00, 62,   0,  // running status from before the meta event
              0x00, 0xFF, 0x2F, 0x00, 0x00, 0x90, 70,   70})});  // after the end of track: ignored
    Warnings warnings;
    const TimedScore t = read(file, &warnings);
    EXPECT_TRUE(warnings.empty());
    ASSERT_EQ(t.notes.size(), 3u);
    EXPECT_EQ(t.notes[0], (TimedNote{0, 480, 36, 90, 0, 9}));
    EXPECT_EQ(t.notes[1], (TimedNote{0, 480, 60, 70, 0, 0}));
    EXPECT_EQ(t.notes[2], (TimedNote{0, 480, 62, 71, 0, 0}));
    EXPECT_EQ(t.end_tick, 480);
}

TEST(Midi, SustainPedal) {
    const Bytes file =
        cat({header(0, 1, 96),
             track({0x00, 0xB0, 0x40, 0x7F,                          // down at 0
                    0x00, 0x90, 60,   80,   0x60, 0xB0, 0x07, 0x64,  // volume: ignored
                    0x00, 0x40, 0x00,                                // running status: up at 96
                    0x00, 0x80, 60,   0,    0x30, 0xB0, 0x40, 0x40,  // 64: down at 144
                    0x10, 0x40, 0x70,                                // still down: no change
                    0x10, 0x40, 0x3F,                                // 63: up at 176
                    0x00, 0xFF, 0x2F, 0x00})});
    const TimedScore t = read(file);
    ASSERT_EQ(t.pedal.size(), 5u);
    EXPECT_EQ(t.pedal[0], (PedalChange{0, 127, 0, 0}));
    EXPECT_EQ(t.pedal[2], (PedalChange{144, 64, 0, 0}));
    const Score s = to_score(t);
    ASSERT_EQ(s.sustain.size(), 4u);
    EXPECT_TRUE(s.sustain[0].down);
    EXPECT_FALSE(s.sustain[1].down);
    EXPECT_DOUBLE_EQ(s.sustain[1].time, 0.5);
    EXPECT_TRUE(s.sustain[2].down);
    EXPECT_DOUBLE_EQ(s.sustain[2].time, 0.75);
    EXPECT_FALSE(s.sustain[3].down);
    EXPECT_DOUBLE_EQ(s.sustain[3].time, 176 / 96.0 * 0.5);
    EXPECT_DOUBLE_EQ(s.duration(), 176 / 96.0 * 0.5);
    // The pedal survives writing and the note script.
    EXPECT_EQ(read(write_midi(t)), t);
    EXPECT_EQ(parse_note_script(write_note_script(t), "p.notes"), t);
}

TEST(Midi, OverlappingSameKeyNotes) {
    // On 60 at 0 and again at 10, offs at 20 and 30: first in, first out pairs them as
    // 0..20 and 10..30; the first is then cut where the second starts.
    const Bytes file =
        cat({header(0, 1, 96), track({0x00, 0x90, 60, 50, 0x0A, 60, 60, 0x0A, 60, 0, 0x0A, 60, 0,
                                      // on 62 twice at 40, one off at 50: one note survives
                                      0x0A, 62, 70, 0x00, 62, 71, 0x0A, 62, 0, 0x0A, 62, 0, 0x00,
                                      0xFF, 0x2F, 0x00})});
    Warnings warnings;
    const TimedScore t = read(file, &warnings);
    ASSERT_EQ(t.notes.size(), 3u);
    EXPECT_EQ(t.notes[0], (TimedNote{0, 10, 60, 50, 0, 0}));
    EXPECT_EQ(t.notes[1], (TimedNote{10, 30, 60, 60, 0, 0}));
    EXPECT_EQ(t.notes[2], (TimedNote{40, 60, 62, 71, 0, 0}));
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_THAT(warnings[0], testing::StartsWith("t.mid: 2 note(s) overlapped"));
    EXPECT_EQ(read(write_midi(t)), t);
}

TEST(Midi, UnreleasedNotesEndWithTheirTrack) {
    const Bytes file =
        cat({header(0, 1, 96),
             track({0x00, 0x90, 60, 50, 0x81, 0x00, 0x80, 61, 0, 0x20, 0xFF, 0x2F, 0x00})});
    Warnings warnings;
    const TimedScore t = read(file, &warnings);
    ASSERT_EQ(t.notes.size(), 1u);
    EXPECT_EQ(t.notes[0], (TimedNote{0, 160, 60, 50, 0, 0}));
    ASSERT_EQ(warnings.size(), 2u);
    EXPECT_EQ(warnings[0], "t.mid: track 0: 1 note(s) never released; they end with the track");
    EXPECT_EQ(warnings[1], "t.mid: track 0: 1 note-off(s) without a sounding note ignored");
}

TEST(Midi, SmpteTiming) {
    // 25 frames per second, 40 ticks per frame: 1000 ticks a second; tempo events don't apply.
    const Bytes file =
        cat({header(0, 1, 0xE728), track({0x00, 0xFF, 0x51, 0x03, 0x07, 0xA1, 0x20, 0x00, 0x90, 60,
                                          80, 0x87, 0x68, 60, 0, 0x00, 0xFF, 0x2F, 0x00})});
    const TimedScore t = read(file);
    EXPECT_EQ(t.ppq, 1000);
    const Score s = to_score(t);
    ASSERT_EQ(s.notes.size(), 1u);
    EXPECT_DOUBLE_EQ(s.notes[0].end, 1.0);
    // 29.97 fps drop-frame: 30 frames take 1.001 s.
    const Bytes df = cat(
        {header(0, 1, 0xE302), track({0x00, 0x90, 60, 80, 0x3C, 60, 0, 0x00, 0xFF, 0x2F, 0x00})});
    EXPECT_DOUBLE_EQ(to_score(read(df)).notes[0].end, 1.001);
}

TEST(Midi, AlienChunksAreSkipped) {
    const Bytes file = cat({header(1, 1, 96), chunk("XFIH", {1, 2, 3}),
                            track({0x00, 0x90, 60, 80, 0x60, 60, 0, 0x00, 0xFF, 0x2F, 0x00}),
                            Bytes{'t', 'r', 'a', 'i', 'l'}});
    EXPECT_EQ(read(file).notes.size(), 1u);
}

TEST(Midi, ErrorCatalogue) {
    const Bytes note = {0x00, 0x90, 60, 80, 0x60, 60, 0};
    EXPECT_EQ(midi_error({'R', 'I', 'F', 'F'}),
              "t.mid: byte 0: not a Standard MIDI File (no \"MThd\" header)");
    EXPECT_EQ(midi_error({}), "t.mid: byte 0: not a Standard MIDI File (no \"MThd\" header)");
    EXPECT_EQ(midi_error({'M', 'T', 'h', 'd', 0, 0, 0, 6, 0, 1}),
              "t.mid: byte 10: truncated header chunk");
    EXPECT_EQ(midi_error({'M', 'T', 'h', 'd', 0, 0, 0, 3, 0, 1, 0, 1, 0, 96}),
              "t.mid: byte 4: header chunk length 3 is too short (need 6)");
    EXPECT_EQ(midi_error({'M', 'T', 'h', 'd', 0, 0, 1, 6, 0, 1, 0, 1, 0, 96}),
              "t.mid: byte 14: truncated header chunk");
    EXPECT_EQ(midi_error(cat({header(2, 1, 96), track(kEnd)})),
              "t.mid: byte 8: MIDI format 2 (independent sequences) is not supported");
    EXPECT_EQ(midi_error(cat({header(7, 1, 96), track(kEnd)})),
              "t.mid: byte 8: unknown MIDI format 7");
    EXPECT_EQ(midi_error(cat({header(1, 0, 96)})),
              "t.mid: byte 10: the header announces no tracks");
    EXPECT_EQ(midi_error(cat({header(0, 2, 96), track(kEnd), track(kEnd)})),
              "t.mid: byte 10: a format 0 file has exactly 1 track, the header announces 2");
    EXPECT_EQ(midi_error(cat({header(1, 1, 0), track(kEnd)})),
              "t.mid: byte 12: time division of 0 ticks per quarter note");
    EXPECT_EQ(midi_error(cat({header(1, 1, 0xE000 | 40), track(kEnd)})),
              "t.mid: byte 12: bad SMPTE time division: 32 frames per second");
    EXPECT_EQ(midi_error(cat({header(1, 1, 0xE700), track(kEnd)})),
              "t.mid: byte 12: bad SMPTE time division: 0 ticks per frame");
    EXPECT_EQ(midi_error(cat({header(1, 2000, 96), track(kEnd)})),
              "t.mid: byte 10: 2000 tracks exceed the limit of 1024");
    EXPECT_EQ(midi_error(cat({header(1, 5, 96), track(kEnd)}), MidiLimits{4, 100}),
              "t.mid: byte 10: 5 tracks exceed the limit of 4");
    EXPECT_EQ(midi_error(cat({header(1, 1, 96), chunk("\x00\x01\x02\x03", kEnd)})),
              "t.mid: byte 14: bad chunk: type bytes 00 01 02 03 where \"MTrk\" was expected");
    Bytes past_end = cat({header(1, 1, 96), track(cat({note, kEnd}))});
    past_end[21] = 100;  // claims 100 bytes; 11 follow
    EXPECT_EQ(midi_error(past_end),
              "t.mid: byte 18: truncated track chunk: length 100 but only "
              "11 bytes left");
    EXPECT_EQ(midi_error(cat({header(1, 1, 96), chunk("JUNK", Bytes(3)), Bytes{'M', 'T', 'r'}})),
              "t.mid: byte 25: truncated file: the header announces 1 tracks but the file ends "
              "after 0");
    EXPECT_EQ(midi_error(cat({header(1, 1, 96), Bytes{'J', 'U', 'N', 'K', 0, 0, 0, 9, 1}})),
              "t.mid: byte 18: truncated \"JUNK\" chunk: length 9 but only 1 bytes left");
    EXPECT_EQ(midi_error(cat({header(1, 2, 96), track(kEnd)})),
              "t.mid: byte 26: truncated file: the header announces 2 tracks but the file ends "
              "after 1");
    EXPECT_EQ(
        midi_error(cat({header(1, 1, 96), track({0xFF, 0xFF, 0xFF, 0xFF, 0x00, 0x90, 60, 80})})),
        "t.mid: byte 22: bad variable-length quantity (longer than 4 bytes)");
    EXPECT_EQ(midi_error(cat({header(1, 1, 96), track({0x00, 0x90, 60})})),
              "t.mid: byte 22: truncated track chunk: an event runs past its end");
    EXPECT_EQ(midi_error(cat({header(1, 1, 96), track({0x00, 0x90, 60, 80, 0x81})})),
              "t.mid: byte 26: truncated track chunk: an event runs past its end");
    EXPECT_EQ(midi_error(cat({header(1, 1, 96), track({0x00, 60, 80})})),
              "t.mid: byte 23: data byte 0x3C where a status byte was expected (no running "
              "status in effect)");
    EXPECT_EQ(midi_error(cat({header(1, 1, 96), track({0x00, 0x90, 60, 0x90})})),
              "t.mid: byte 25: bad data byte 0x90 in a channel event");
    EXPECT_EQ(midi_error(cat({header(1, 1, 96), track({0x00, 0xF8})})),
              "t.mid: byte 23: unexpected status byte 0xF8 in a track");
    EXPECT_EQ(midi_error(cat({header(1, 1, 96), track({0x00, 0xFF, 0x01, 0x10, 'a', 'b'})})),
              "t.mid: byte 22: truncated track chunk: meta event of 16 bytes runs past its end");
    EXPECT_EQ(
        midi_error(cat({header(1, 1, 96), track({0x00, 0xFF, 0x01, 0xFF, 0xFF, 0xFF, 0x7F, 'a'})})),
        "t.mid: byte 22: truncated track chunk: meta event of 268435455 bytes runs past "
        "its end");
    EXPECT_EQ(midi_error(cat({header(1, 1, 96), track({0x00, 0xF0, 0x85, 0x00, 0x01})})),
              "t.mid: byte 22: truncated track chunk: sysex event of 640 bytes runs past its end");
    EXPECT_EQ(midi_error(cat({header(1, 1, 96), track({0x00, 0xFF, 0x01})})),
              "t.mid: byte 25: truncated track chunk: an event runs past its end");
    EXPECT_EQ(midi_error(
                  cat({header(1, 2, 96), track(cat({note, kEnd})), track(cat({note, note, kEnd}))}),
                  MidiLimits{16, 5}),
              "t.mid: byte 48: more than 5 events (the limit)");
}

TEST(Midi, DefaultEventLimit) {
    EXPECT_EQ(MidiLimits{}.max_events, 10'000'000u);
    EXPECT_EQ(MidiLimits{}.max_tracks, 1024u);
}

// Every prefix of a file is an error, never a crash or a hang.
TEST(Midi, TruncatedAtEveryCutPoint) {
    for (const Bytes& file :
         {entertainer_bytes(),
          cat({header(1, 2, 96),
               track({0x00, 0xFF, 0x51, 0x03, 7, 0xA1, 0x20, 0x00, 0xFF, 0x2F, 0x00}),
               track({0x00, 0x90, 60, 80, 0x83, 0x00, 60, 0, 0x00, 0xF0, 0x01, 0xF7, 0x00, 0xFF,
                      0x2F, 0x00})})}) {
        ASSERT_NO_THROW((void)read(file));
        for (std::size_t cut = 0; cut < file.size(); ++cut) {
            const Bytes prefix(file.begin(), file.begin() + static_cast<std::ptrdiff_t>(cut));
            EXPECT_THROW((void)read(prefix), Error) << "cut at " << cut;
        }
    }
}

// Corrupted files either read or throw Error; run under the sanitizers this also checks that no
// byte is read out of bounds. What does read survives both writers unchanged.
TEST(Midi, CorruptedFilesNeverCrash) {
    const Bytes original = entertainer_bytes();
    std::mt19937 rng(12345);
    int read_ok = 0, errors = 0;
    for (int round = 0; round < 300; ++round) {
        Bytes file = original;
        const int flips = 1 + static_cast<int>(rng() % 8);
        for (int i = 0; i < flips; ++i) {
            const std::size_t at = rng() % file.size();
            file[at] = static_cast<std::uint8_t>(rng());
        }
        TimedScore t;
        try {
            t = read(file);
        } catch (const Error&) {
            ++errors;
            continue;
        }
        ++read_ok;
        (void)to_score(t);
        // Whatever reads, the note script and MIDI writers carry over exactly.
        ASSERT_EQ(parse_note_script(write_note_script(t), "fuzz.notes"), t) << "round " << round;
        ASSERT_EQ(read(write_midi(t)), t) << "round " << round;
    }
    EXPECT_EQ(read_ok + errors, 300);
    EXPECT_GT(errors, 0);
    EXPECT_GT(read_ok, 0);
}

TEST(Midi, WriterBytes) {
    TimedScore t;
    t.ppq = 96;
    t.tempo = {{0, 500000}};
    t.time_signatures = {{0, 2, 4}};
    t.notes = {{0, 96, 60, 100, 1, 0}, {48, 96, 64, 90, 1, 0}};
    t.end_tick = 192;
    const Bytes expected = cat({
        header(1, 2, 96),
        track({0x00, 0xFF, 0x51, 0x03, 0x07, 0xA1, 0x20,        // tempo
               0x00, 0xFF, 0x58, 0x04, 0x02, 0x02, 0x18, 0x08,  // 2/4
               0x81, 0x40, 0xFF, 0x2F, 0x00}),                  // end at 192
        track({0x00, 0x90, 60, 100, 0x30, 64, 90,               // running status
               0x30, 60, 0,                                     // note-offs as velocity 0
               0x00, 64, 0, 0x60, 0xFF, 0x2F, 0x00}),
    });
    EXPECT_EQ(write_midi(t), expected);
}

TEST(Midi, WriterRefusesWhatMidiCannotHold) {
    auto error = [](const TimedScore& t) {
        try {
            (void)write_midi(t);
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("(no error)");
    };
    TimedScore t;
    t.notes = {{0, 10, 60, 0, 0, 0}};
    EXPECT_EQ(error(t), "cannot write MIDI: velocity 0 outside 1..127");
    t.notes = {{0, 10, 128, 80, 0, 0}};
    EXPECT_EQ(error(t), "cannot write MIDI: key 128 outside 0..127");
    t.notes = {{0, 0x10000000, 60, 80, 0, 0}};
    EXPECT_EQ(error(t),
              "cannot write MIDI: 268435456 ticks between two events of track 0 exceed "
              "the limit of 268435455");
    t.notes = {{10, 10, 60, 80, 0, 0}};
    EXPECT_EQ(error(t), "cannot write MIDI: note 60 at tick 10 ends at tick 10");
    t.notes.clear();
    t.time_signatures = {{0, 3, 6}};
    EXPECT_EQ(error(t),
              "cannot write MIDI: time signature denominator 6 is not a power of two "
              "from 1 to 128");
}

TEST(Midi, IsMidi) {
    const Bytes yes = {'M', 'T', 'h', 'd'};
    const Bytes no = {'M', 'T', 'h'};
    EXPECT_TRUE(is_midi(yes));
    EXPECT_FALSE(is_midi(no));
}

}  // namespace
}  // namespace toonray
