#include "toonray/anim/batch.h"

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <exception>
#include <fmt/format.h>
#include <future>
#include <memory>

#include "toonray/core/error.h"
#include "toonray/anim/scene_frames.h"
#include "toonray/core/limits.h"
#include "toonray/scene/gltf_loader.h"
#include "toonray/scene/obj_loader.h"

namespace toonray {
namespace {

bool parse_int(const std::string& s, int& out) {
    if (s.empty() || s.size() > 9) return false;
    int v = 0;
    for (char c : s) {
        if (c < '0' || c > '9') return false;
        v = v * 10 + (c - '0');
    }
    out = v;
    return true;
}

// The output file pattern: the given one, else NAME_%06d.png with any % in the name escaped.
FramePattern output_pattern(const BatchOptions& options) {
    if (options.output_pattern) return FramePattern(*options.output_pattern);
    std::string escaped;
    const std::string name = is_gltf_path(options.name)
                                 ? std::filesystem::path(options.name).stem().string()
                                 : options.name;
    for (char c : name) {
        if (c == '%') escaped.push_back('%');
        escaped.push_back(c);
    }
    return FramePattern(escaped + "_%06d.png");
}

// The frames of a batch: frame N's scene is read from the OBJ file its number names.
class ObjSequenceSource : public SceneSource {
public:
    ObjSequenceSource(const BatchOptions& options, SceneSetup setup, const FramePlan& plan)
        : input_dir_(options.input_dir), setup_(std::move(setup)) {
        // Each job keeps two scenes (one rendering, the next loading) and its frame buffers.
        obj_.limits.reserved_memory = plan.bytes();
        obj_.limits.scenes_in_flight = static_cast<std::uint32_t>(2 * plan.jobs);
        if (options.input_pattern) {
            input_patterns_.emplace_back(*options.input_pattern);
        } else {
            input_patterns_ = default_input_patterns(options.name);
        }
    }

