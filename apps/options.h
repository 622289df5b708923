#pragma once
/// Options shared by several subcommands, kept as text until validated, and what the subcommands
/// that render share: warnings, the stop signal, the score and its soundtrack.

#include <CLI/CLI.hpp>
#include <atomic>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/media/audio.h"
#include "toonray/frame/frame_renderer.h"
#include "toonray/frame/settings.h"
#include "toonray/score/score.h"

namespace toonray::cli {

/// The settings of every command that renders: one command-line option per key of the
/// settings document (frame/settings.h, settings_table()), given as text and read by the
/// table's own setters; `--settings FILE` (the document as TOML, which the options given
/// override); `--lights FILE` and `--line-style FILE`; and where feature images go.
class SettingsArgs {
public:
    void add_to(CLI::App& app);
    /// The defaults, then the settings file, then every option given. Throws Error naming the
    /// option (or the file, line and key) of a bad value.
    [[nodiscard]] Settings settings() const;
    /// Frame options of `settings` with the feature image outputs (--aov, --aov-exr) and
    /// what the outputs record.
    [[nodiscard]] FrameOptions frame_options(const Settings& settings) const;
    /// settings(), with the limits it gives made the process-wide limits (before any work).
    [[nodiscard]] Settings apply() const;
    /// Whether the option of a settings key was given on the command line.
    [[nodiscard]] bool given(std::string_view key) const;

private:
    /// One option of the table, with where CLI11 puts its value.
    struct Entry {
        const Setting* setting = nullptr;
        CLI::Option* option = nullptr;
        std::string text;
        std::vector<std::string> list;
        bool flag = false;
    };
    std::deque<Entry> entries_;  // stable addresses: CLI11 writes into them
    std::string settings_file_, lights_file_, line_style_, aov_dir_, aov_exr_;
    CLI::Option* lights_file_option_ = nullptr;
};

/// Vector output of the ink lines: `--svg FILE` (render) or `--svg DIR` (one SVG per frame,
/// named like its PNG). Its look (hidden lines, fill) is in the settings.
struct SvgArgs {
    std::string svg;

    void add_to(CLI::App& app, bool per_frame);
    /// Sets options.svg (or svg_dir); Error for --hidden-lines or --svg-fill without --svg.
    void apply(FrameOptions& options, bool per_frame, const SettingsArgs& settings) const;
};

/// The help of a limit's option, with its default.
[[nodiscard]] std::string limit_help(std::string_view flag);

/// Limits on what inputs may ask for (docs/robustness.md), as text until validated.
struct LimitArgs {
    std::string triangles, vertices, pixels, memory, input_size;

    void add_to(CLI::App& app);
    /// Sets the process-wide limits; call before any work.
    void apply() const;
};

/// Options of `piano` and `demo`.
struct PianoArgs {
    std::string score, camera_path, soundfont, export_obj, audio;
    double start = 0.0, seconds = 0.0, fps = 24.0;
    std::string name = "keys";
    int jobs = 0;
    bool resume = false, quiet = false;

    void add_common(CLI::App& app);
};

void print_warnings(const Warnings& warnings);

/// Installs SIGINT and SIGTERM handlers and returns the flag they set: long runs finish the
/// frames in flight and stop.
const std::atomic<bool>* install_stop_handlers();

/// The score at `path`, or the built-in one when `path` is empty.
Score load_score_or_demo(const std::string& path);

/// Audio options for the soundtrack of `seconds` of `score` (to its end when empty); throws if the
/// soundtrack would not fit the memory limit.
AudioOptions audio_options(const Score& score, const PianoArgs& args,
                           std::optional<double> seconds);

}  // namespace toonray::cli
