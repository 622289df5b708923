#pragma once
/// The note script's key names: white keys w1..w52 and black keys b1..b36, each counted from
/// the lowest key of an 88-key piano (A0 = MIDI 21), so w1 = A0 = 21, b1 = A#0 = 22,
/// w2 = B0 = 23, w24 = C4 (middle C) = 60, w52 = C8 = 108.

#include <string>

namespace toonray {

inline constexpr int kPianoLowestKey = 21;    ///< A0
inline constexpr int kPianoHighestKey = 108;  ///< C8
inline constexpr int kPianoWhiteKeys = 52;
inline constexpr int kPianoBlackKeys = 36;

/// True for the MIDI keys of black piano keys (C#, D#, F#, G#, A#).
[[nodiscard]] constexpr bool is_black_key(int midi) {
    int pc = ((midi % 12) + 12) % 12;
    return pc == 1 || pc == 3 || pc == 6 || pc == 8 || pc == 10;
}

/// MIDI key of white key `n` (1..52), or -1 when there is no such key.
[[nodiscard]] int white_key(int n);

/// MIDI key of black key `n` (1..36), or -1 when there is no such key.
[[nodiscard]] int black_key(int n);

/// Script name of a MIDI key: "w24" or "b12" on the piano, "m12" (the raw MIDI number) outside.
[[nodiscard]] std::string key_name(int midi);

}  // namespace toonray
