#include "toonray/anim/batch.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fmt/format.h>
#include <future>
#include <mutex>
#include <thread>

#include "toonray/core/error.h"
#include "toonray/core/limits.h"
#include "toonray/core/parallel.h"
#include "toonray/io/png.h"
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

/// A frame's input, loaded ahead of rendering so parsing overlaps tracing.
struct LoadedFrame {
    int frame = 0;
    std::filesystem::path output;
    enum class State { Load, Skip, Fail } state = State::Load;
    std::string error;
    Warnings warnings;
};

class Runner {
public:
    Runner(const BatchOptions& options, BatchObserver* observer, std::vector<int> frames,
           const FramePlan& plan)
        : options_(options), observer_(observer), frames_(std::move(frames)), jobs_(plan.jobs) {
        // Each job keeps two scenes (one rendering, the next loading) and its frame buffers.
        obj_.limits.reserved_memory = static_cast<std::uint64_t>(plan.jobs) * plan.frame_bytes;
        obj_.limits.scenes_in_flight = static_cast<std::uint32_t>(2 * plan.jobs);
        if (options.input_pattern) {
            input_patterns_.emplace_back(*options.input_pattern);
        } else {
            input_patterns_ = default_input_patterns(options.name);
        }
        output_pattern_.emplace(options.output_pattern.value_or(
            [&] {
                std::string escaped;
                for (char c : options.name) {
                    if (c == '%') escaped.push_back('%');
                    escaped.push_back(c);
                }
                return escaped + "_%06d.png";
            }()));
    }

    BatchReport run() {
        report_.total = static_cast<int>(frames_.size());
        const int jobs = std::max(1, std::min(jobs_, report_.total));
        std::vector<std::thread> workers;
        for (int i = 1; i < jobs; ++i) workers.emplace_back([&] { work(jobs); });
        work(jobs);
        for (auto& w : workers) w.join();
        std::sort(report_.failures.begin(), report_.failures.end(),
                  [](const FrameFailure& a, const FrameFailure& b) { return a.frame < b.frame; });
        report_.cancelled = cancelled();
        return report_;
    }

private:
    bool cancelled() const {
        return stop_.load() || (options_.cancel && options_.cancel->load());
    }

    // Claims the next frame index, or -1 when done or stopping.
    int claim() {
        if (cancelled()) return -1;
        int i = next_.fetch_add(1);
        return i < static_cast<int>(frames_.size()) ? i : -1;
    }

    LoadedFrame load(int index, Scene& scene) {
        // Runs on a worker thread: nothing may escape it (an exception would end the process).
        LoadedFrame f;
        f.frame = frames_[index];
        try {
            load_into(f, scene);
        } catch (const std::exception& e) {
            f.state = LoadedFrame::State::Fail;
            f.error = fmt::format("frame {}: {}", f.frame, e.what());
        }
        return f;
    }

    void load_into(LoadedFrame& f, Scene& scene) {
        f.output = options_.output_dir / output_pattern_->format(f.frame);
        if (options_.resume && is_valid_png(f.output)) {
            f.state = LoadedFrame::State::Skip;
            return;
        }
        auto input = find_frame_file(options_.input_dir, input_patterns_, f.frame);
        if (!input) {
            std::string tried;
            for (const auto& p : input_patterns_) tried += (tried.empty() ? "" : ", ") + p.format(f.frame);
            f.state = LoadedFrame::State::Fail;
            f.error = fmt::format("{}: no input file for frame {} (tried {})",
                                  options_.input_dir.string(), f.frame, tried);
            return;
        }
        try {
            load_obj(*input, scene, f.warnings, obj_);
        } catch (const Error& e) {
            f.state = LoadedFrame::State::Fail;
            f.error = e.what();
        }
    }

    void work(int jobs) {
        FileRenderer renderer;
        FileRenderOptions render = options_.render;
        // Frame-level parallelism already fills the cores; one thread per frame avoids
        // oversubscription unless the user asked for more.
        if (jobs > 1 && render.settings.threads == 0) render.settings.threads = 1;
        Scene scenes[2];
        int slot = 0;
        int index = claim();
        if (index < 0) return;
        std::future<LoadedFrame> pending =
            std::async(std::launch::deferred, [&, index] { return load(index, scenes[0]); });
        while (index >= 0) {
            LoadedFrame current = pending.get();
            int next = claim();
            if (next >= 0) {
                Scene& target = scenes[1 - slot];
                pending = std::async(std::launch::async, [&, next] { return load(next, target); });
            }
            finish(current, scenes[slot], renderer, render);
            slot = 1 - slot;
            index = next;
        }
    }

    void finish(LoadedFrame& f, const Scene& scene, FileRenderer& renderer, const FileRenderOptions& render) {
        if (f.state == LoadedFrame::State::Load) {
            try {
                renderer.render(scene, f.output, render, f.warnings);
            } catch (const Error& e) {
                f.state = LoadedFrame::State::Fail;
                f.error = e.what();
            } catch (const std::exception& e) {
                f.state = LoadedFrame::State::Fail;
                f.error = fmt::format("{}: {}", f.output.string(), e.what());
            }
        }
        std::lock_guard lock(mutex_);
        for (const auto& w : f.warnings)
            if (observer_) observer_->warning(f.frame, w);
        FrameStatus status = FrameStatus::Rendered;
        switch (f.state) {
            case LoadedFrame::State::Load: report_.rendered++; break;
            case LoadedFrame::State::Skip: report_.skipped++; status = FrameStatus::Skipped; break;
            case LoadedFrame::State::Fail:
                report_.failed++;
                status = FrameStatus::Failed;
                report_.failures.push_back({f.frame, f.error});
                if (options_.fail_fast) stop_ = true;
                break;
        }
        if (observer_) observer_->frame_done(f.frame, status, f.error);
    }

