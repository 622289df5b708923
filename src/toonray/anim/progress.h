#pragma once
/// Progress for long runs: a redrawn bar on a terminal, plain periodic lines otherwise (logs,
/// Slurm), nothing when quiet. Failures and warnings are always printed.

#include <chrono>
#include <cstdio>
#include <string>

#include "toonray/anim/batch.h"

namespace toonray {

class ProgressReporter : public BatchObserver {
public:
    /// `total` frames expected; `out` is usually stderr. `interactive` chooses the bar; by
    /// default it is whether `out` is a terminal.
    ProgressReporter(int total, std::FILE* out, bool quiet, int interactive = -1);

    void frame_done(int frame, FrameStatus status, const std::string& message) override;
    void warning(int frame, const std::string& message) override;
    /// Ends the bar line and prints a one-line summary.
    void finish(const BatchReport& report);

    /// "1m02s" style durations.
    static std::string format_duration(double seconds);

private:
    void draw(bool force);
    void clear_bar();

    int total_;
    int done_ = 0;
    std::FILE* out_;
    bool quiet_;
    bool interactive_;
    bool bar_shown_ = false;
    std::chrono::steady_clock::time_point start_, last_draw_;
};

}  // namespace toonray
