#include "toonray/anim/piano_movie.h"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <fmt/format.h>
#include <mutex>
#include <thread>

#include "toonray/core/error.h"
#include "toonray/core/limits.h"
#include "toonray/core/parallel.h"
#include "toonray/io/png.h"
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
    return parse_camera_path(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()),
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
        throw Error(fmt::format("{:.0f} s at {} fps: {}{} frames is more than the limit of {}", seconds, fps,
                                frames == 2147483647 ? "over " : "", frames, limits().max_frames));
    return frames;
}

namespace {

void check_directory(const std::filesystem::path& dir, const char* what) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec || ::access(dir.c_str(), W_OK) != 0)
        throw Error(fmt::format("{}: {} directory cannot be created or is not writable", dir.string(), what));
}

class MovieRunner {
public:
    MovieRunner(const Score& score, const CameraPath& path, const PianoMovieOptions& options,
                BatchObserver* observer)
        : playback_(score), path_(path), options_(options), observer_(observer),
          output_pattern_(options.name + "_%06d" + (options.export_obj_dir ? ".obj" : ".png")) {
        // The roll's hole pool holds the most slots visible at once; a score can ask for
        // millions (two triangles each). Check before building.
        const std::uint64_t holes = playback_.hole_capacity();
        if (2 * holes > limits().max_triangles)
            throw Error(fmt::format("the score puts up to {} notes on the roll's window at once: {} "
                                    "triangles, more than the limit of {} (--max-triangles raises it)",
                                    holes, 2 * holes, limits().max_triangles));
        PianoOptions piano;
        piano.hole_capacity = std::max<std::uint32_t>(playback_.hole_capacity(), 1);
        model_ = build_piano(piano);
    }

    PianoMovieReport run(int frames) {
        PianoMovieReport report;
        report.frame_count = frames;
        report.triangles = model_.scene.triangle_count();
        report_.total = frames;
        // Each job poses its own copy of the scene with its own BVH, and (unless exporting)
        // renders into its own frame buffers.
        const bool exporting = options_.export_obj_dir.has_value();
        FramePlan plan;
        if (exporting) {
            plan.jobs = std::max(1, std::min(options_.jobs > 0 ? options_.jobs : hardware_threads(), frames));
        } else {
            plan = plan_frame_jobs(options_.render.settings, options_.jobs, static_cast<std::size_t>(frames));
        }
        const std::uint64_t scene = scene_bytes(model_.scene.positions.size(), model_.scene.triangle_count());
        if (options_.jobs <= 0)  // one per core, as many as fit
            while (plan.jobs > 1 && plan.jobs * (plan.frame_bytes + scene) > limits().max_memory) --plan.jobs;
        check_memory(plan.jobs * (plan.frame_bytes + scene),
                     fmt::format("{} frame{} at once of the piano ({} triangles)", plan.jobs,
                                 plan.jobs == 1 ? "" : "s", model_.scene.triangle_count()),
                     "render fewer at once with --jobs");
        int jobs = std::max(1, std::min(plan.jobs, frames));
        auto start = std::chrono::steady_clock::now();
        std::vector<std::thread> workers;
        for (int i = 1; i < jobs; ++i) workers.emplace_back([&] { work(jobs); });
        if (frames > 0) work(jobs);
        for (auto& w : workers) w.join();
        report_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        report_.cancelled = options_.cancel && options_.cancel->load();
        std::sort(report_.failures.begin(), report_.failures.end(),
                  [](const FrameFailure& a, const FrameFailure& b) { return a.frame < b.frame; });
        report.batch = report_;
        report.dropped_holes = dropped_holes_;
        return report;
    }

private:
    void work(int jobs) {
        Scene scene = model_.scene;  // this job's copy to pose
        TriangleAccel accel;
        accel.build(scene.positions, scene.tri_positions, options_.render.bvh);
        Renderer renderer;
        ObjWriter writer;
        FileRenderOptions render = options_.render;
        if (jobs > 1 && render.settings.threads == 0) render.settings.threads = 1;
        const int frames = report_.total;
        while (!(options_.cancel && options_.cancel->load())) {
            int index = next_.fetch_add(1);
            if (index >= frames) break;
            int frame = index + 1;
            FrameStatus status = FrameStatus::Rendered;
            std::string error;
            try {
                status = render_frame(frame, scene, accel, renderer, writer, render);
            } catch (const std::exception& e) {
                status = FrameStatus::Failed;
                error = e.what();
            }
            std::lock_guard lock(mutex_);
            if (status == FrameStatus::Rendered) report_.rendered++;
            if (status == FrameStatus::Skipped) report_.skipped++;
            if (status == FrameStatus::Failed) {
                report_.failed++;
                report_.failures.push_back({frame, error});
            }
            if (observer_) observer_->frame_done(frame, status, error);
        }
    }

    FrameStatus render_frame(int frame, Scene& scene, TriangleAccel& accel, Renderer& renderer,
                             ObjWriter& writer, const FileRenderOptions& render) {
        const double t = options_.start + (frame - 1) / options_.fps;
        const bool exporting = options_.export_obj_dir.has_value();
        std::filesystem::path out =
            (exporting ? *options_.export_obj_dir : options_.output_dir) / output_pattern_.format(frame);
        if (options_.resume && !exporting && is_valid_png(out)) return FrameStatus::Skipped;

        PoseStats stats = pose_piano(model_, playback_.pose_at(t), &playback_.roll(), scene);
        if (stats.dropped_holes) {
            std::lock_guard lock(mutex_);
            dropped_holes_ += stats.dropped_holes;
        }
        CameraSpec camera = path_.camera(t);
        if (exporting) {
            scene.camera = camera;
            writer.write(out, scene);
            return FrameStatus::Rendered;
        }
        accel.refit(scene.positions, scene.tri_positions);
        const ImageRgb8& image = renderer.render(scene, accel, camera, render.settings);
        write_frame(renderer, image, out, render);
        return FrameStatus::Rendered;
    }

    PianoPlayback playback_;
    PianoModel model_;
    const CameraPath& path_;
    const PianoMovieOptions& options_;
    BatchObserver* observer_;
    FramePattern output_pattern_;
    std::atomic<int> next_{0};
    std::mutex mutex_;
    BatchReport report_;
    std::uint32_t dropped_holes_ = 0;
};

}  // namespace

PianoMovieReport render_piano_movie(const Score& score, const CameraPath& camera_path,
                                    const PianoMovieOptions& options, BatchObserver* observer) {
    if (!(options.fps > 0.0 && options.fps <= 1000.0))
        throw Error(fmt::format("--fps {}: must be in (0, 1000]", options.fps));
    if (!(options.start >= 0.0)) throw Error("--start must not be negative");
    if (options.name.empty() || options.name.find('/') != std::string::npos)
        throw Error(fmt::format("--name '{}': must be a plain file name", options.name));
    if (camera_path.empty()) throw Error(fmt::format("{}: camera path has no keys", camera_path.source()));
    double music_end = score.notes.empty() ? 0.0 : score.duration();
    double seconds = options.seconds ? *options.seconds : std::max(0.0, music_end - options.start);
    if (!(seconds > 0.0)) throw Error("nothing to render: the length is zero (an empty score, or --start past its end)");
    const int frames = checked_frame_count(seconds, options.fps);
    if (options.export_obj_dir) {
        check_directory(*options.export_obj_dir, "OBJ export");
    } else {
        check_directory(options.output_dir, "output");
    }
    if (options.render.aov_dir) check_directory(*options.render.aov_dir, "AOV");
    MovieRunner runner(score, camera_path, options, observer);
    return runner.run(frames);
}

}  // namespace toonray
