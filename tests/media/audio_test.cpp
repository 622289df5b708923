#include "toonray/media/audio.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <unistd.h>

#include "toonray/core/error.h"
#include "toonray/io/file.h"
#include "toonray/media/wav.h"
#include "support/test_support.h"

namespace toonray {
namespace {

using toonray::test_support::TempDir;

namespace fs = std::filesystem;

Score one_note(double start, double end, int key = 60, int velocity = 100) {
    Score s;
    s.notes.push_back({start, end, key, velocity, 0});
    return s;
}

/// Largest absolute sample (either channel) over frames [from, to).
int max_abs(const WavAudio& a, std::int64_t from, std::int64_t to) {
    int m = 0;
    for (std::int64_t f = std::max<std::int64_t>(0, from); f < std::min(to, a.frames()); ++f)
        for (int c = 0; c < a.channels; ++c)
            m = std::max(m, std::abs(static_cast<int>(a.samples[f * a.channels + c])));
    return m;
}

double rms(const WavAudio& a, std::int64_t from, std::int64_t to) {
    double sum = 0;
    std::int64_t n = 0;
    for (std::int64_t f = std::max<std::int64_t>(0, from); f < std::min(to, a.frames()); ++f)
        for (int c = 0; c < a.channels; ++c, ++n) {
            double v = a.samples[f * a.channels + c] / 32768.0;
            sum += v * v;
        }
    return n ? std::sqrt(sum / n) : 0.0;
}

/// First frame at or after `from` whose magnitude exceeds `threshold`, or -1.
std::int64_t first_above(const WavAudio& a, std::int64_t from, int threshold) {
    for (std::int64_t f = std::max<std::int64_t>(0, from); f < a.frames(); ++f)
        for (int c = 0; c < a.channels; ++c)
            if (std::abs(static_cast<int>(a.samples[f * a.channels + c])) > threshold) return f;
    return -1;
}

TEST(Audio, NoteAtOneSecondIsSilentBeforeAndLoudJustAfter) {
    AudioResult r = synthesize_score(one_note(1.0, 1.5));
    const WavAudio& a = r.audio;
    ASSERT_EQ(a.sample_rate, 44100);
    ASSERT_EQ(a.channels, 2);
    EXPECT_EQ(r.notes, 1);
    EXPECT_EQ(r.preset, "Yamaha Grand Piano");
    // Nothing at all before the note: no leading noise, no reverb of nothing.
    EXPECT_EQ(max_abs(a, 0, 44100), 0);
    const int peak = max_abs(a, 0, a.frames());
    ASSERT_GT(peak, 3000) << "the note should be clearly audible";
    // Onset: the first sample above 1% of the peak is within 10 ms after 1.0 s.
    const std::int64_t onset = first_above(a, 0, peak / 100);
    ASSERT_GE(onset, 44100);
    EXPECT_LT(onset, 44100 + 441) << "onset " << (onset - 44100) << " samples after 1.0 s";
    // Loud in the first 100 ms after the onset.
    EXPECT_GT(rms(a, 44100, 44100 + 4410), 0.02);
}

TEST(Audio, OnsetsAreWithinOneFluidSynthBlockOfTheirSample) {
    // Note times that fall at different offsets inside FluidSynth's 64-sample blocks, far apart
    // so each onset is found in silence (short notes, no pedal, no reverb).
    AudioOptions o;
    o.reverb = false;
    Score s;
    const double times[] = {0.0, 0.7000113, 1.4123457, 2.1, 2.8003};
    for (double t : times) s.notes.push_back({t, t + 0.05, 72, 110, 0});
    AudioResult r = synthesize_score(s, o);
    const int peak = max_abs(r.audio, 0, r.audio.frames());
    for (double t : times) {
        const std::int64_t at = std::llround(t * 44100);
        // The previous note has died away by 0.7 s later: silence just before this one.
        EXPECT_LT(max_abs(r.audio, at - 200, at), peak / 200) << "t = " << t;
        const std::int64_t onset = first_above(r.audio, at, peak / 100);
        EXPECT_GE(onset, at) << "t = " << t;
        EXPECT_LT(onset - at, 64 + 32) << "t = " << t;  // block quantisation + sample attack
    }
    // The first note starts the file: the sound begins within the first block.
    EXPECT_LT(first_above(r.audio, 0, peak / 100), 64 + 32);
}

TEST(Audio, DurationIsScoreEndPlusTail) {
    Score s = one_note(0.25, 1.75);
    s.notes.push_back({0.5, 1.0, 64, 90, 0});
    AudioOptions o;
    o.tail = 1.5;
    AudioResult r = synthesize_score(s, o);
    EXPECT_EQ(r.audio.frames(), std::llround((1.75 + 1.5) * 44100));
    EXPECT_NEAR(r.audio.duration(), 3.25, 1e-4);
    // A pedal release after the last note extends the score.
    s.sustain = {{0.1, true}, {2.5, false}};
    r = synthesize_score(s, o);
    EXPECT_EQ(r.audio.frames(), std::llround((2.5 + 1.5) * 44100));
    // The last sample is faded to silence.
    EXPECT_EQ(max_abs(r.audio, r.audio.frames() - 1, r.audio.frames()), 0);
}

TEST(Audio, WindowShiftsNotesAndCutsWithAFade) {
    Score s;
    s.notes.push_back({0.5, 3.0, 48, 100, 0});  // before the window: not played
    s.notes.push_back({1.5, 3.0, 60, 100, 0});  // in the window, lasts past its end
    s.notes.push_back({2.5, 3.0, 67, 100, 0});  // after the window
    AudioOptions o;
    o.start = 1.0;
    o.length = 1.0;
    AudioResult r = synthesize_score(s, o);
    EXPECT_EQ(r.notes, 1);
    EXPECT_EQ(r.audio.frames(), 44100);
    EXPECT_EQ(max_abs(r.audio, 0, 22050), 0) << "the note at 0.5 s must not sound in the window";
    const int peak = max_abs(r.audio, 0, r.audio.frames());
    const std::int64_t onset = first_above(r.audio, 0, peak / 100);
    EXPECT_GE(onset, 22050);
    EXPECT_LT(onset, 22050 + 441);
    // Still sounding shortly before the cut, faded to nothing at it.
    EXPECT_GT(rms(r.audio, 44100 - 4410, 44100 - 2205), 0.005);
    EXPECT_LT(max_abs(r.audio, 44100 - 5, 44100), 300);
    EXPECT_EQ(max_abs(r.audio, 44099, 44100), 0);
}

TEST(Audio, SustainPedalHoldsTheNote) {
    // A short note, then measure 0.6..0.9 s after its release: with the pedal down it still
    // rings; without, the damper has stopped it.
    AudioOptions o;
    o.reverb = false;
    Score dry = one_note(0.0, 0.2, 60, 100);
    Score held = dry;
    held.sustain = {{0.0, true}, {2.0, false}};
    const double dry_rms = rms(synthesize_score(dry, o).audio, 35280, 48510);
    const double held_rms = rms(synthesize_score(held, o).audio, 35280, 48510);
    EXPECT_GT(held_rms, 20 * dry_rms + 1e-4) << "held " << held_rms << " dry " << dry_rms;
}

TEST(Audio, PedalDownBeforeTheWindowIsAppliedAtItsStart) {
    AudioOptions o;
    o.reverb = false;
    o.start = 1.0;
    o.length = 1.5;
    Score s = one_note(1.0, 1.2, 60, 100);
    Score held = s;
    held.sustain = {{0.5, true}};
    const double dry_rms = rms(synthesize_score(s, o).audio, 35280, 48510);
    const double held_rms = rms(synthesize_score(held, o).audio, 35280, 48510);
    EXPECT_GT(held_rms, 20 * dry_rms + 1e-4);
}

TEST(Audio, OutputIsDeterministic) {
    Score s;
    for (int i = 0; i < 40; ++i) {
        const double t = 0.05 * i;
        s.notes.push_back({t, t + 0.4, 40 + (i * 7) % 45, 60 + i, 0});
        s.notes.push_back({t, t + 0.3, 52 + (i * 5) % 30, 90, 1});
    }
    s.sustain = {{0.3, true}, {1.1, false}, {1.2, true}, {1.9, false}};
    const auto a = encode_wav(synthesize_score(s).audio);
    const auto b = encode_wav(synthesize_score(s).audio);
    ASSERT_EQ(a.size(), b.size());
    EXPECT_TRUE(a == b) << "two renders of the same score differ";
    // And the reverb is really in play (otherwise this proves less): the dry render differs.
    AudioOptions dry;
    dry.reverb = false;
    EXPECT_FALSE(encode_wav(synthesize_score(s, dry).audio) == a);
}

TEST(Audio, OverlappingSameKeyNotesKeepSounding) {
    // Second strike at 0.5 s while the first is held to 1.0 s; the first's release at 1.0 s must
    // not silence the second, which is held to 2.0 s.
    AudioOptions o;
    o.reverb = false;
    Score s = one_note(0.0, 1.0, 60, 100);
    s.notes.push_back({0.5, 2.0, 60, 100, 0});
    Score single = one_note(0.0, 1.0, 60, 100);
    const double overlapped = rms(synthesize_score(s, o).audio, 66150, 79380);  // 1.5..1.8 s
    const double released = rms(synthesize_score(single, o).audio, 66150, 79380);
    EXPECT_GT(overlapped, 10 * released + 1e-4);
}

TEST(Audio, WritesAReadableWav) {
    TempDir dir;
    const fs::path wav = dir.path / "out.wav";
    AudioResult r = render_audio(one_note(0.0, 0.5), wav);
    WavAudio back = read_wav(wav);
    EXPECT_EQ(back.sample_rate, 44100);
    EXPECT_EQ(back.channels, 2);
    EXPECT_TRUE(back.samples == r.audio.samples);
    EXPECT_EQ(fs::file_size(wav), 44 + r.audio.samples.size() * 2);
    // No temporary left behind.
    EXPECT_EQ(std::distance(fs::directory_iterator(dir.path), fs::directory_iterator()), 1);
}

TEST(Audio, MissingSoundFontIsNamed) {
    AudioOptions o;
    o.soundfont = "/nonexistent/dir/Piano.sf2";
    try {
        synthesize_score(one_note(0, 1), o);
        FAIL() << "expected Error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/Piano.sf2"), std::string::npos)
            << e.what();
        EXPECT_NE(std::string(e.what()).find("not found"), std::string::npos) << e.what();
    }
}

