#pragma once
/// One scheduler for every sequence of frames (batch rendering of OBJ files, the piano movie
/// rendered in memory or exported as OBJ files): jobs claim frames, produce them on their own
/// threads, and report each under a lock, with resume, cancel and fail-fast.

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/frame/frame_renderer.h"

namespace toonray {

enum class FrameStatus { Rendered, Skipped, Failed };

struct FrameFailure {
    int frame = 0;
    std::string message;         ///< names the file and line when the input was bad
    std::optional<Limit> limit;  ///< the limit the frame exceeded, when that was why it failed
};

struct BatchReport {
    int total = 0;  ///< frames to produce
    int rendered = 0, skipped = 0, failed = 0;
    bool cancelled = false;              ///< stopped early: by the cancel flag or by fail-fast
    std::vector<FrameFailure> failures;  ///< sorted by frame
    double seconds = 0.0;
};

/// Receives progress from the worker threads (calls are serialised).
class BatchObserver {
public:
    virtual ~BatchObserver() = default;
    virtual void frame_done(int frame, FrameStatus status, const std::string& message) = 0;
    virtual void warning(int frame, const std::string& message) = 0;
};

/// Frames rendered at once within the limits (docs/robustness.md).
struct FramePlan {
    int jobs = 1;                   ///< frames in flight
    std::uint64_t frame_bytes = 0;  ///< estimated memory of one frame (frame_bytes)

    /// Estimated memory of the frames in flight, each with `per_job` more bytes (a posed
    /// scene), saturating at 2^64 - 1 so that a total too large to count is too much.
    [[nodiscard]] std::uint64_t bytes(std::uint64_t per_job = 0) const;
};

/// Checks the image size against limits().max_image_pixels (LimitError) and the memory of the
/// frames in flight against limits().max_memory. `requested` jobs, 0 = one per core: then as
/// many as fit (at least 1); an explicit number that does not fit is an Error, as is one frame
/// that does not fit. Never more jobs than `frames`.
FramePlan plan_frame_jobs(const FrameOptions& options, int requested, std::size_t frames);

/// Threads each frame uses when `jobs` frames run at once: several frames already fill the
/// cores, so one each unless `requested` (0 = all) says otherwise.
int threads_per_frame(int requested, int jobs);

/// One job's state (a scene to pose, a loader, a renderer), used on the job's own thread.
class FrameJob {
public:
    virtual ~FrameJob() = default;
    /// Writes `frame`'s output. `next` is the frame this job produces after it, if any, so that
    /// a job can get it ready meanwhile (the OBJ loader parses the next file while this one
    /// renders). Throws for a failed frame: Error (LimitError for a limit) with a message that
    /// names what was wrong, or any other exception.
    virtual void produce(int frame, std::optional<int> next, Warnings& warnings) = 0;
};

/// Where a run's frames come from and go to.
class FrameSource {
public:
    virtual ~FrameSource() = default;
    /// The file `frame` writes; on resume, a frame whose file is a valid PNG is skipped.
    [[nodiscard]] virtual std::filesystem::path output(int frame) const = 0;
    /// Whether `frame` is done already (resume): by default, its file is a valid PNG.
    [[nodiscard]] virtual bool done(int frame) const { return is_valid_png(output(frame)); }
    /// A job's state; `jobs` run at once. Called on the job's thread.
    virtual std::unique_ptr<FrameJob> make_job(int jobs) = 0;
};

struct ScheduleOptions {
    int jobs = 1;                               ///< frames produced at once
    bool resume = false;                        ///< skip frames whose output is a valid PNG
    bool fail_fast = false;                     ///< stop claiming frames after the first failure
    const std::atomic<bool>* cancel = nullptr;  ///< set (e.g. by SIGINT) to stop cleanly
};

/// Produces `frames` from `source`. Frames that fail are reported and the rest go on (unless
/// fail_fast); frames already claimed when the run stops are finished. Never throws for a
/// frame's failure.
BatchReport run_frames(FrameSource& source, const std::vector<int>& frames,
                       const ScheduleOptions& options, BatchObserver* observer = nullptr);

}  // namespace toonray
