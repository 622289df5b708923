#include <memory>
#include <string>

#include "commands.h"
#include "toonray/score/score_io.h"

namespace toonray::cli {
namespace {

struct ConvertArgs {
    std::string input, output;
};

int run_convert(const ConvertArgs& args) {
    Warnings warnings;
    convert_score(args.input, args.output, &warnings);
    print_warnings(warnings);
    return 0;
}

}  // namespace

Subcommand add_score_command(CLI::App& app, LimitArgs& limit_args) {
    auto args = std::make_shared<ConvertArgs>();
    CLI::App* score = app.add_subcommand("score", "Work with scores (note scripts and MIDI files)");
    score->require_subcommand(1);
    CLI::App* convert = score->add_subcommand(
        "convert",
        "Convert between a MIDI file and a note script, losslessly where the script can say it "
        "(the output's extension chooses: .mid/.midi or .notes)");
    convert->add_option("input", args->input, "Score to read (MIDI or note script)")
        ->required()
        ->check(CLI::ExistingFile);
    convert->add_option("output", args->output, "Score to write")->required();
    limit_args.add_to(*convert);
    return {convert, [args] { return run_convert(*args); }};
}

}  // namespace toonray::cli
