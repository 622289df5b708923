#pragma once
/// "The Entertainer": the procedural player piano playing a score, rendered frame by frame
/// along a camera path, with its soundtrack and the finished movie.
///
/// Frame i (1-based, as the seed's `keys 1 2229`) shows score time start + (i - 1) / fps.
/// In memory, each job poses its own copy of the piano and renders it (refitting its BVH, see
/// AnimationAccel); exporting, it writes the seed's files instead, one OBJ + MTL per frame with
/// the camera block, which `toonray batch` renders to the same images.

#include <atomic>
#include <filesystem>
#include <optional>
#include <span>
#include <string>

#include "toonray/anim/batch.h"
#include "toonray/anim/camera_path.h"
#include "toonray/frame/frame_renderer.h"
#include "toonray/score/score.h"

namespace toonray {

/// The demo's assets, compiled into the program.
std::span<const unsigned char> demo_score_midi();
std::span<const unsigned char> demo_camera_path();
/// The demo score (The Entertainer) and its default camera path, parsed.
Score load_demo_score();
CameraPath load_demo_camera_path();

struct PianoMovieOptions {
    double start = 0.0;             ///< score time of frame 1, seconds
    std::optional<double> seconds;  ///< length; default: to the end of the music
    double fps = 24.0;
    std::string name = "keys";         ///< frames are NAME_NNNNNN.png (or .obj)
    std::filesystem::path output_dir;  ///< PNG frames go here
    /// Write OBJ + MTL frames here instead of rendering PNGs.
    std::optional<std::filesystem::path> export_obj_dir;
    FrameOptions render;  ///< size, lines, AOVs, PNG level
    SceneSetup scene;     ///< auto-smooth, lights; a camera here replaces the camera path
    int jobs = 0;         ///< frames at once; 0 = one per core
    /// The 88 keys as instances of their shapes (instance_keys, piano/piano_pose.h): posing a
    /// frame moves 88 transforms and rebuilds the BVH's top level instead of refitting the
    /// keys' vertices. The pictures differ from the flattened keys' only along edges (hits and
    /// lines found in the keys' frames). Exported OBJ files hold the keys flattened.
    bool instanced_keys = false;
    bool resume = false;  ///< skip frames whose PNG is already valid
    const std::atomic<bool>* cancel = nullptr;
};

struct PianoMovieReport {
    BatchReport batch;  ///< frames rendered / skipped / failed, time
    int frame_count = 0;
    std::size_t triangles = 0;        ///< of the posed scene (piano and floor)
    std::uint32_t dropped_holes = 0;  ///< roll slots left out because the hole pool was full
};

/// Number of frames for `seconds` of animation at `fps` (the last frame starts before the end).
/// Saturates at INT_MAX instead of overflowing.
int frame_count(double seconds, double fps);

/// frame_count, checked against limits().max_frames: throws LimitError("S s at F fps: N frames
/// is more than the limit of M") when a score or a length asks for too many.
int checked_frame_count(double seconds, double fps);

/// Renders (or exports) the frames. Throws Error for whole-run problems (bad options, an
/// unwritable directory); per-frame failures are counted in the report.
PianoMovieReport render_piano_movie(const Score& score, const CameraPath& camera_path,
                                    const PianoMovieOptions& options,
                                    BatchObserver* observer = nullptr);

}  // namespace toonray
