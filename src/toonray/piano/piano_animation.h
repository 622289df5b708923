#pragma once
/// Playback: the piano's pose at any time t of a score, as a player piano would play it.
///
/// Keys: a key starts down `attack` seconds before its note's onset and reaches the bottom at
/// the onset, as on a real piano, where the note sounds when the key bottoms out; it holds, and
/// comes up over `release` seconds from the note's end. A key counts as *down* when it is at
/// least kKeyDownDepth (80%) of the way down; every note's key is fully down from its onset
/// and stays so at least until onset + min_hold (1/24 s by default), so the first frame at or
/// after an onset, at any frame rate from 24 fps up, shows it down. When the same key sounds
/// again, the earlier note's hold is shortened so that the key is fully up for `min_up` seconds
/// before the next press begins (the release stays visible at 24 fps). If notes on one key are
/// closer than attack + min_hold + release + min_up, the hold wins and the key comes only
/// partly up.
///
/// Roll: the paper advances at RollGeometry::paper_speed from t = 0 (so a slot punched at a
/// note's onset reaches the tracker bar then) until the last note has ended, then stops.
/// Pedals: pump alternately, one stroke per foot per `pedal_cycle`, starting `pedal_lead`
/// seconds before the first note and stopping after the last, easing in and out.

#include <array>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/piano/piano_pose.h"
#include "toonray/score/score.h"

namespace toonray {

/// Depth (0 = rest, 1 = fully pressed) from which a key counts as down.
inline constexpr float kKeyDownDepth = 0.8f;

struct PlaybackSettings {
    double attack = 0.015;         ///< seconds from rest to fully down, ending at the onset
    double release = 0.025;        ///< seconds from fully down to rest
    double min_hold = 1.0 / 24.0;  ///< a key stays fully down at least this long after onset
    double min_up = 1.0 / 24.0;    ///< fully up at least this long between presses of one key
    float key_dip_angle = kKeyDipAngle;
    double pedal_cycle = 1.2;  ///< seconds per pumping cycle (each pedal pressed once)
    float pedal_stroke = kPedalStrokeAngle;
    double pedal_lead = 0.8;  ///< pumping starts this long before the first note
    double pedal_ease = 0.5;  ///< seconds to ease pumping in and out
    RollGeometry roll;        ///< paper speed and window (keep it the model's)
};

/// One press of a key after the adjustments above.
struct KeyPress {
    double on = 0.0;   ///< the note's onset: fully down (it starts `attack` earlier)
    double off = 0.0;  ///< starts coming up
    float start_depth =
        0.0f;  ///< depth at on - attack (above 0 only when presses crowd each other)
};

class PianoPlayback {
public:
    /// Notes outside the 88 keys are ignored; they are counted and reported in warnings().
    explicit PianoPlayback(const Score& score, const PlaybackSettings& settings = {});

    /// The pose at time t (seconds; any t, before, during or after the score).
    [[nodiscard]] PianoPose pose_at(double t) const;

    /// Depth of the key for MIDI note `midi` at time t: 0 = rest, 1 = fully pressed.
    /// Keys outside 21..108 are always 0.
    [[nodiscard]] float key_depth(int midi, double t) const;
    /// True when the key is at least kKeyDownDepth down.
    [[nodiscard]] bool is_key_down(int midi, double t) const {
        return key_depth(midi, t) >= kKeyDownDepth;
    }
    [[nodiscard]] float roll_position(double t) const;
    [[nodiscard]] std::array<float, 2> pedal_angles(double t) const;

    /// The presses of one key (MIDI 21..108), by onset.
    [[nodiscard]] const std::vector<KeyPress>& presses(int midi) const;
    /// The score's slots for the roll (pass to pose_piano).
    [[nodiscard]] const PunchedRoll& roll() const { return roll_; }
    /// Hole pool size the model needs for this score (PianoOptions::hole_capacity).
    [[nodiscard]] std::uint32_t hole_capacity() const {
        return static_cast<std::uint32_t>(roll_.max_visible());
    }
    [[nodiscard]] int ignored_notes() const { return ignored_; }
    [[nodiscard]] const Warnings& warnings() const { return warnings_; }
    /// First onset and the time the last key is back up (0 and 0 for an empty score).
    [[nodiscard]] double start_time() const { return start_; }
    [[nodiscard]] double end_time() const { return end_; }
    [[nodiscard]] const PlaybackSettings& settings() const { return settings_; }

private:
    [[nodiscard]] float press_depth(const KeyPress& p, double t) const;

    PlaybackSettings settings_;
    std::array<std::vector<KeyPress>, kPianoKeys> presses_;
    PunchedRoll roll_;
    double start_ = 0.0, end_ = 0.0;
    double music_end_ = 0.0;  ///< last note end (the roll stops here)
    int ignored_ = 0;
    bool has_notes_ = false;
    Warnings warnings_;
};

}  // namespace toonray
