#include <algorithm>
#include <fmt/format.h>
#include <memory>
#include <optional>
#include <string>

#include "commands.h"
#include "hints.h"
#include "toonray/anim/camera_path.h"
#include "toonray/anim/piano_movie.h"
#include "toonray/anim/progress.h"
#include "toonray/media/audio.h"

namespace toonray::cli {
namespace {

struct PianoCommandArgs {
    PianoArgs piano;
    SettingsArgs render;
    SvgArgs svg;
    std::string output;
    bool instanced_keys = false;
};

PianoMovieReport run_piano_movie(const Score& score, const PianoArgs& args,
                                 PianoMovieOptions options, const CLI::App& command) {
    CameraPath path =
        args.camera_path.empty() ? load_demo_camera_path() : load_camera_path(args.camera_path);
    options.start = args.start;
    options.fps = args.fps;
    options.jobs = args.jobs;
    options.resume = args.resume;
    options.cancel = install_stop_handlers();
    double seconds =
        options.seconds
            ? *options.seconds
            : std::max(0.0, (score.notes.empty() ? 0.0 : score.duration()) - options.start);
    ProgressReporter progress(frame_count(seconds, options.fps), stderr, args.quiet);
    PianoMovieReport report = render_piano_movie(score, path, options, &progress);
    progress.finish(report.batch);
    print_frame_limit_hints(report.batch, command);
    if (report.dropped_holes)
        fmt::print(stderr, "toonray: warning: {} roll holes did not fit the hole pool\n",
                   report.dropped_holes);
    return report;
}

int run_piano(const PianoCommandArgs& args, const CLI::App& command) {
    const PianoArgs& piano = args.piano;
    if (args.output.empty() == piano.export_obj.empty())
        throw Error(
            "piano: give exactly one of --output DIR (render PNG frames) or --export-obj DIR");
    Score score = load_score_or_demo(piano.score);
    PianoMovieOptions options;
    options.name = piano.name;
    options.output_dir = args.output;
    options.instanced_keys = args.instanced_keys;
    if (!piano.export_obj.empty()) options.export_obj_dir = piano.export_obj;
    if (piano.seconds > 0) options.seconds = piano.seconds;
    const Settings settings = args.render.apply();
    options.render = args.render.frame_options(settings);
    options.scene = settings.scene_setup();
    args.svg.apply(options.render, true, args.render);
    std::optional<AudioOptions> audio_opts;  // checked before the frames are rendered
    if (!piano.audio.empty()) audio_opts = audio_options(score, piano, options.seconds);
    PianoMovieReport report = run_piano_movie(score, piano, options, command);
    if (report.batch.cancelled) return 130;
    if (report.batch.failed > 0) return 1;
    if (audio_opts) {
        AudioResult audio = with_soundfont_hint(
            piano.soundfont, [&] { return render_audio(score, piano.audio, *audio_opts); });
        print_warnings(audio.warnings);
    }
    return 0;
}

}  // namespace

Subcommand add_piano_command(CLI::App& app) {
    auto args = std::make_shared<PianoCommandArgs>();
    PianoArgs& piano_args = args->piano;
    CLI::App* piano = app.add_subcommand(
        "piano",
        "Render the procedural player piano playing a score, or export its frames as OBJ files");
    piano->add_option("--score", piano_args.score,
                      "Score: a MIDI file or a note script (default: the built-in Entertainer)");
    piano->add_option("-o,--output", args->output, "Directory for the PNG frames");
    piano->add_option(
        "--export-obj", piano_args.export_obj,
        "Instead of rendering, write one OBJ + MTL per frame with its camera block to this "
        "directory (render them with `toonray batch NAME 1 N`)");
    piano
        ->add_option("--seconds", piano_args.seconds,
                     "Length in seconds (default: to the end of the music)")
        ->check(CLI::PositiveNumber);
    piano->add_option("--name", piano_args.name, "Frame file name prefix")->capture_default_str();
    piano->add_option("--audio", piano_args.audio,
                      "Also write the soundtrack of the same stretch to this WAV");
    piano->add_flag("--instanced-keys", args->instanced_keys,
                    "The 88 keys as instances of their shapes: posing moves 88 transforms (a "
                    "two-level BVH) instead of the keys' vertices; the frames differ only along "
                    "edges");
    piano_args.add_common(*piano);
    args->render.add_to(*piano);
    args->svg.add_to(*piano, true);
    return {piano, [args, piano] { return run_piano(*args, *piano); }};
}

}  // namespace toonray::cli
