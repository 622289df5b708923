#pragma once
/// Batch rendering of numbered frames: `toonray batch keys 1 2229`.

#include <atomic>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "toonray/anim/frame_pattern.h"
#include "toonray/anim/frame_scheduler.h"
#include "toonray/frame/frame_renderer.h"
#include "toonray/scene/gltf_animation.h"
#include "toonray/scene/scene_source.h"

namespace toonray {

/// Shard K of N (1-based): frames are dealt out interleaved, so shard K renders the frames at
/// positions K-1, K-1+N, K-1+2N, ... of the range. Every shard gets an even share of slow
/// and fast parts of an animation, and all N shards together cover each frame exactly once.
struct Shard {
    int index = 1;
    int count = 1;
};

/// Parses "K/N" with 1 <= K <= N. Throws Error ("shard 'TEXT': ...").
Shard parse_shard(const std::string& text);

/// The shard from a Slurm job array: K = SLURM_ARRAY_TASK_ID - SLURM_ARRAY_TASK_MIN + 1 and
/// N = SLURM_ARRAY_TASK_COUNT (MIN defaults to 1 when absent). nullopt when not in an array.
/// Throws Error when the variables are present but inconsistent.
std::optional<Shard> shard_from_environment();

/// The frames of [first, last] that belong to `shard`, in order. Throws Error when first > last
/// or when there would be more than limits().max_frames (checked before allocating).
std::vector<int> shard_frames(int first, int last, const Shard& shard);

struct BatchOptions {
    /// Animation name, e.g. "keys"; or a .gltf/.glb file, whose frame N is the file posed at
    /// N / gltf_fps seconds (docs/gltf.md)
    std::string name;
    int first = 1, last = 1;
    std::filesystem::path input_dir = ".";
    std::filesystem::path output_dir = ".";
    std::optional<std::string> input_pattern;   ///< default: see default_input_patterns()
    std::optional<std::string> output_pattern;  ///< default: NAME_%06d.png
    FrameOptions render;
    /// Auto-smooth, camera and lights (scene/scene_source.h): frames are lit by scene.lights
    /// when given, else by each frame's lights file or the glTF file's lights, else by the
    /// default light.
    SceneSetup scene;
    int jobs = 0;            ///< frames rendered at once; 0 = one per hardware thread
    bool resume = false;     ///< skip frames whose PNG exists and is valid
    bool fail_fast = false;  ///< stop at the first failed frame
    Shard shard;
    const std::atomic<bool>* cancel = nullptr;  ///< set (e.g. by SIGINT) to stop cleanly
    GltfPoseOptions gltf;                       ///< for a glTF file: the animation and camera
    double gltf_fps = 24.0;                     ///< for a glTF file: frames per second
};

/// Renders the frames. Frames that fail are reported and the rest go on (unless fail_fast).
/// Output is byte-identical for any number of jobs and threads. Throws Error only for
/// problems with the whole run (bad pattern or range, unwritable output directory).
BatchReport run_batch(const BatchOptions& options, BatchObserver* observer = nullptr);

}  // namespace toonray
