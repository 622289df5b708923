#pragma once
/// Note scripts: the seed's line-per-eighth text format and our backward-compatible extension
/// (docs/scores.md describes both in full).
///
/// Seed: each non-empty line is one step of an eighth note. "E:w26,w28,w30" starts eighth notes
/// on white keys 26, 28 and 30; Q, H and W are quarter, half and whole notes; "|" separates
/// groups of different lengths ("E:w30,w37|H:w16,w19"); "Empty" starts nothing.
///
/// Extension: S, T, X (16th, 32nd, 64th), dots ("Q."), ties as sums ("Q+S"), durations in
/// ticks ("100"), keys by MIDI number ("m60"), per-note velocity ("w24@100"), `#` comments,
/// and directive lines: ppq, tempo, time, step, wait, velocity, track, channel, pedal.

#include <cstdint>
#include <string>
#include <string_view>

#include "toonray/core/error.h"
#include "toonray/score/timed_score.h"

namespace toonray {

inline constexpr int kScriptDefaultPpq = 384;                 ///< ticks per quarter
inline constexpr std::uint32_t kScriptDefaultTempo = 833333;  ///< 72 quarters per minute
inline constexpr int kScriptDefaultVelocity = 80;             ///< mezzo-forte
inline constexpr int kScriptMaxTrack = 1023;                  ///< fits MidiLimits::max_tracks

/// Parses a note script; `file` names it in messages. Throws Error("file:line: reason") on the
/// first bad line. Overlapping notes of one key and voice are cut short (see `normalize`) and
/// reported in `warnings` when given. The result is normalized.
[[nodiscard]] TimedScore parse_note_script(std::string_view text, std::string_view file,
                                           Warnings* warnings = nullptr);

/// Writes a score as a note script that parses back to the same TimedScore (for a normalized
/// score with keys 0..127, velocities 1..127, channels 0..15 and tracks 0..1023): one section
/// per track and channel, one line per step, the step being the largest duration (at most a
/// whole note) that every event time of the section is a multiple of.
[[nodiscard]] std::string write_note_script(const TimedScore& score);

}  // namespace toonray
