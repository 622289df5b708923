#include "toonray/anim/piano_movie.h"

#include <unistd.h>

#include <atomic>
#include <cmath>
#include <fmt/format.h>
#include <memory>

#include "toonray/core/error.h"
#include "toonray/core/limits.h"
#include "toonray/core/parallel.h"
#include "toonray/anim/scene_frames.h"
#include "toonray/piano/piano_animation.h"
#include "toonray/piano/piano_model.h"
#include "toonray/piano/piano_pose.h"
#include "toonray/scene/obj_writer.h"
#include "toonray/score/midi.h"
#include "toonray/score/timed_score.h"

namespace toonray {

Score load_demo_score() {
    auto bytes = demo_score_midi();
    return to_score(read_midi(bytes, "entertainer.midi (built in)"));
}

CameraPath load_demo_camera_path() {
    auto bytes = demo_camera_path();
    return parse_camera_path(
        std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()),
        "entertainer.campath (built in)");
}

int frame_count(double seconds, double fps) {
    // Frames whose start time lies before the end; the small epsilon keeps 30 s at 24 fps at
    // exactly 720 despite rounding in seconds * fps. Saturates at INT_MAX (a score may last
    // 10^16 s), which every caller rejects as too many frames.
    const double frames = std::ceil(seconds * fps - 1e-9);
    if (!(frames > 0)) return 0;
    if (frames >= 2147483647.0) return 2147483647;
    return static_cast<int>(frames);
}

int checked_frame_count(double seconds, double fps) {
    const int frames = frame_count(seconds, fps);
    if (static_cast<std::uint64_t>(frames) > limits().max_frames)
        throw LimitError(
            Limit::Frames,
            fmt::format("{:.0f} s at {} fps: {}{} frames is more than the limit of {}", seconds,
                        fps, frames == 2147483647 ? "over " : "", frames, limits().max_frames));
    return frames;
}

namespace {

void check_directory(const std::filesystem::path& dir, const char* what) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec || ::access(dir.c_str(), W_OK) != 0)
        throw Error(fmt::format("{}: {} directory cannot be created or is not writable",
                                dir.string(), what));
}

// The piano's frames: frame N is the piano posed at its score time, seen from the camera path
// (unless the settings give a camera). Each job poses its own copy of the piano.
class PianoSource : public SceneSource {
public:
    PianoSource(const Score& score, const CameraPath& path, const PianoMovieOptions& options,
                SceneSetup setup)
        : playback_(score), path_(path), options_(options), setup_(std::move(setup)) {
        // The roll's hole pool holds the most slots visible at once; a score can ask for
        // millions (two triangles each). Check before building.
        const std::uint64_t holes = playback_.hole_capacity();
        if (2 * holes > limits().max_triangles)
            throw LimitError(
                Limit::Triangles,
                fmt::format("the score puts up to {} notes on the roll's window at once: {} "
                            "triangles, more than the limit of {}",
                            holes, 2 * holes, limits().max_triangles));
        PianoOptions piano;
        piano.hole_capacity = std::max<std::uint32_t>(playback_.hole_capacity(), 1);
        model_ = build_piano(piano);
        if (options_.instanced_keys) keyed_ = instance_keys(model_);
    }

    void load(int frame, SceneFrame& out, Warnings&) const override {
        const double t = options_.start + (frame - 1) / options_.fps;
        // A job poses its own copy in place; auto-smooth adds normals that posing would not
        // move, so then every frame starts from the model.
        const Scene& start = options_.instanced_keys ? keyed_ : model_.scene;
        if (out.scene.triangle_count() != start.triangle_count() ||
            out.scene.instances.size() != start.instances.size() || setup_.auto_smooth)
            out.scene = start;
        const PianoPose pose = playback_.pose_at(t);
        const PoseStats stats = pose_piano(model_, pose, &playback_.roll(), out.scene);
        if (options_.instanced_keys) pose_key_instances(model_, pose, out.scene);
        dropped_holes_ += stats.dropped_holes;
        out.scene.camera = path_.camera(t);
        finish_scene(out, {}, setup_);
    }

    [[nodiscard]] const Scene& scene() const { return model_.scene; }
    [[nodiscard]] std::uint32_t dropped_holes() const { return dropped_holes_.load(); }

private:
    PianoPlayback playback_;
    PianoModel model_;
    Scene keyed_;  ///< with instanced keys: the model's scene with the keys as instances
    const CameraPath& path_;
    const PianoMovieOptions& options_;
    SceneSetup setup_;
    mutable std::atomic<std::uint32_t> dropped_holes_{0};
};

// Exporting instead of rendering: each frame's posed piano as OBJ + MTL with its camera block.
class ExportedFrames : public FrameSource {
public:
    ExportedFrames(const PianoSource& scenes, std::filesystem::path dir, FramePattern pattern)
        : scenes_(scenes), dir_(std::move(dir)), pattern_(std::move(pattern)) {}

