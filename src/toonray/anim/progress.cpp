#include "toonray/anim/progress.h"

#include <unistd.h>

#include <fmt/format.h>

namespace toonray {

ProgressReporter::ProgressReporter(int total, std::FILE* out, bool quiet, int interactive)
    : total_(total),
      out_(out),
      quiet_(quiet),
      interactive_(interactive >= 0 ? interactive != 0 : ::isatty(::fileno(out)) != 0),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

std::string ProgressReporter::format_duration(double seconds) {
    if (!(seconds >= 0) || seconds > 1e7) return "?";
    long s = static_cast<long>(seconds + 0.5);
    if (s >= 3600) return fmt::format("{}h{:02d}m", s / 3600, (s / 60) % 60);
    if (s >= 60) return fmt::format("{}m{:02d}s", s / 60, s % 60);
    return fmt::format("{}s", s);
}

void ProgressReporter::clear_bar() {
    if (bar_shown_) {
        fmt::print(out_, "\r\033[K");
        bar_shown_ = false;
    }
}

void ProgressReporter::frame_done(int frame, FrameStatus status, const std::string& message) {
    ++done_;
    if (status == FrameStatus::Failed) {
        clear_bar();
        fmt::print(out_, "toonray: frame {} failed: {}\n", frame, message);
    }
    draw(done_ == total_);
}

void ProgressReporter::warning(int frame, const std::string& message) {
    if (quiet_) return;
    clear_bar();
    fmt::print(out_, "toonray: warning: frame {}: {}\n", frame, message);
}

void ProgressReporter::draw(bool force) {
    if (quiet_) return;
    auto now = std::chrono::steady_clock::now();
    double since_draw = std::chrono::duration<double>(now - last_draw_).count();
    // A terminal redraws ten times a second; a log gets a line every ten seconds.
    if (!force && since_draw < (interactive_ ? 0.1 : 10.0)) return;
    last_draw_ = now;
    double elapsed = std::chrono::duration<double>(now - start_).count();
    double fps = elapsed > 0 ? done_ / elapsed : 0.0;
    double eta = fps > 0 ? (total_ - done_) / fps : -1.0;
    if (interactive_) {
        const int width = 30;
        int filled = total_ > 0 ? done_ * width / total_ : width;
        fmt::print(out_, "\r[{}{}] {}/{} frames  {:.1f} fps  ETA {}\033[K",
                   std::string(filled, '#'), std::string(width - filled, ' '), done_, total_, fps,
                   format_duration(eta));
        bar_shown_ = true;
    } else {
        fmt::print(out_, "toonray: {}/{} frames, {:.1f} fps, ETA {}\n", done_, total_, fps,
                   format_duration(eta));
    }
    std::fflush(out_);
}

void ProgressReporter::finish(const BatchReport& report) {
    clear_bar();
    double fps = report.seconds > 0 ? (report.rendered) / report.seconds : 0.0;
    if (!quiet_ || report.failed > 0 || report.cancelled)
        fmt::print(
            out_, "toonray: {} rendered, {} skipped, {} failed of {} frames in {} ({:.1f} fps){}\n",
            report.rendered, report.skipped, report.failed, report.total,
            format_duration(report.seconds), fps, report.cancelled ? "; stopped early" : "");
    if (report.failed > 0) {
        std::string list;
        for (std::size_t i = 0; i < report.failures.size() && i < 20; ++i)
            list += fmt::format("{}{}", i ? " " : "", report.failures[i].frame);
        fmt::print(out_, "toonray: failed frames: {}{}\n", list,
                   report.failures.size() > 20 ? " ..." : "");
    }
    std::fflush(out_);
}

}  // namespace toonray
