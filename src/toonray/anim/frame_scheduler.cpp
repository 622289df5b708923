#include "toonray/anim/frame_scheduler.h"

#include <algorithm>
#include <chrono>
#include <fmt/format.h>
#include <mutex>
#include <thread>

#include "toonray/core/limits.h"
#include "toonray/core/parallel.h"
#include "toonray/core/saturating.h"
#include "toonray/io/png.h"

namespace toonray {
namespace {

class Scheduler {
public:
    Scheduler(FrameSource& source, const std::vector<int>& frames, const ScheduleOptions& options,
              BatchObserver* observer)
        : source_(source), frames_(frames), options_(options), observer_(observer) {}

    BatchReport run() {
        report_.total = static_cast<int>(frames_.size());
        const int jobs = std::max(1, std::min(options_.jobs, report_.total));
        std::vector<std::thread> workers;
        for (int i = 1; i < jobs; ++i) workers.emplace_back([&] { work(jobs); });
        if (report_.total > 0) work(jobs);
        for (auto& w : workers) w.join();
        std::sort(report_.failures.begin(), report_.failures.end(),
                  [](const FrameFailure& a, const FrameFailure& b) { return a.frame < b.frame; });
        report_.cancelled = stopping();
        return report_;
    }

private:
    bool stopping() const { return stop_.load() || (options_.cancel && options_.cancel->load()); }

    // The next frame to produce, or nullopt when done or stopping. Frames kept on resume are
    // reported as they are claimed.
    std::optional<int> claim() {
        while (!stopping()) {
            const int i = next_.fetch_add(1);
            if (i >= static_cast<int>(frames_.size())) return std::nullopt;
            const int frame = frames_[i];
            if (options_.resume && source_.done(frame)) {
                report(frame, FrameStatus::Skipped, {}, {});
                continue;
            }
            return frame;
        }
        return std::nullopt;
    }

    void work(int jobs) {
        std::optional<int> frame = claim();
        if (!frame) return;
        std::unique_ptr<FrameJob> job;
        while (frame) {
            std::optional<int> next = claim();
            Warnings warnings;
            FrameFailure failure{*frame, {}, {}};
            bool failed = true;
            try {
                if (!job) job = source_.make_job(jobs);
                job->produce(*frame, next, warnings);
                failed = false;
            } catch (const LimitError& e) {
                failure.message = e.what();
                failure.limit = e.limit();
            } catch (const Error& e) {
                failure.message = e.what();
            } catch (const std::exception& e) {
                failure.message = fmt::format("{}: {}", source_.output(*frame).string(), e.what());
            }
            if (failed) {
                report(*frame, FrameStatus::Failed, warnings, std::move(failure));
            } else {
                report(*frame, FrameStatus::Rendered, warnings, {});
            }
            frame = next;
        }
    }

    void report(int frame, FrameStatus status, const Warnings& warnings, FrameFailure failure) {
        std::lock_guard lock(mutex_);
        for (const auto& w : warnings)
            if (observer_) observer_->warning(frame, w);
        switch (status) {
            case FrameStatus::Rendered: report_.rendered++; break;
            case FrameStatus::Skipped: report_.skipped++; break;
            case FrameStatus::Failed:
                report_.failed++;
                if (options_.fail_fast) stop_ = true;
                break;
        }
        const std::string message = failure.message;
        if (status == FrameStatus::Failed) report_.failures.push_back(std::move(failure));
        if (observer_) observer_->frame_done(frame, status, message);
    }

    FrameSource& source_;
    const std::vector<int>& frames_;
    const ScheduleOptions& options_;
    BatchObserver* observer_;
    std::atomic<int> next_{0};
    std::atomic<bool> stop_{false};
    std::mutex mutex_;
    BatchReport report_;
};

}  // namespace

std::uint64_t FramePlan::bytes(std::uint64_t per_job) const {
    return mul_saturated(static_cast<std::uint64_t>(jobs), add_saturated(frame_bytes, per_job));
}

FramePlan plan_frame_jobs(const FrameOptions& options, int requested, std::size_t frames) {
    const Limits& lim = limits();
    const RenderSettings& settings = options.settings;
    if (settings.width < 1 || settings.height < 1)
        throw Error(fmt::format("image size {}x{}: both must be at least 1", settings.width,
                                settings.height));
    const std::uint64_t pixels =
        static_cast<std::uint64_t>(settings.width) * static_cast<std::uint64_t>(settings.height);
    if (pixels > lim.max_image_pixels)
        throw LimitError(
            Limit::ImagePixels,
            fmt::format("image size {}x{}: {} pixels, more than the limit of {}", settings.width,
                        settings.height, pixels, lim.max_image_pixels));
    FramePlan plan;
    plan.frame_bytes = frame_bytes(options);
    const std::string size = fmt::format("a {}x{} frame", settings.width, settings.height);
    check_memory(plan.frame_bytes, size);
    const int wanted = requested > 0 ? requested : hardware_threads();
    const int most =
        static_cast<int>(std::max<std::size_t>(1, std::min<std::size_t>(frames, 1 << 16)));
    plan.jobs = std::max(1, std::min(wanted, most));
    if (requested > 0) {
        check_memory(plan.bytes(), fmt::format("{} frames at once ({} each)", plan.jobs, size));
    } else {
        // One per core, as many as fit.
        const std::uint64_t fit = std::max<std::uint64_t>(
            1, lim.max_memory / std::max<std::uint64_t>(plan.frame_bytes, 1));
        plan.jobs =
            static_cast<int>(std::min<std::uint64_t>(static_cast<std::uint64_t>(plan.jobs), fit));
    }
    return plan;
}

int threads_per_frame(int requested, int jobs) {
    return jobs > 1 && requested == 0 ? 1 : requested;
}

BatchReport run_frames(FrameSource& source, const std::vector<int>& frames,
                       const ScheduleOptions& options, BatchObserver* observer) {
    const auto start = std::chrono::steady_clock::now();
    Scheduler scheduler(source, frames, options, observer);
    BatchReport report = scheduler.run();
    report.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return report;
}

}  // namespace toonray
