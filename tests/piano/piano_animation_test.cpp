#include "toonray/piano/piano_animation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace toonray {
namespace {

constexpr double kFrame = 1.0 / 24.0;

/// A small hand-made score: a melody, a chord, a long bass note, staccato notes, repeated
/// notes (back to back, overlapping, and quick), a note at t = 0 and two out of range.
Score hand_score() {
    Score s;
    auto add = [&](double start, double end, int key) {
        s.notes.push_back({start, end, key, 80, 0});
    };
    add(0.0, 0.4, 60);
    add(0.5, 0.9, 62);
    add(1.0, 1.4, 64);
    for (int k : {60, 64, 67}) add(1.5, 2.5, k);  // chord
    add(0.2, 3.0, 36);                            // long bass note
    add(2.6, 2.62, 72);                           // staccato, 20 ms
    add(2.7, 2.71, 74);
    add(3.0, 3.5, 69);  // repeated, back to back
    add(3.5, 4.0, 69);
    add(4.0, 4.6, 69);
    add(5.0, 5.6, 57);  // repeated, overlapping in the score
    add(5.4, 6.0, 57);
    add(6.2, 6.32, 50);  // quick repeats, 125 ms apart
    add(6.325, 6.45, 50);
    add(6.45, 6.6, 50);
    add(1.0, 1.2, 12);   // below A0
    add(1.0, 1.2, 115);  // above C8
    std::sort(s.notes.begin(), s.notes.end(), [](const Note& a, const Note& b) {
        return a.start < b.start || (a.start == b.start && a.key < b.key);
    });
    return s;
}

TEST(PianoPlayback, EveryKeyIsDownFromItsOnsetForAFrame) {
    const Score score = hand_score();
    const PianoPlayback play(score);
    int checked = 0;
    for (const Note& n : score.notes) {
        if (n.key < 21 || n.key > 108) continue;
        // Fully down at the onset itself and for a whole 24 fps frame after it, so the frame
        // showing the onset shows the key down.
        for (double dt : {0.0, 0.5 * kFrame, kFrame})
            EXPECT_GE(play.key_depth(n.key, n.start + dt), 1.0f)
                << "key " << n.key << " at " << n.start << "+" << dt;
        // The press starts before the onset: already half down half an attack earlier.
        EXPECT_GT(play.key_depth(n.key, n.start - 0.5 * play.settings().attack), 0.4f);
        ++checked;
    }
    EXPECT_EQ(checked, 17);
}

TEST(PianoPlayback, KeysComeBackUpAfterRelease) {
    const Score score = hand_score();
    const PianoPlayback play(score);
    const double release = play.settings().release;
    for (const Note& n : score.notes) {
        if (n.key < 21 || n.key > 108) continue;
        // Up again a release after the note's (possibly shortened) end, unless the key is
        // struck again by then.
        const auto& presses = play.presses(n.key);
        auto p = std::find_if(presses.begin(), presses.end(),
                              [&](const KeyPress& k) { return k.on == n.start; });
        ASSERT_NE(p, presses.end());
        EXPECT_LE(p->off, std::max(n.end, n.start + play.settings().min_hold) + 1e-9);
        const double up = p->off + release + 1e-6;
        const bool struck_again = p + 1 != presses.end() && (p + 1)->on <= up;
        if (!struck_again) {
            EXPECT_EQ(play.key_depth(n.key, up), 0.0f) << "key " << n.key << " at " << n.start;
        }
        // Still down just before the release begins.
        EXPECT_TRUE(play.is_key_down(n.key, p->off - 1e-6));
    }
    // Keys never played stay at rest; everything is up after the end.
    for (double t = 0.0; t < 7.0; t += 0.01) EXPECT_EQ(play.key_depth(100, t), 0.0f);
    for (int k = 21; k <= 108; ++k) EXPECT_EQ(play.key_depth(k, play.end_time() + 1e-6), 0.0f);
}

/// Smallest depth over (from, to) sampled at 24 fps with the given phase.
float lowest_frame(const PianoPlayback& play, int key, double from, double to, double phase) {
    float lowest = 1.0f;
    for (double t = std::ceil((from - phase) / kFrame) * kFrame + phase; t < to; t += kFrame)
        if (t > from) lowest = std::min(lowest, play.key_depth(key, t));
    return lowest;
}

TEST(PianoPlayback, RepeatedNotesVisiblyReleaseAndRepress) {
    const Score score = hand_score();
    const PianoPlayback play(score);
    // (key, first onset, second onset) of same-key notes that follow each other.
    const struct {
        int key;
        double a, b;
    } repeats[] = {
        {69, 3.0, 3.5}, {69, 3.5, 4.0}, {57, 5.0, 5.4}, {50, 6.2, 6.325}, {50, 6.325, 6.45}};
    for (const auto& r : repeats) {
        // Fully up for at least a frame between the presses...
        double up_from = -1.0, up_to = -1.0;
        for (double t = r.a; t < r.b; t += 0.0005) {
            if (play.key_depth(r.key, t) == 0.0f) {
                if (up_from < 0.0) up_from = t;
                up_to = t;
            }
        }
        ASSERT_GE(up_from, 0.0) << "key " << r.key << " never comes up between " << r.a << " and "
                                << r.b;
        EXPECT_GE(up_to - up_from, kFrame - 0.001) << r.key << " at " << r.a;
        // ...so whatever the frame phase, some 24 fps frame shows it up...
        for (double phase = 0.0; phase < kFrame; phase += kFrame / 7.0)
            EXPECT_LE(lowest_frame(play, r.key, r.a + kFrame, r.b, phase), 1.0f - kKeyDownDepth)
                << r.key << " at " << r.a << " phase " << phase;
        // ...and it is down again a frame after the second onset.
        EXPECT_TRUE(play.is_key_down(r.key, r.b + kFrame));
    }
    // The overlapping pair (57: 5.0-5.6 and 5.4-6.0) was shortened, not merged.
    EXPECT_EQ(play.presses(57).size(), 2u);
    EXPECT_LT(play.presses(57)[0].off, 5.4 - play.settings().release);
}

TEST(PianoPlayback, PressesTooCloseStillShowEachOnset) {
    // Same key 60 ms apart: too close for a full release; every onset still shows the key down
    // a frame later and the key rises between the presses.
    Score s;
    s.notes.push_back({1.0, 1.05, 64, 80, 0});
    s.notes.push_back({1.06, 1.2, 64, 80, 0});
    const PianoPlayback play(s);
    EXPECT_TRUE(play.is_key_down(64, 1.0 + kFrame));
    EXPECT_TRUE(play.is_key_down(64, 1.06 + kFrame));
    const auto& presses = play.presses(64);
    ASSERT_EQ(presses.size(), 2u);
    EXPECT_GE(presses[0].off, 1.0 + play.settings().min_hold - 1e-9);
    EXPECT_GT(presses[1].start_depth, 0.0f);
    EXPECT_LT(presses[1].start_depth, 1.0f);
}

TEST(PianoPlayback, OutOfRangeNotesAreCountedAndIgnored) {
    const PianoPlayback play(hand_score());
    EXPECT_EQ(play.ignored_notes(), 2);
    ASSERT_EQ(play.warnings().size(), 1u);
    EXPECT_NE(play.warnings()[0].find("2 notes"), std::string::npos);
    EXPECT_EQ(play.key_depth(12, 1.1), 0.0f);
    EXPECT_EQ(play.key_depth(115, 1.1), 0.0f);
    EXPECT_EQ(play.roll().ignored_notes(), 2);
    EXPECT_THROW((void)play.presses(12), Error);
}

TEST(PianoPlayback, AttackAndReleaseShapes) {
    Score s;
    s.notes.push_back({2.0, 3.0, 60, 80, 0});
    const PianoPlayback play(s);
    const auto& st = play.settings();
    EXPECT_EQ(play.key_depth(60, 1.999 - st.attack), 0.0f);
    EXPECT_EQ(play.key_depth(60, 2.0 - st.attack), 0.0f);
    EXPECT_NEAR(play.key_depth(60, 2.0 - 0.5 * st.attack), 0.5f, 1e-4f);
    EXPECT_NEAR(play.key_depth(60, 2.0), 1.0f, 1e-6f);
    EXPECT_EQ(play.key_depth(60, 3.0), 1.0f);
    EXPECT_NEAR(play.key_depth(60, 3.0 + 0.5 * st.release), 0.5f, 1e-4f);
    EXPECT_NEAR(play.key_depth(60, 3.0 + st.release), 0.0f, 1e-6f);
    EXPECT_EQ(play.key_depth(60, 3.0 + st.release + 1e-9), 0.0f);
    EXPECT_DOUBLE_EQ(play.start_time(), 2.0);
    EXPECT_DOUBLE_EQ(play.end_time(), 3.0 + st.release);
    // The pose carries the depth as an angle.
    PianoPose pose = play.pose_at(2.0 - 0.5 * st.attack);
    EXPECT_NEAR(pose.key_angle[60 - 21], 0.5f * kKeyDipAngle, 1e-6f);
    for (int k = 0; k < kPianoKeys; ++k) {
        if (k != 60 - 21) {
            EXPECT_EQ(pose.key_angle[static_cast<std::size_t>(k)], 0.0f);
        }
    }
}

TEST(PianoPlayback, RollRunsAtConstantSpeedWhileMusicPlays) {
    const Score score = hand_score();
    const PianoPlayback play(score);
    const double v = play.settings().roll.paper_speed;
    EXPECT_EQ(play.roll_position(-1.0), 0.0f);
    EXPECT_EQ(play.roll_position(0.0), 0.0f);
    for (double t = 0.5; t < 6.0; t += 0.37) {
        EXPECT_NEAR(play.roll_position(t), v * t, 1e-6);
        EXPECT_NEAR(play.roll_position(t + kFrame) - play.roll_position(t), v * kFrame, 1e-6);
    }
    // It stops when the music does (the last note ends at 6.6 s).
    EXPECT_NEAR(play.roll_position(6.6), v * 6.6, 1e-6);
    EXPECT_EQ(play.roll_position(7.0), play.roll_position(100.0));
    EXPECT_EQ(play.pose_at(3.3).roll_position, play.roll_position(3.3));
}

TEST(PianoPlayback, PedalsPumpAlternatelyWhilePlaying) {
    Score s;
    for (int i = 0; i < 20; ++i)
        s.notes.push_back({2.0 + 0.5 * i, 2.4 + 0.5 * i, 60 + i % 12, 80, 0});
    const PianoPlayback play(s);
    const auto& st = play.settings();
    // At rest well before and after the music.
    EXPECT_EQ(play.pedal_angles(0.0)[0], 0.0f);
    EXPECT_EQ(play.pedal_angles(0.0)[1], 0.0f);
    EXPECT_EQ(play.pedal_angles(play.end_time() + 1.0)[0], 0.0f);
    EXPECT_EQ(play.pedal_angles(play.end_time() + 1.0)[1], 0.0f);
    // While playing: both move, in opposition (one down while the other is up), each through
    // a full stroke.
    float min_l = 1.0f, max_l = 0.0f, max_r = 0.0f;
    for (double t = 3.0; t < 10.0; t += 0.01) {
        auto a = play.pedal_angles(t);
        EXPECT_NEAR(a[0] + a[1], st.pedal_stroke, 1e-5f) << t;
        EXPECT_GE(a[0], 0.0f);
        EXPECT_GE(a[1], 0.0f);
        min_l = std::min(min_l, a[0]);
        max_l = std::max(max_l, a[0]);
        max_r = std::max(max_r, a[1]);
    }
    EXPECT_LT(min_l, 0.01f * st.pedal_stroke);
    EXPECT_GT(max_l, 0.99f * st.pedal_stroke);
    EXPECT_GT(max_r, 0.99f * st.pedal_stroke);
    // Pumping already under way at the first note.
    auto first = play.pedal_angles(2.0);
    EXPECT_NEAR(first[0] + first[1], st.pedal_stroke, 0.02f * st.pedal_stroke);
    EXPECT_EQ(play.pose_at(4.2).pedal_angle, play.pedal_angles(4.2));
}

TEST(PianoPlayback, EmptyScoreIsAtRest) {
    const PianoPlayback play{Score{}};
    const PianoPose pose = play.pose_at(3.0);
    for (float a : pose.key_angle) EXPECT_EQ(a, 0.0f);
    EXPECT_EQ(pose.roll_position, 0.0f);
    EXPECT_EQ(pose.pedal_angle[0], 0.0f);
    EXPECT_EQ(pose.pedal_angle[1], 0.0f);
    EXPECT_EQ(play.hole_capacity(), 0u);
}

}  // namespace
}  // namespace toonray
