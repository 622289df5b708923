// toonray command line: parses arguments into options and calls the library. Errors from the
// library carry file and line; they are caught here once and printed.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <fmt/format.h>

#include "commands.h"
#include "hints.h"
#include "toonray/core/error.h"
#include "toonray/core/memory.h"
#include "toonray/frame/settings.h"

namespace {

using namespace toonray::cli;

/// Runs `command`; a limit it exceeds is reported with the option that raises it.
int run(const Subcommand& command) {
    try {
        return command.run();
    } catch (const toonray::LimitError& e) {
        throw toonray::Error(with_limit_hint(e.what(), e.limit(), *command.app));
    }
}

}  // namespace

int main(int argc, char** argv) {
    toonray::retain_freed_memory();
    CLI::App app{"toonray: a toon ray tracer. OBJ/MTL scenes in, cel-shaded and outlined PNG out."};
    app.require_subcommand(1);
    app.set_version_flag("--version", "toonray " + std::string(toonray::toonray_version()));

    LimitArgs limit_args;
    const Subcommand commands[] = {
        add_render_command(app),   add_batch_command(app),
        add_encode_command(app),   add_score_command(app, limit_args),
        add_piano_command(app),    add_demo_command(app),
        add_settings_command(app),
    };

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    }

    try {
        limit_args.apply();
        for (const Subcommand& command : commands)
            if (*command.app) return run(command);
    } catch (const std::exception& e) {
        fmt::print(stderr, "toonray: error: {}\n", e.what());
        return 1;
    }
    return 0;
}
