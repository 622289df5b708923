#pragma once
/// Loading, saving and converting scores by file: a Standard MIDI File (recognised by its
/// "MThd" magic, whatever the file is called) or a note script (anything else).

#include <filesystem>

#include "toonray/core/error.h"
#include "toonray/score/midi.h"
#include "toonray/score/note_script.h"
#include "toonray/score/score.h"
#include "toonray/score/timed_score.h"

namespace toonray {

/// Reads a score in ticks, choosing the format by content. Throws Error naming the file and
/// the line (note script) or byte offset (MIDI).
[[nodiscard]] TimedScore load_timed_score(const std::filesystem::path& path,
                                          Warnings* warnings = nullptr,
                                          const MidiLimits& limits = {});

/// Reads a score in seconds, choosing the format by content.
[[nodiscard]] Score load_score(const std::filesystem::path& path, Warnings* warnings = nullptr,
                               const MidiLimits& limits = {});

/// Writes a score atomically, choosing the format by extension (case-insensitive): ".mid" or
/// ".midi" for MIDI, ".notes" for a note script; any other extension is an Error.
void save_score(const TimedScore& score, const std::filesystem::path& path);

/// `toonray score convert`: loads `in` (either format) and saves it as `out` (by extension).
/// MIDI -> note script -> MIDI keeps every note (start, end, key, velocity, track, channel),
/// the tempo map, time signatures and sustain pedal; other events are dropped.
void convert_score(const std::filesystem::path& in, const std::filesystem::path& out,
                   Warnings* warnings = nullptr);

}  // namespace toonray