    [[nodiscard]] std::filesystem::path output(int frame) const override {
        return dir_ / pattern_.format(frame);
    }
    std::unique_ptr<FrameJob> make_job(int) override { return std::make_unique<Job>(*this); }

private:
    class Job : public FrameJob {
    public:
        explicit Job(const ExportedFrames& frames) : frames_(frames) {}
        void produce(int frame, std::optional<int>, Warnings& warnings) override {
            frames_.scenes_.load(frame, scene_, warnings);
            scene_.scene.camera = scene_.camera;
            if (scene_.scene.instances.empty()) {
                writer_.write(frames_.output(frame), scene_.scene);
            } else {
                // OBJ has no instances: the keys are written flattened.
                Scene flat = flatten_instances(scene_.scene);
                flat.camera = scene_.camera;
                writer_.write(frames_.output(frame), flat);
            }
        }

    private:
        const ExportedFrames& frames_;
        SceneFrame scene_;
        ObjWriter writer_;
    };

    const PianoSource& scenes_;
    std::filesystem::path dir_;
    FramePattern pattern_;
};

}  // namespace

PianoMovieReport render_piano_movie(const Score& score, const CameraPath& camera_path,
                                    const PianoMovieOptions& options, BatchObserver* observer) {
    if (!(options.fps > 0.0 && options.fps <= 1000.0))
        throw Error(fmt::format("frame rate {} fps: must be in (0, 1000]", options.fps));
    if (!(options.start >= 0.0))
        throw Error(fmt::format("start time {} s: must not be negative", options.start));
    if (options.name.empty() || options.name.find('/') != std::string::npos)
        throw Error(fmt::format("frame name '{}': must be a plain file name", options.name));
    if (camera_path.empty())
        throw Error(fmt::format("{}: camera path has no keys", camera_path.source()));
    double music_end = score.notes.empty() ? 0.0 : score.duration();
    double seconds = options.seconds ? *options.seconds : std::max(0.0, music_end - options.start);
    if (!(seconds > 0.0))
        throw Error(
            "nothing to render: the length is zero (an empty score, or a start time past its end)");
    const int frames = checked_frame_count(seconds, options.fps);
    if (options.export_obj_dir) {
        check_directory(*options.export_obj_dir, "OBJ export");
    } else {
        check_directory(options.output_dir, "output");
    }
    if (options.render.aov_dir) check_directory(*options.render.aov_dir, "AOV");
    if (options.render.aov_exr) check_exr_sequence(*options.render.aov_exr);
    if (options.render.svg_dir) check_directory(*options.render.svg_dir, "SVG");
    SceneSetup setup = options.scene;
    setup.width = options.render.settings.width;
    setup.height = options.render.settings.height;
    PianoSource source(score, camera_path, options, setup);
    const Scene& piano = source.scene();
    // Each job poses its own copy of the scene with its own BVH, and (unless exporting)
    // renders into its own frame buffers.
    const bool exporting = options.export_obj_dir.has_value();
    FramePlan plan;
    if (exporting) {
        plan.jobs =
            std::max(1, std::min(options.jobs > 0 ? options.jobs : hardware_threads(), frames));
    } else {
        plan = plan_frame_jobs(options.render, options.jobs, static_cast<std::size_t>(frames));
    }
    // The flat model's estimate: with instanced keys the scene holds less (the keys' shapes
    // once and 88 instances).
    const std::uint64_t scene = scene_bytes(piano.positions.size(), piano.triangle_count());
    if (options.jobs <= 0)  // one per core, as many as fit
        while (plan.jobs > 1 && plan.bytes(scene) > limits().max_memory) --plan.jobs;
    check_memory(plan.bytes(scene),
                 fmt::format("{} frame{} at once of the piano ({} triangles)", plan.jobs,
                             plan.jobs == 1 ? "" : "s", piano.triangle_count()));
    std::vector<int> numbers(static_cast<std::size_t>(frames));
    for (int i = 0; i < frames; ++i) numbers[static_cast<std::size_t>(i)] = i + 1;
    ScheduleOptions schedule;
    schedule.jobs = plan.jobs;
    schedule.resume = options.resume && !exporting;
    schedule.cancel = options.cancel;
    const FramePattern pattern(options.name + "_%06d" + (exporting ? ".obj" : ".png"));
    PianoMovieReport report;
    report.frame_count = frames;
    report.triangles = piano.triangle_count();
    if (exporting) {
        ExportedFrames exported(source, *options.export_obj_dir, pattern);
        report.batch = run_frames(exported, numbers, schedule, observer);
    } else {
        RenderedFrames rendered(source, options.render, options.output_dir, pattern);
        report.batch = run_frames(rendered, numbers, schedule, observer);
    }
    report.dropped_holes = source.dropped_holes();
    return report;
}

}  // namespace toonray