    void load(int frame, SceneFrame& out, Warnings& warnings) const override {
        auto input = find_frame_file(input_dir_, input_patterns_, frame);
        if (!input) {
            std::string tried;
            for (const auto& p : input_patterns_)
                tried += (tried.empty() ? "" : ", ") + p.format(frame);
            throw Error(fmt::format("{}: no input file for frame {} (tried {})",
                                    input_dir_.string(), frame, tried));
        }
        try {
            ObjFileSource::load_file(*input, setup_, obj_, out, warnings);
        } catch (const Error&) {
            throw;
        } catch (const std::exception& e) {
            throw Error(fmt::format("frame {}: {}", frame, e.what()));
        }
    }
    [[nodiscard]] bool reads_files() const override { return true; }

private:
    std::filesystem::path input_dir_;
    SceneSetup setup_;
    std::vector<FramePattern> input_patterns_;
    ObjOptions obj_;
};

}  // namespace

Shard parse_shard(const std::string& text) {
    auto slash = text.find('/');
    Shard s;
    if (slash == std::string::npos || !parse_int(text.substr(0, slash), s.index) ||
        !parse_int(text.substr(slash + 1), s.count) || s.count < 1 || s.index < 1 ||
        s.index > s.count)
        throw Error(fmt::format("shard '{}': expected K/N with 1 <= K <= N", text));
    return s;
}

std::optional<Shard> shard_from_environment() {
    const char* id = std::getenv("SLURM_ARRAY_TASK_ID");
    const char* count = std::getenv("SLURM_ARRAY_TASK_COUNT");
    if (!id || !count) return std::nullopt;
    const char* min = std::getenv("SLURM_ARRAY_TASK_MIN");
    int task = 0, n = 0, first = 1;
    if (!parse_int(id, task) || !parse_int(count, n) || (min && !parse_int(min, first)))
        throw Error(
            fmt::format("Slurm array variables are not numbers: SLURM_ARRAY_TASK_ID={} "
                        "SLURM_ARRAY_TASK_COUNT={} SLURM_ARRAY_TASK_MIN={}",
                        id, count, min ? min : "(unset)"));
    Shard s{task - first + 1, n};
    if (s.count < 1 || s.index < 1 || s.index > s.count)
        throw Error(
            fmt::format("Slurm array task {} (min {}) is outside a {}-task array; submit "
                        "with --array=1-N for N tasks",
                        task, first, n));
    return s;
}

std::vector<int> shard_frames(int first, int last, const Shard& shard) {
    if (first > last)
        throw Error(
            fmt::format("frame range {} {}: the first frame is after the last", first, last));
    if (shard.count < 1 || shard.index < 1 || shard.index > shard.count)
        throw Error(
            fmt::format("shard {}/{}: expected K/N with 1 <= K <= N", shard.index, shard.count));
    const long long span = static_cast<long long>(last) - first;  // >= 0
    const long long count =
        span < shard.index - 1 ? 0 : (span - (shard.index - 1)) / shard.count + 1;
    if (static_cast<unsigned long long>(count) > limits().max_frames)
        throw LimitError(Limit::Frames,
                         fmt::format("frame range {} {}: {} frames is more than the limit of {}",
                                     first, last, count, limits().max_frames));
    std::vector<int> frames;
    frames.reserve(static_cast<std::size_t>(count));
    for (long long f = static_cast<long long>(first) + (shard.index - 1); f <= last;
         f += shard.count)
        frames.push_back(static_cast<int>(f));
    return frames;
}

BatchReport run_batch(const BatchOptions& options, BatchObserver* observer) {
    if (options.first < 0 || options.last < 0)
        throw Error(fmt::format("frame range {} {}: frame numbers must not be negative",
                                options.first, options.last));
    if (options.first > options.last)
        throw Error(fmt::format("frame range {} {}: the first frame is after the last",
                                options.first, options.last));
    if (options.name.empty() && !options.input_pattern)
        throw Error("batch: the animation name is empty");
    std::error_code ec;
    std::filesystem::create_directories(options.output_dir, ec);
    if (ec || ::access(options.output_dir.c_str(), W_OK) != 0)
        throw Error(fmt::format("{}: output directory cannot be created or is not writable",
                                options.output_dir.string()));
    if (options.render.aov_dir) {
        std::filesystem::create_directories(*options.render.aov_dir, ec);
        if (ec || ::access(options.render.aov_dir->c_str(), W_OK) != 0)
            throw Error(fmt::format("{}: AOV directory cannot be created or is not writable",
                                    options.render.aov_dir->string()));
    }
    if (options.render.aov_exr) check_exr_sequence(*options.render.aov_exr);
    if (options.render.svg_dir) {
        std::filesystem::create_directories(*options.render.svg_dir, ec);
        if (ec || ::access(options.render.svg_dir->c_str(), W_OK) != 0)
            throw Error(fmt::format("{}: SVG directory cannot be created or is not writable",
                                    options.render.svg_dir->string()));
    }
    std::vector<int> frames_list = shard_frames(options.first, options.last, options.shard);
    const FramePlan plan = plan_frame_jobs(options.render, options.jobs, frames_list.size());
    // The automatic camera frames the image the frames are rendered at.
    SceneSetup setup = options.scene;
    setup.width = options.render.settings.width;
    setup.height = options.render.settings.height;
    ScheduleOptions schedule;
    schedule.jobs = plan.jobs;
    schedule.resume = options.resume;
    schedule.fail_fast = options.fail_fast;
    schedule.cancel = options.cancel;
    if (is_gltf_path(options.name) && !options.input_pattern) {
        if (!(options.gltf_fps > 0.0) || !std::isfinite(options.gltf_fps))
            throw Error(fmt::format("fps {}: must be positive", options.gltf_fps));
        std::filesystem::path file = options.name;
        if (!std::filesystem::exists(file) && std::filesystem::exists(options.input_dir / file))
            file = options.input_dir / file;
        GltfOptions gltf;
        gltf.limits.reserved_memory = plan.bytes();
        Warnings warnings;
        GltfDocument document = load_gltf(file, warnings, gltf);
        // Each job poses its own scene.
        check_memory(
            plan.bytes(scene_bytes(document.vertices, document.triangles, document.instances)),
            fmt::format("{} frames of {} at once", plan.jobs, file.string()));
        GltfSource scenes(std::move(document), options.gltf, options.gltf_fps, setup);
        if (auto w = scenes.animator().aspect_warning(setup.width, setup.height))
            warnings.push_back(*w);
        if (observer)
            for (const auto& w : warnings) observer->warning(options.first, w);
        // Without a camera, one automatic camera for the whole run, framing the range's first
        // frame (whatever the shard), so that the animation moves in a still frame.
        scenes.hold_automatic_camera(gltf_frame_time(options.first, options.gltf_fps));
        RenderedFrames frames(scenes, options.render, options.output_dir, output_pattern(options));
        return run_frames(frames, frames_list, schedule, observer);
    }
    ObjSequenceSource scenes(options, setup, plan);
    RenderedFrames frames(scenes, options.render, options.output_dir, output_pattern(options));
    return run_frames(frames, frames_list, schedule, observer);
}

}  // namespace toonray