TEST(Audio, InvalidSoundFontIsNamed) {
    TempDir dir;
    const fs::path bad = dir.path / "bogus.sf2";
    const std::string text = "RIFF\x10\0\0\0sfbkLIST but nothing else";
    write_file_atomic(bad, {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
    AudioOptions o;
    o.soundfont = bad;
    try {
        synthesize_score(one_note(0, 1), o);
        FAIL() << "expected Error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(bad.string()), std::string::npos) << e.what();
    }
    const fs::path text_file = dir.path / "notes.txt";
    write_file_atomic(text_file, {reinterpret_cast<const std::uint8_t*>("hello"), 5});
    o.soundfont = text_file;
    try {
        synthesize_score(one_note(0, 1), o);
        FAIL() << "expected Error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("notes.txt: not a SoundFont"), std::string::npos)
            << e.what();
    }
}

TEST(Audio, NoNotesIsAnError) {
    EXPECT_THROW(synthesize_score(Score{}), Error);
    AudioOptions o;
    o.start = 5.0;
    o.length = 1.0;
    try {
        synthesize_score(one_note(1.0, 2.0), o);
        FAIL() << "expected Error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("no notes start in the window"), std::string::npos)
            << e.what();
    }
}

TEST(Audio, InvalidValuesAreErrors) {
    EXPECT_THROW(synthesize_score(one_note(0.0, 1.0, 128)), Error);
    EXPECT_THROW(synthesize_score(one_note(NAN, 1.0)), Error);
    AudioOptions o;
    o.length = 0.0;
    EXPECT_THROW(synthesize_score(one_note(0.0, 1.0), o), Error);
    o = {};
    o.sample_rate = 100;
    EXPECT_THROW(synthesize_score(one_note(0.0, 1.0), o), Error);
}

TEST(Wav, RoundTripsAndRejectsGarbage) {
    TempDir dir;
    WavAudio a;
    a.sample_rate = 22050;
    a.channels = 1;
    for (int i = 0; i < 1000; ++i) a.samples.push_back(static_cast<std::int16_t>(i * 37 - 18000));
    write_wav(dir.path / "a.wav", a);
    WavAudio b = read_wav(dir.path / "a.wav");
    EXPECT_EQ(b.sample_rate, 22050);
    EXPECT_EQ(b.channels, 1);
    EXPECT_TRUE(a.samples == b.samples);
    write_file_atomic(dir.path / "x.wav", {reinterpret_cast<const std::uint8_t*>("nope"), 4});
    EXPECT_THROW(read_wav(dir.path / "x.wav"), Error);
    EXPECT_THROW(read_wav(dir.path / "missing.wav"), Error);
}

}  // namespace
}  // namespace toonray
