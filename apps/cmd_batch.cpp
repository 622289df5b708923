#include <memory>
#include <string>

#include "commands.h"
#include "gltf_args.h"
#include "hints.h"
#include "toonray/anim/batch.h"
#include "toonray/anim/progress.h"

namespace toonray::cli {
namespace {

struct BatchArgs {
    std::string name;
    int first = 1, last = 1;
    std::string input = ".", output = ".";
    std::string pattern, output_pattern, shard;
    int jobs = 0;
    bool resume = false, fail_fast = false, quiet = false;
    SettingsArgs render;
    GltfArgs gltf;
    SvgArgs svg;

    void add_to(CLI::App& app) {
        app.add_option("name", name,
                       "Animation name: frame N is read from NAME_NNNNNN.obj, "
                       "NAME_NNNN.obj, NAMEN.obj or NAME_N.obj, the first that exists; or a "
                       ".gltf/.glb file, posed at N/fps seconds")
            ->required();
        app.add_option("first", first, "First frame number")
            ->required()
            ->check(CLI::NonNegativeNumber);
        app.add_option("last", last, "Last frame number (inclusive)")
            ->required()
            ->check(CLI::NonNegativeNumber);
        app.add_option("-i,--input", input, "Directory of the frame OBJ files")
            ->capture_default_str();
        app.add_option("-o,--output", output, "Directory for the PNG frames (created if missing)")
            ->capture_default_str();
        app.add_option("--pattern", pattern, "Input file pattern, e.g. 'keys_%06d.obj'");
        app.add_option("--output-pattern", output_pattern,
                       "Output file pattern (default: NAME_%06d.png)");
        app.add_option("--jobs", jobs, "Frames rendered at once (0 = one per core)")
            ->check(CLI::Range(0, 256))
            ->capture_default_str();
        app.add_option(
            "--shard", shard,
            "Render shard K of N (K/N): frames at positions K-1, K-1+N, ... of the range. "
            "Default: from SLURM_ARRAY_TASK_ID/COUNT/MIN when set, else all frames");
        app.add_flag("--resume", resume, "Skip frames whose PNG already exists and is valid");
        app.add_flag("--fail-fast", fail_fast, "Stop at the first frame that fails");
        app.add_flag("-q,--quiet", quiet, "No progress output (failures are still reported)");
    }
};

int run_batch(const BatchArgs& args, const CLI::App& command) {
    BatchOptions options;
    options.name = args.name;
    options.first = args.first;
    options.last = args.last;
    options.input_dir = args.input;
    options.output_dir = args.output;
    if (!args.pattern.empty()) options.input_pattern = args.pattern;
    if (!args.output_pattern.empty()) options.output_pattern = args.output_pattern;
    const Settings settings = args.render.apply();
    options.render = args.render.frame_options(settings);
    options.scene = settings.scene_setup();
    args.svg.apply(options.render, true, args.render);
    options.jobs = args.jobs;
    options.resume = args.resume;
    options.fail_fast = args.fail_fast;
    options.gltf = args.gltf.pose();
    options.gltf_fps = args.gltf.fps;
    if (!args.shard.empty()) {
        options.shard = with_flag("--shard", [&] { return parse_shard(args.shard); });
    } else if (auto slurm = shard_from_environment()) {
        options.shard = *slurm;
    }
    options.cancel = install_stop_handlers();
    auto frames = shard_frames(options.first, options.last, options.shard);
    ProgressReporter progress(static_cast<int>(frames.size()), stderr, args.quiet);
    BatchReport report = toonray::run_batch(options, &progress);
    progress.finish(report);
    print_frame_limit_hints(report, command);
    if (report.cancelled) return 130;
    return report.failed > 0 ? 1 : 0;
}

}  // namespace

Subcommand add_batch_command(CLI::App& app) {
    auto args = std::make_shared<BatchArgs>();
    CLI::App* batch = app.add_subcommand(
        "batch",
        "Render numbered frames NAME FIRST LAST to a PNG sequence (all render options apply)");
    args->add_to(*batch);
    args->render.add_to(*batch);
    args->gltf.add_to(*batch, false);
    args->svg.add_to(*batch, true);
    return {batch, [args, batch] { return run_batch(*args, *batch); }};
}

}  // namespace toonray::cli
