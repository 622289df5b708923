#include <fmt/format.h>
#include <memory>

#include "commands.h"

namespace toonray::cli {

Subcommand add_settings_command(CLI::App& app) {
    auto args = std::make_shared<SettingsArgs>();
    CLI::App* settings = app.add_subcommand(
        "settings",
        "Print the effective settings as a TOML document (docs/settings.md): the defaults, a "
        "--settings file and the options given, as render, batch, piano and demo would use "
        "them; `--settings` reads the output back");
    args->add_to(*settings);
    return {settings, [args] {
                fmt::print("{}", settings_toml(args->settings()));
                return 0;
            }};
}

}  // namespace toonray::cli
