#pragma once
/// Standard MIDI Files (SMF): a reader for formats 0 and 1 and a format 1 writer.
///
/// The reader takes note on/off (note-on with velocity 0 is a note-off), the sustain pedal
/// (controller 64), tempo (FF 51) and time signature (FF 58) events; every other event (other
/// controllers, program changes, pitch bend, text and other meta events, sysex) is skipped by
/// its length. Running status is honoured, also across meta and sysex events (the standard
/// cancels it there, but some writers rely on it and a valid file never notices). Unknown
/// chunk types are skipped, as the standard asks. SMPTE time division is read exactly, as
/// ticks per quarter at a tempo of one (or 1.001 for 29.97 fps) second per quarter.
///
/// Notes are paired first in, first out per track, channel and key, so a second note-on of a
/// sounding key does not end it; `normalize` then cuts the earlier note where the later one
/// starts. A note still sounding at the end of its track ends there (with a warning). Every
/// error names the file and the byte offset: "song.mid: byte 1234: truncated track chunk".
/// Work is linear in the file size and bounded by `MidiLimits`, so no input crashes, hangs or
/// exhausts memory.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/score/timed_score.h"

namespace toonray {

/// Bounds on what a (possibly hostile) file may ask for.
struct MidiLimits {
    std::size_t max_tracks = 1024;        ///< track chunks announced by the header
    std::size_t max_events = 10'000'000;  ///< events of all kinds over all tracks
};

/// True when `bytes` start with the "MThd" chunk of a Standard MIDI File.
[[nodiscard]] bool is_midi(std::span<const std::uint8_t> bytes);

/// Reads a Standard MIDI File of format 0 or 1. `file` names it in messages. Throws Error on
/// malformed input or exceeded limits; notes never released and similar oddities go to
/// `warnings` when given. The result is normalized (see `normalize`).
[[nodiscard]] TimedScore read_midi(std::span<const std::uint8_t> bytes, std::string_view file,
                                   Warnings* warnings = nullptr, const MidiLimits& limits = {});

/// Writes a format 1 Standard MIDI File: track 0 holds the tempo map and time signatures,
/// track N the notes and pedal changes of track N (note-offs as note-on with velocity 0, with
/// running status); every track ends at `end_tick`. At one tick, note-offs come before pedal
/// changes and note-ons. Throws Error
/// when the score cannot be written as MIDI (a value out of range, a gap between events longer
/// than 2^28 - 1 ticks, more than 65535 tracks).
[[nodiscard]] std::vector<std::uint8_t> write_midi(const TimedScore& score);

}  // namespace toonray
