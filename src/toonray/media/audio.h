#pragma once
/// Audio for the demo: a Score played on a SoundFont piano by the FluidSynth library, rendered
/// offline to a 16-bit stereo WAV whose sample 0 is score time `start` (0 by default), so the
/// soundtrack lines up with frame 0 of the video without any offset.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "toonray/core/error.h"
#include "toonray/media/wav.h"
#include "toonray/score/score.h"

namespace toonray {

/// The General MIDI SoundFont installed by the Debian package fluid-soundfont-gm.
std::filesystem::path default_soundfont();

struct AudioOptions {
    std::filesystem::path soundfont;  ///< .sf2 file; empty = default_soundfont()
    int sample_rate = 44100;          ///< 8000..192000
    int bank = 0;                     ///< preset bank in the SoundFont
    int program = 0;                  ///< GM program; 0 = Acoustic Grand Piano
    /// Window in score seconds: notes starting in [start, start + length) are played, shifted so
    /// that `start` is sample 0. Without a length the file runs to the end of the score plus
    /// `tail`; with one it is exactly `length` seconds long, cut at its end with a `fade`.
    double start = 0.0;
    std::optional<double> length;
    double tail = 2.0;   ///< seconds kept after the score's end for the release to ring out
    double fade = 0.05;  ///< raised-cosine fade over the file's last seconds (no click at a cut)
    float gain = 0.7f;   ///< FluidSynth master gain (0.2, its default, is quiet for solo piano;
                         ///< 0.7 peaks at -3 dBFS on The Entertainer)
    bool reverb = true;  ///< FluidSynth's reverb (deterministic; chorus is always off)
};

struct AudioResult {
    WavAudio audio;            ///< 2 channels at options.sample_rate
    int notes = 0;             ///< notes played (those starting in the window)
    std::string preset;        ///< name of the SoundFont preset used
    float peak = 0.0f;         ///< largest absolute sample before clamping, 1 = full scale
    std::int64_t clipped = 0;  ///< samples clamped to the 16-bit range
    Warnings warnings;         ///< clipping, preset fallback, FluidSynth warnings
};

/// Renders the score to memory. Events are sent to FluidSynth between rendering calls split at
/// their exact sample; FluidSynth starts voices on its 64-sample internal block, so an onset is
/// at most 63 samples (1.4 ms at 44.1 kHz) late, and a note at t = start is at sample 0.
/// Output is deterministic: the same score and options give the same samples.
/// Throws Error: soundfont missing, unreadable or invalid (path named); no notes in the window;
/// invalid options or note values.
AudioResult synthesize_score(const Score& score, const AudioOptions& options = {});

/// synthesize_score, then writes the WAV atomically to `wav`.
AudioResult render_audio(const Score& score, const std::filesystem::path& wav,
                         const AudioOptions& options = {});

}  // namespace toonray
