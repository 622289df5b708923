#pragma once
/// The subcommands of toonray, one file each (cmd_*.cpp).

#include <CLI/CLI.hpp>
#include <functional>

#include "options.h"

namespace toonray::cli {

/// A subcommand as main sees it: the CLI::App its options were added to, and the work it
/// stands for, which returns the exit status.
struct Subcommand {
    CLI::App* app;
    std::function<int()> run;
};

// Each adds its subcommand to `app`. The commands that render take their limits with their
// settings (SettingsArgs); `score` reads inputs only and takes `limit_args`.
Subcommand add_render_command(CLI::App& app);
Subcommand add_batch_command(CLI::App& app);
Subcommand add_encode_command(CLI::App& app);
Subcommand add_score_command(CLI::App& app, LimitArgs& limit_args);
Subcommand add_piano_command(CLI::App& app);
Subcommand add_demo_command(CLI::App& app);
Subcommand add_settings_command(CLI::App& app);

}  // namespace toonray::cli
