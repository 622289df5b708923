#pragma once
/// A score as timed note events: what the piano animation and the audio synthesis both play.
/// Loaded from a note script (the seed's format and our extension) or a Standard MIDI File.

#include <cstdint>
#include <filesystem>
#include <vector>

namespace toonray {

/// One note. Times in seconds from the start of the score.
struct Note {
    double start = 0.0;
    double end = 0.0;
    int key = 60;       ///< MIDI note number; an 88-key piano spans 21 (A0) to 108 (C8)
    int velocity = 80;  ///< 1..127
    int track = 0;      ///< source track (MIDI) or 0 (note script)
};

/// Sustain pedal (MIDI CC64) changes.
struct PedalEvent {
    double time = 0.0;
    bool down = false;
};

struct Score {
    std::vector<Note> notes;          ///< sorted by start, then key
    std::vector<PedalEvent> sustain;  ///< sorted by time
    /// End of the piece including a final rest (MIDI end of track, a note script's last line);
    /// never before duration(). 0 when unknown, as in a Score built by hand.
    double end_time = 0.0;
    /// End of the last note (or pedal event), in seconds.
    [[nodiscard]] double duration() const;
};

}  // namespace toonray
