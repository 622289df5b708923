#pragma once
/// Options shared by several subcommands, kept as text until validated, and what the subcommands
/// that render share: warnings, the stop signal, the score and its soundtrack.

#include <CLI/CLI.hpp>
#include <atomic>
#include <optional>
#include <string>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/media/audio.h"
#include "toonray/frame/frame_renderer.h"
#include "toonray/score/score.h"

namespace toonray::cli {

/// Options shared by every command that renders, kept as text until validated.
struct RenderArgs {
    std::string size = "1280x720";
    std::vector<std::string> lights;
    std::string lights_file;
    std::string ramp;
    bool shadows = false, specular = false, no_textures = false;
    float rim = 0.0f;
    std::string camera;
    std::string background = "1,1,1";
    std::string edges = "ink";  // the fewest specks and whole creases (docs/lines.md)
    float depth_threshold = 8.0f;
    float normal_threshold = 4.0f;
    std::string lines = "all";
    float crease_angle = LineSettings{}.crease_angle;
    float depth_step = RobustLineSettings{}.depth_step;
    float line_width = LineSettings{}.width;
    std::string line_colour = "0,0,0";
    int samples = SamplingSettings{}.samples;
    std::string adaptive = "on";
    int tile_size = SamplingSettings{}.tile_size;
    int threads = 0;
    int leaf_size = Bvh::Config{}.max_leaf_size;
    int png_level = PngOptions{}.level;
    std::string aov_dir;
    std::string aov_exr;
    // Ink line styles (add_ink_style_options).
    std::string line_style;
    float line_taper = 0.0f;
    bool line_width_by_depth = false;

    float auto_smooth = -1.0f;  ///< degrees; below 0: off

    void add_to(CLI::App& app);
    [[nodiscard]] FrameOptions resolve() const;
    /// Auto-smooth, the lights given (--light, --lights) and the camera (--camera), for an
    /// image of --size.
    [[nodiscard]] SceneSetup scene_setup() const;

private:
    void add_ink_style_options(CLI::App& app);
    void resolve_ink_style(FrameOptions& options) const;
};

/// Vector output of the ink lines: `--svg FILE` (render) or `--svg DIR` (one SVG per frame,
/// named like its PNG), `--hidden-lines` (alias `--svg-hidden`), `--svg-fill`.
struct SvgArgs {
    std::string svg;
    bool hidden = false, fill = false;

    void add_to(CLI::App& app, bool per_frame);
    /// Sets options.svg (or svg_dir), svg_hidden, svg_fill; Error for --hidden-lines or
    /// --svg-fill without --svg.
    void apply(FrameOptions& options, bool per_frame) const;
};

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