    const BatchOptions& options_;
    BatchObserver* observer_;
    std::vector<int> frames_;
    int jobs_;
    ObjOptions obj_;
    std::vector<FramePattern> input_patterns_;
    std::optional<FramePattern> output_pattern_;
    std::atomic<int> next_{0};
    std::atomic<bool> stop_{false};
    std::mutex mutex_;
    BatchReport report_;
};

}  // namespace

Shard parse_shard(const std::string& text) {
    auto slash = text.find('/');
    Shard s;
    if (slash == std::string::npos || !parse_int(text.substr(0, slash), s.index) ||
        !parse_int(text.substr(slash + 1), s.count) || s.count < 1 || s.index < 1 || s.index > s.count)
        throw Error(fmt::format("--shard: expected K/N with 1 <= K <= N, got '{}'", text));
    return s;
}

std::optional<Shard> shard_from_environment() {
    const char* id = std::getenv("SLURM_ARRAY_TASK_ID");
    const char* count = std::getenv("SLURM_ARRAY_TASK_COUNT");
    if (!id || !count) return std::nullopt;
    const char* min = std::getenv("SLURM_ARRAY_TASK_MIN");
    int task = 0, n = 0, first = 1;
    if (!parse_int(id, task) || !parse_int(count, n) || (min && !parse_int(min, first)))
        throw Error(fmt::format("Slurm array variables are not numbers: SLURM_ARRAY_TASK_ID={} "
                                "SLURM_ARRAY_TASK_COUNT={} SLURM_ARRAY_TASK_MIN={}",
                                id, count, min ? min : "(unset)"));
    Shard s{task - first + 1, n};
    if (s.count < 1 || s.index < 1 || s.index > s.count)
        throw Error(fmt::format("Slurm array task {} (min {}) is outside a {}-task array; submit "
                                "with --array=1-N for N tasks",
                                task, first, n));
    return s;
}

std::vector<int> shard_frames(int first, int last, const Shard& shard) {
    if (first > last)
        throw Error(fmt::format("frame range {} {}: the first frame is after the last", first, last));
    if (shard.count < 1 || shard.index < 1 || shard.index > shard.count)
        throw Error(fmt::format("shard {}/{}: expected K/N with 1 <= K <= N", shard.index, shard.count));
    const long long span = static_cast<long long>(last) - first;  // >= 0
    const long long count = span < shard.index - 1 ? 0 : (span - (shard.index - 1)) / shard.count + 1;
    if (static_cast<unsigned long long>(count) > limits().max_frames)
        throw Error(fmt::format("frame range {} {}: {} frames is more than the limit of {}", first, last,
                                count, limits().max_frames));
    std::vector<int> frames;
    frames.reserve(static_cast<std::size_t>(count));
    for (long long f = static_cast<long long>(first) + (shard.index - 1); f <= last; f += shard.count)
        frames.push_back(static_cast<int>(f));
    return frames;
}

FramePlan plan_frame_jobs(const RenderSettings& settings, int requested, std::size_t frames) {
    const Limits& lim = limits();
    if (settings.width < 1 || settings.height < 1)
        throw Error(fmt::format("image size {}x{}: both must be at least 1", settings.width, settings.height));
    const std::uint64_t pixels = static_cast<std::uint64_t>(settings.width) * static_cast<std::uint64_t>(settings.height);
    if (pixels > lim.max_image_pixels)
        throw Error(fmt::format("--size {}x{}: {} pixels, more than the limit of {} (--max-image-pixels "
                                "raises it)",
                                settings.width, settings.height, pixels, lim.max_image_pixels));
    FramePlan plan;
    plan.frame_bytes = frame_buffer_bytes(pixels, settings.edges == EdgeMode::Classic ? 1 : settings.samples);
    const std::string size = fmt::format("a {}x{} frame", settings.width, settings.height);
    check_memory(plan.frame_bytes, size);
    const int wanted = requested > 0 ? requested : hardware_threads();
    const int most = static_cast<int>(std::max<std::size_t>(1, std::min<std::size_t>(frames, 1 << 16)));
    plan.jobs = std::max(1, std::min(wanted, most));
    if (requested > 0) {
        check_memory(plan.jobs * plan.frame_bytes, fmt::format("{} frames at once ({} each)", plan.jobs, size),
                     "render fewer at once with --jobs");
    } else {
        // One per core, as many as fit.
        const std::uint64_t fit = std::max<std::uint64_t>(1, lim.max_memory / std::max<std::uint64_t>(plan.frame_bytes, 1));
        plan.jobs = static_cast<int>(std::min<std::uint64_t>(static_cast<std::uint64_t>(plan.jobs), fit));
    }
    return plan;
}

BatchReport run_batch(const BatchOptions& options, BatchObserver* observer) {
    if (options.first < 0 || options.last < 0)
        throw Error(fmt::format("frame range {} {}: frame numbers must not be negative", options.first, options.last));
    if (options.first > options.last)
        throw Error(fmt::format("frame range {} {}: the first frame is after the last", options.first, options.last));
    if (options.name.empty() && !options.input_pattern) throw Error("batch: the animation name is empty");
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
    std::vector<int> frames = shard_frames(options.first, options.last, options.shard);
    const FramePlan plan = plan_frame_jobs(options.render.settings, options.jobs, frames.size());
    auto start = std::chrono::steady_clock::now();
    Runner runner(options, observer, std::move(frames), plan);
    BatchReport report = runner.run();
    report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return report;
}

}  // namespace toonray
