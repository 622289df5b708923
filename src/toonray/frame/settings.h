#pragma once
/// The settings document: every render and line option in one place, as the command line, a
/// TOML file (`--settings FILE`), the Python module and the Blender engine give them
/// (docs/settings.md). One table of keys (settings_table) is read by all of them, and written
/// back as TOML (`toonray settings`) and into every output the settings made.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "toonray/accel/bvh.h"
#include "toonray/core/limits.h"
#include "toonray/frame/frame_renderer.h"
#include "toonray/io/png.h"
#include "toonray/render/render_settings.h"
#include "toonray/scene/scene_source.h"

namespace toonray {

/// "0.2.0": the version every output records with its settings.
[[nodiscard]] std::string_view toonray_version();

/// The limits the settings give (`[limits]`): each as its text ("4G", "50M"), unset for the
/// default.
struct LimitSettings {
    std::optional<std::string> triangles, vertices, image_pixels, memory, input_size;
    bool operator==(const LimitSettings&) const = default;
};

/// Everything a frame is made with, apart from where its files go.
struct Settings {
    RenderSettings render;  ///< layers, strokes and hidden_lines are set by the outputs asked for
    SceneSetup scene;       ///< its width and height follow render's (scene_setup())
    Bvh::Config bvh;
    PngOptions png;
    bool svg_hidden = false;   ///< an SVG also holds the hidden lines
    bool svg_fill = false;     ///< an SVG also holds the cel picture under its lines
    bool svg_plotter = false;  ///< an SVG is for a pen plotter (ink/plotter.h)
    LimitSettings limits;

    /// The scene setup for frames of render's size.
    [[nodiscard]] SceneSetup scene_setup() const;
    /// Frame options with these settings and no outputs (the caller sets the files).
    [[nodiscard]] FrameOptions frame_options() const;
    /// The process-wide limits with these applied over `base`. Throws Error ("limits.memory:
    /// ...") for a malformed one.
    [[nodiscard]] Limits applied_limits(const Limits& base) const;
};

/// A setting's value as TOML, Python and the command line give it. Text is read as the command
/// line reads the option's text.
using SettingValue =
    std::variant<bool, std::int64_t, double, std::string, std::vector<std::string>>;

/// How the command line gives a setting.
enum class SettingForm {
    Option,       ///< `--flag VALUE`
    Repeated,     ///< `--flag VALUE`, any number of times, a list
    Flag,         ///< `--flag` sets it to true
    NegatedFlag,  ///< `--flag` sets it to false
};

/// One key of the document.
struct Setting {
    std::string_view key;   ///< its TOML path: "lines.width"
    std::string_view flag;  ///< its command-line option ("--line-width"), or empty
    SettingForm form = SettingForm::Option;
    std::string_view help;
    /// Whether it can change the picture. The others (threads, bucket size, limits) are not
    /// recorded in the outputs: frames made with different ones are the same.
    bool picture = true;
    /// The value; nullopt for an optional setting left unset.
    std::optional<SettingValue> (*get)(const Settings&);
    /// Sets it; throws Error("what was wrong") without naming the key or flag.
    void (*set)(Settings&, const SettingValue&);
    /// Whether an output records it at its default value. Keys that came after outputs first
    /// recorded their settings are recorded only when set otherwise, so that a frame made
    /// without them records, and is, the same bytes as before.
    bool recorded_at_default = true;
};

/// Every key of the document, in the order they are written.
[[nodiscard]] std::span<const Setting> settings_table();
/// The setting of a key, or null.
[[nodiscard]] const Setting* find_setting(std::string_view key);

/// Sets `key` from `value`. Throws Error("KEY: what was wrong") for an unknown key or a bad
/// value.
void set_setting(Settings& settings, std::string_view key, const SettingValue& value);

/// The line rules of a `[[lines.rule]]` table (key and value text pairs, as a `.style` match
/// line has them), `where` naming it in errors ("s.toml: lines.rule[2]").
void add_line_rule(Settings& settings, std::span<const std::pair<std::string, std::string>> entries,
                   const std::string& where);

/// Reads a TOML settings document over `settings`: the keys it has replace those values; the
/// others stay. `source` names it in errors: "SOURCE:LINE:COLUMN: KEY: what was wrong" (or a
/// TOML syntax error with its place). Throws Error.
void read_settings(std::string_view text, std::string_view source, Settings& settings);
/// read_settings of a file.
void load_settings(const std::filesystem::path& path, Settings& settings);

/// The settings as a TOML document that read_settings reads back to the same settings: every
/// key with its value, unset optional ones as comments, then the line rules. With
/// `picture_only`, only the keys that can change the picture (what outputs record).
[[nodiscard]] std::string settings_toml(const Settings& settings, bool picture_only = false);

/// Checks what no single key can: throws Error for line types the mode cannot draw.
void check_settings(const Settings& settings);

/// What an output records of the settings that made it (FrameOptions::record).
[[nodiscard]] OutputRecord output_record(const Settings& settings);

}  // namespace toonray
