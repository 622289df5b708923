#include <fmt/format.h>
#include <memory>
#include <string>

#include "commands.h"
#include "toonray/media/encode.h"

namespace toonray::cli {
namespace {

struct EncodeArgs {
    std::string frames_dir, output, audio;
    double fps = 24.0;
    int start_number = -1;
};

int run_encode(const EncodeArgs& args) {
    EncodeOptions options;
    options.frames_dir = args.frames_dir;
    options.output = args.output;
    options.fps = args.fps;
    options.audio = args.audio;
    if (args.start_number >= 0) options.start_number = args.start_number;
    EncodeResult result = encode_video(options);
    fmt::print(stderr, "toonray: wrote {}: {} frames ({}), {:.2f} s{}\n", args.output,
               result.frames.count, result.frames.pattern(), result.duration,
               args.audio.empty() ? "" : ", with audio");
    return 0;
}

}  // namespace

Subcommand add_encode_command(CLI::App& app) {
    auto args = std::make_shared<EncodeArgs>();
    CLI::App* encode = app.add_subcommand(
        "encode",
        "Compile a PNG sequence into an H.264 MP4 (yuv420p) with ffmpeg, optionally with audio");
    encode->add_option("frames", args->frames_dir, "Directory holding one numbered PNG sequence")
        ->required()
        ->check(CLI::ExistingDirectory);
    encode->add_option("-o,--output", args->output, "MP4 file to write")->required();
    encode->add_option("--fps", args->fps, "Frames per second")
        ->check(CLI::Range(0.001, 1000.0))
        ->capture_default_str();
    encode->add_option("--audio", args->audio,
                       "Soundtrack (WAV or anything ffmpeg reads), aligned with frame 0");
    encode
        ->add_option("--start-number", args->start_number,
                     "First frame number (default: the lowest present)")
        ->check(CLI::NonNegativeNumber);
    return {encode, [args] { return run_encode(*args); }};
}

}  // namespace toonray::cli
