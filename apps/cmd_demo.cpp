#include <algorithm>
#include <fmt/format.h>
#include <memory>
#include <optional>
#include <string>

#include "commands.h"
#include "hints.h"
#include "toonray/anim/camera_path.h"
#include "toonray/anim/demo.h"
#include "toonray/anim/progress.h"

namespace toonray::cli {
namespace {

/// Progress of `toonray demo`: the frame bar, and a line per stage.
class DemoProgress : public DemoObserver {
public:
    DemoProgress(int frames, bool quiet) : frames_(frames, stderr, quiet), quiet_(quiet) {}
    void frame_done(int frame, FrameStatus status, const std::string& message) override {
        frames_.frame_done(frame, status, message);
    }
    void warning(int frame, const std::string& message) override {
        frames_.warning(frame, message);
    }
    void stage(const std::string& what) override {
        if (!quiet_) fmt::print(stderr, "toonray: demo: {}\n", what);
    }
    void finish(const BatchReport& report) { frames_.finish(report); }

private:
    ProgressReporter frames_;
    bool quiet_;
};

struct DemoArgs {
    PianoArgs piano;
    SettingsArgs render;
    SvgArgs svg;
    std::string output = "out";
    bool full = false;
};

int run_demo(const DemoArgs& args, const CLI::App& command) {
    const PianoArgs& piano = args.piano;
    Score score = load_score_or_demo(piano.score);
    CameraPath path =
        piano.camera_path.empty() ? load_demo_camera_path() : load_camera_path(piano.camera_path);
    DemoOptions options;
    options.output_dir = args.output;
    options.seconds = args.full ? std::optional<double>() : std::optional<double>(piano.seconds);
    options.soundfont = piano.soundfont;
    const Settings settings = args.render.apply();
    options.movie.render = args.render.frame_options(settings);
    options.movie.scene = settings.scene_setup();
    args.svg.apply(options.movie.render, true, args.render);
    options.movie.start = piano.start;
    options.movie.fps = piano.fps;
    options.movie.jobs = piano.jobs;
    options.movie.resume = piano.resume;
    options.movie.cancel = install_stop_handlers();
    double seconds =
        options.seconds ? *options.seconds : std::max(0.0, score.duration() - piano.start);
    // Checked before run_demo starts: the frame count (a score may last centuries) and
    // the soundtrack's memory.
    const int frames = checked_frame_count(seconds, piano.fps);
    (void)audio_options(score, piano, options.seconds);
    DemoProgress progress(frames, piano.quiet);
    DemoReport report = with_soundfont_hint(
        piano.soundfont, [&] { return toonray::run_demo(score, path, options, &progress); });
    progress.finish(report.movie.batch);
    print_frame_limit_hints(report.movie.batch, command);
    if (report.movie.batch.cancelled) return 130;
    if (!report.completed) return 1;
    print_warnings(report.audio.warnings);
    fmt::print(stderr, "toonray: demo: wrote {} ({} frames, {:.1f} s, {} triangles)\n",
               report.movie_path.string(), report.encode.frames.count, report.encode.duration,
               report.movie.triangles);
    return 0;
}

}  // namespace

Subcommand add_demo_command(CLI::App& app) {
    auto args = std::make_shared<DemoArgs>();
    PianoArgs& demo_args = args->piano;
    demo_args.seconds = 30.0;
    CLI::App* demo = app.add_subcommand(
        "demo",
        "The main job: a movie of the player piano playing Scott Joplin's \"The Entertainer\", "
        "with sound (frames in DIR/frames, DIR/entertainer.wav, DIR/entertainer.mp4)");
    demo->add_option("-o,--output", args->output, "Output directory")->capture_default_str();
    demo->add_flag("--full", args->full,
                   "The whole piece (about 4 min 13 s) instead of the first seconds");
    demo->add_option("--seconds", demo_args.seconds, "Length in seconds")
        ->check(CLI::PositiveNumber)
        ->capture_default_str();
    demo->add_option("--score", demo_args.score, "Play another score (MIDI or note script)");
    demo_args.add_common(*demo);
    args->render.add_to(*demo);
    args->svg.add_to(*demo, true);
    return {demo, [args, demo] { return run_demo(*args, *demo); }};
}

}  // namespace toonray::cli
