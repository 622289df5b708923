#include "options.h"

#include <algorithm>
#include <csignal>
#include <cstdint>
#include <fmt/format.h>

#include "hints.h"
#include "toonray/anim/piano_movie.h"
#include "toonray/core/limits.h"
#include "toonray/core/parse.h"
#include "toonray/scene/light.h"
#include "toonray/ink/line_style.h"
#include "toonray/io/file.h"
#include "toonray/score/score_io.h"

namespace toonray::cli {

std::string limit_help(std::string_view flag) {
    const Limits d;
    if (flag == "--max-triangles")
        return fmt::format("Largest scene, in triangles (default {}; k, M, G suffixes)",
                           d.max_triangles);
    if (flag == "--max-vertices")
        return fmt::format("Most OBJ v, vn and vt statements, each (default {})", d.max_vertices);
    if (flag == "--max-image-pixels")
        return fmt::format("Largest image, width x height (default {} = 8192x8192)",
                           d.max_image_pixels);
    if (flag == "--max-memory")
        return "Memory the estimate of a run may reach (frame buffers and scenes of all frames in "
               "flight), e.g. 4G (default: 3/4 of physical memory)";
    return fmt::format("Largest input file: OBJ, MTL, score, camera path (default {})",
                       format_bytes(d.max_input_bytes));
}

namespace {

// A default value as the help shows it.
std::string default_text(const SettingValue& value) {
    return std::visit(
        [](const auto& v) -> std::string {
            using T = std::decay_t<decltype(v)>;
            if constexpr (std::is_same_v<T, std::string>) return v;
            else if constexpr (std::is_same_v<T, std::vector<std::string>>) return "";
            else if constexpr (std::is_same_v<T, double>)
                return format_number(static_cast<float>(v));
            else return fmt::format("{}", v);
        },
        value);
}

}  // namespace

void SettingsArgs::add_to(CLI::App& app) {
    app.add_option("--settings", settings_file_,
                   "A settings document (TOML, docs/settings.md: `toonray settings` prints one); "
                   "options given on the command line override its keys")
        ->check(CLI::ExistingFile);
    const Settings defaults;
    for (const Setting& setting : settings_table()) {
        if (setting.flag.empty()) continue;
        Entry& e = entries_.emplace_back();
        e.setting = &setting;
        const std::string flag(setting.flag), help(setting.help);
        switch (setting.form) {
            case SettingForm::Option: e.option = app.add_option(flag, e.text, help); break;
            case SettingForm::Repeated: e.option = app.add_option(flag, e.list, help); break;
            case SettingForm::Flag:
            case SettingForm::NegatedFlag: e.option = app.add_flag(flag, e.flag, help); break;
        }
        if (setting.key.starts_with("limits.")) {
            e.option->description(limit_help(flag));
            e.option->group("Limits");
        } else if (setting.form == SettingForm::Option) {
            if (const auto value = setting.get(defaults))
                e.option->default_str(default_text(*value));
        }
    }
    lights_file_option_ =
        app.add_option("--lights", lights_file_,
                       "File of lights, one per line: point x y z [intensity] | directional x y z "
                       "[intensity]; with --light, both")
            ->check(CLI::ExistingFile);
    app.add_option("--line-style", line_style_,
                   "Line sets and styles file (docs/ink.md): rules matching objects, materials, "
                   "line types and visible/hidden lines, setting draw, color, width, opacity, "
                   "dash, taper and width_by_depth; replaces the settings' rules")
        ->check(CLI::ExistingFile);
    app.add_option(
        "--aov", aov_dir_,
        "Also write feature images to this directory, named after the output: "
        "NAME_depth, _normal, _edges, _cel .png, and per mode: classic _edges_depth, "
        "_edges_normal; robust _lines_silhouette, _lines_crease, _lines_depth, _lines_object, "
        "_lines_material, _object_id, _material_id, _samples; ink _lines_silhouette, "
        "_lines_crease, _lines_material, _lines_border, _lines_intersection, _lines_polyline, "
        "_object_id, _material_id, _samples");
    app.add_option("--aov-exr", aov_exr_,
                   "Also write the frame's layers as one multi-layer OpenEXR (docs/exr.md): "
                   "render: this .exr file; batch, piano, demo: a directory, one NAME.exr a frame");
}

Settings SettingsArgs::settings() const {
    Settings settings;
    if (!settings_file_.empty()) load_settings(settings_file_, settings);
    for (const Entry& e : entries_) {
        if (e.option->count() == 0) continue;
        SettingValue value;
        switch (e.setting->form) {
            case SettingForm::Option: value = e.text; break;
            case SettingForm::Repeated: value = e.list; break;
            case SettingForm::Flag: value = e.flag; break;
            case SettingForm::NegatedFlag: value = !e.flag; break;
        }
        const std::string flag(e.setting->flag.substr(0, e.setting->flag.find(',')));
        with_flag(flag, [&] {
            try {
                e.setting->set(settings, value);
            } catch (const Error& error) {
                throw Error(fmt::format("{}: {}", flag, error.what()));
            }
        });
    }
    if (!lights_file_.empty()) {
        // With --light both, else the file's lights replace the settings'.
        if (!given("scene.lights")) settings.scene.lights.clear();
        const std::vector<Light> from_file = load_lights(lights_file_);
        settings.scene.lights.insert(settings.scene.lights.end(), from_file.begin(),
                                     from_file.end());
    }
    if (!line_style_.empty())
        settings.render.lines.ink.styles =
            ink::parse_line_styles(read_file(line_style_), line_style_);
    // check_settings names the key at fault ("lines.types: ..."): its flag goes in front.
    try {
        check_settings(settings);
    } catch (const Error& e) {
        const std::string_view what = e.what();
        const Setting* setting = find_setting(what.substr(0, what.find(':')));
        if (!setting || setting->flag.empty()) throw;
        throw Error(fmt::format("{}: {}", setting->flag.substr(0, setting->flag.find(',')), what));
    }
    return settings;
}

Settings SettingsArgs::apply() const {
    Settings s = settings();
    set_limits(s.applied_limits(limits()));
    return s;
}

FrameOptions SettingsArgs::frame_options(const Settings& settings) const {
    FrameOptions o = settings.frame_options();
    if (!aov_dir_.empty()) o.aov_dir = aov_dir_;
    if (!aov_exr_.empty()) o.aov_exr = aov_exr_;
    return o;
}

void SvgArgs::add_to(CLI::App& app, bool per_frame) {
    app.add_option("--svg", svg,
                   per_frame
                       ? "Also write each frame's ink lines as SVG into this directory, named "
                         "like its PNG (NAME_000030.svg), in any --edges mode; resumable like PNGs"
                       : "Also write the ink lines as SVG paths in pixel units, grouped by type "
                         "(silhouette, border, crease, material, intersection), in any --edges "
                         "mode");
}

bool SettingsArgs::given(std::string_view key) const {
    return std::any_of(entries_.begin(), entries_.end(), [&](const Entry& e) {
        return e.setting->key == key && e.option->count() > 0;
    });
}

void SvgArgs::apply(FrameOptions& options, bool per_frame, const SettingsArgs& settings) const {
    if (svg.empty()) {
        if (settings.given("output.svg_hidden")) throw Error("--hidden-lines needs --svg");
        if (settings.given("output.svg_fill")) throw Error("--svg-fill needs --svg");
        return;
    }
    if (per_frame) options.svg_dir = svg;
    else options.svg = svg;
}

void LimitArgs::add_to(CLI::App& app) {
    for (auto [flag, text] : {std::pair{"--max-triangles", &triangles},
                              {"--max-vertices", &vertices},
                              {"--max-image-pixels", &pixels},
                              {"--max-memory", &memory},
                              {"--max-input-size", &input_size}})
        app.add_option(flag, *text, limit_help(flag))->group("Limits");
}

void LimitArgs::apply() const {
    Limits l = limits();
    if (!triangles.empty())
        l.max_triangles = with_flag("--max-triangles", [&] { return parse_count(triangles); });
    if (!vertices.empty())
        l.max_vertices = with_flag("--max-vertices", [&] { return parse_count(vertices); });
    if (!pixels.empty())
        l.max_image_pixels = with_flag("--max-image-pixels", [&] { return parse_count(pixels); });
    if (!memory.empty())
        l.max_memory = with_flag("--max-memory", [&] { return parse_bytes(memory); });
    if (!input_size.empty())
        l.max_input_bytes = with_flag("--max-input-size", [&] { return parse_bytes(input_size); });
    set_limits(l);
}

void PianoArgs::add_common(CLI::App& app) {
    app.add_option("--camera-path", camera_path,
                   "Camera path file (docs/camera-path.md; default: the built-in path)");
    app.add_option("--fps", fps, "Frames per second")
        ->check(CLI::Range(0.001, 1000.0))
        ->capture_default_str();
    app.add_option("--start", start, "Score time of the first frame, seconds")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    app.add_option("--jobs", jobs, "Frames rendered at once (0 = one per core)")
        ->check(CLI::Range(0, 256))
        ->capture_default_str();
    app.add_option("--soundfont", soundfont, "SoundFont for the audio (default: FluidR3 GM)");
    app.add_flag("--resume", resume, "Skip frames whose PNG already exists and is valid");
    app.add_flag("-q,--quiet", quiet, "No progress output");
}

void print_warnings(const Warnings& warnings) {
    for (const auto& w : warnings) fmt::print(stderr, "toonray: warning: {}\n", w);
}

namespace {

std::atomic<bool> stop_requested{false};

extern "C" void request_stop(int) { stop_requested = true; }

}  // namespace

const std::atomic<bool>* install_stop_handlers() {
    struct sigaction sa {};
    sa.sa_handler = request_stop;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
    return &stop_requested;
}

Score load_score_or_demo(const std::string& path) {
    if (path.empty()) return load_demo_score();
    Warnings warnings;
    Score score = load_score(path, &warnings);
    print_warnings(warnings);
    return score;
}

AudioOptions audio_options(const Score& score, const PianoArgs& args,
                           std::optional<double> seconds) {
    AudioOptions audio;
    audio.soundfont = args.soundfont;
    audio.start = args.start;
    audio.length = seconds;
    // The soundtrack is synthesised in memory (16-bit stereo, then its WAV copy): a score that
    // lasts for days must fail here, not in an allocation.
    const double length =
        seconds ? *seconds : std::max(score.end_time, score.duration()) - args.start + 5.0;
    const double bytes = std::max(0.0, length) * audio.sample_rate * 2 * 2 * 2;
    try {
        check_memory(bytes < 1.8e19 ? static_cast<std::uint64_t>(bytes) : UINT64_MAX,
                     fmt::format("the soundtrack ({:.0f} s)", length));
    } catch (const LimitError& e) {
        // Fewer frames at once (--jobs) leave the soundtrack as large: only the limit helps.
        throw Error(fmt::format("{} ({})", e.what(), raise_hint(e.limit())));
    }
    return audio;
}

}  // namespace toonray::cli
