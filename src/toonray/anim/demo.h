#pragma once
/// The main job: a movie of the player piano playing a score (by default the built-in
/// "The Entertainer"), with its soundtrack. Writes DIR/frames/entertainer_NNNNNN.png,
/// DIR/entertainer.wav and DIR/entertainer.mp4.

#include <filesystem>
#include <optional>
#include <string>

#include "toonray/anim/piano_movie.h"
#include "toonray/media/audio.h"
#include "toonray/media/encode.h"

namespace toonray {

struct DemoOptions {
    std::filesystem::path output_dir = "out";
    std::optional<double> seconds = 30.0;  ///< nullopt: the whole piece
    PianoMovieOptions movie;               ///< fps, start, size, lines, jobs, resume, cancel
    std::filesystem::path soundfont;       ///< empty: the default General MIDI piano
};

struct DemoReport {
    PianoMovieReport movie;
    AudioResult audio;
    EncodeResult encode;
    std::filesystem::path movie_path, audio_path;
    bool completed = false;  ///< false when frames failed or the run was cancelled
};

/// Progress of the demo's stages, for the command line.
class DemoObserver : public BatchObserver {
public:
    virtual void stage(const std::string& what) = 0;
};

/// Renders the frames (removing frames left over from a longer earlier run, so they cannot
/// join the movie), synthesises the audio for the same stretch of the score and encodes the
/// movie. Throws Error for a bad score, soundfont or encoder failure.
DemoReport run_demo(const Score& score, const CameraPath& camera_path, const DemoOptions& options,
                    DemoObserver* observer = nullptr);

}  // namespace toonray
