#pragma once
/// A score in MIDI ticks with its tempo map: the lossless form behind both file formats.
/// Readers fill it, writers consume it, and `to_score` turns it into seconds for playback.

#include <cstdint>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/score/score.h"

namespace toonray {

/// MIDI's tempo when a file sets none: 120 quarter notes per minute.
inline constexpr std::uint32_t kMidiDefaultTempo = 500000;

/// One note in ticks. `end` > `start` after `normalize`.
struct TimedNote {
    std::int64_t start = 0;
    std::int64_t end = 0;
    int key = 60;       ///< MIDI note number 0..127
    int velocity = 80;  ///< 1..127
    int track = 0;      ///< MIDI track chunk index (0-based) or note-script track
    int channel = 0;    ///< MIDI channel 0..15

    friend bool operator==(const TimedNote&, const TimedNote&) = default;
};

/// From `tick` on, a quarter note lasts `us_per_quarter` microseconds.
struct TempoChange {
    std::int64_t tick = 0;
    std::uint32_t us_per_quarter = kMidiDefaultTempo;  ///< 1..0xFFFFFF (24 bits in MIDI)

    friend bool operator==(const TempoChange&, const TempoChange&) = default;
};

/// A time signature such as 2/4 from `tick` on. Informational: it does not change timing.
struct TimeSignature {
    std::int64_t tick = 0;
    int numerator = 4;    ///< 1..255
    int denominator = 4;  ///< a power of two, 1..128

    friend bool operator==(const TimeSignature&, const TimeSignature&) = default;
};

/// A sustain pedal controller (CC64) value; 64 and above means down.
struct PedalChange {
    std::int64_t tick = 0;
    int value = 0;  ///< 0..127
    int track = 0;
    int channel = 0;

    [[nodiscard]] bool down() const { return value >= 64; }
    friend bool operator==(const PedalChange&, const PedalChange&) = default;
};

struct TimedScore {
    int ppq = 384;                               ///< ticks per quarter note, 1..32767
    std::vector<TimedNote> notes;                ///< sorted by start, key, track, channel, end
    std::vector<TempoChange> tempo;              ///< sorted, one per tick, tempo[0].tick == 0
    std::vector<TimeSignature> time_signatures;  ///< sorted, one per tick
    std::vector<PedalChange> pedal;  ///< sorted by tick, track, channel; else in file order
    /// End of the piece: the latest MIDI end-of-track, or where a note script's last line
    /// ends; never before the last event. Trailing rests make it later than the last note.
    std::int64_t end_tick = 0;

    /// Seconds from the start at `tick`, through the tempo map (MIDI's 120 bpm if it is empty).
    [[nodiscard]] double seconds_at(std::int64_t tick) const;

    friend bool operator==(const TimedScore&, const TimedScore&) = default;
};

/// Puts a score in the canonical form both readers produce, so that reading, writing and
/// reading again changes nothing:
/// - tempo changes and time signatures sorted by tick, the last one at a tick winning; a tempo
///   at tick 0 added (`default_tempo`) when missing;
/// - pedal changes stably sorted by tick, track and channel;
/// - `end_tick` moved to the last note end or event when it is earlier;
/// - notes sorted; where two notes of one key on the same track and channel overlap, the
///   earlier one is cut off where the later one starts (a piano key cannot be struck while it
///   is down, and MIDI cannot tell such notes apart); notes left without length are dropped.
/// Reports the notes it shortened or dropped in `warnings` (when given), naming `file`.
void normalize(TimedScore& score, std::uint32_t default_tempo = kMidiDefaultTempo,
               Warnings* warnings = nullptr, std::string_view file = {});

/// The score in seconds. Pedal changes from all tracks and channels merge into one pedal; only
/// changes of state (up to down, down to up) are kept.
[[nodiscard]] Score to_score(const TimedScore& score);

}  // namespace toonray
