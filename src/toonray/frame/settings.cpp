#include "toonray/frame/settings.h"

#include <charconv>
#include <cmath>
#include <fmt/format.h>

#include "toonray/core/error.h"
#include "toonray/core/parse.h"

namespace toonray {

std::string_view toonray_version() { return TOONRAY_VERSION; }

namespace {

// ---- Values: what each kind of setting accepts -----------------------------------------------

[[noreturn]] void bad(const std::string& what) { throw Error(what); }

std::string describe(const SettingValue& v) {
    return std::visit(
        [](const auto& x) -> std::string {
            using T = std::decay_t<decltype(x)>;
            if constexpr (std::is_same_v<T, bool>) return x ? "true" : "false";
            else if constexpr (std::is_same_v<T, std::string>) return "'" + x + "'";
            else if constexpr (std::is_same_v<T, std::vector<std::string>>) return "a list";
            else return fmt::format("{}", x);
        },
        v);
}

double as_double(const SettingValue& v) {
    if (const auto* d = std::get_if<double>(&v)) return *d;
    if (const auto* i = std::get_if<std::int64_t>(&v)) return static_cast<double>(*i);
    if (const auto* s = std::get_if<std::string>(&v)) {
        double out = 0.0;
        const char* b = s->data();
        const auto [p, ec] = std::from_chars(b, b + s->size(), out);
        if (!s->empty() && ec == std::errc() && p == b + s->size()) return out;
    }
    bad(fmt::format("expected a number, got {}", describe(v)));
}

float as_float(const SettingValue& v, double lo, double hi) {
    const double d = as_double(v);
    if (!std::isfinite(d) || d < lo || d > hi)
        bad(fmt::format("{} is outside [{}, {}]", describe(v), lo, hi));
    return static_cast<float>(d);
}

std::int64_t as_int(const SettingValue& v, std::int64_t lo, std::int64_t hi) {
    std::int64_t out = 0;
    if (const auto* i = std::get_if<std::int64_t>(&v)) {
        out = *i;
    } else if (const auto* s = std::get_if<std::string>(&v)) {
        const char* b = s->data();
        const auto [p, ec] = std::from_chars(b, b + s->size(), out);
        if (s->empty() || ec != std::errc() || p != b + s->size())
            bad(fmt::format("expected a whole number, got {}", describe(v)));
    } else {
        bad(fmt::format("expected a whole number, got {}", describe(v)));
    }
    if (out < lo || out > hi) bad(fmt::format("{} is outside [{}, {}]", out, lo, hi));
    return out;
}

bool as_bool(const SettingValue& v) {
    if (const auto* b = std::get_if<bool>(&v)) return *b;
    if (const auto* s = std::get_if<std::string>(&v)) {
        for (const char* yes : {"true", "yes", "on"})
            if (*s == yes) return true;
        for (const char* no : {"false", "no", "off"})
            if (*s == no) return false;
    }
    bad(fmt::format("expected true or false, got {}", describe(v)));
}

std::string as_text(const SettingValue& v) {
    if (const auto* s = std::get_if<std::string>(&v)) return *s;
    bad(fmt::format("expected text, got {}", describe(v)));
}

std::vector<std::string> as_list(const SettingValue& v) {
    if (const auto* l = std::get_if<std::vector<std::string>>(&v)) return *l;
    if (const auto* s = std::get_if<std::string>(&v)) return {*s};
    bad(fmt::format("expected a list of text, got {}", describe(v)));
}

SettingValue number(float v) { return static_cast<double>(v); }

// A limit is kept as its text ("4G"), checked when set.
template <std::optional<std::string> LimitSettings::*kLimit>
std::optional<SettingValue> get_limit(const Settings& s) {
    const std::optional<std::string>& text = s.limits.*kLimit;
    if (!text) return std::nullopt;
    return SettingValue(*text);
}

template <std::optional<std::string> LimitSettings::*kLimit,
          std::uint64_t (*kParse)(std::string_view)>
void set_limit(Settings& s, const SettingValue& v) {
    const std::string text = as_text(v);
    (void)kParse(text);
    s.limits.*kLimit = text;
}

// ---- The table -------------------------------------------------------------------------------

using Get = std::optional<SettingValue> (*)(const Settings&);
using Set = void (*)(Settings&, const SettingValue&);

constexpr Setting kSettings[] = {
    // [image]
    {"image.size", "--size", SettingForm::Option, "Image size WIDTHxHEIGHT", true,
     [](const Settings& s) -> std::optional<SettingValue> {
         return fmt::format("{}x{}", s.render.width, s.render.height);
     },
     [](Settings& s, const SettingValue& v) {
         const ImageSize size = parse_image_size(as_text(v), "size");
         s.render.width = size.width;
         s.render.height = size.height;
     }},
    {"image.background", "--background", SettingForm::Option,
     "Colour where rays see nothing: r,g,b in [0,1] or #rrggbb", true,
     [](const Settings& s) -> std::optional<SettingValue> {
         return format_colour(s.render.background);
     },
     [](Settings& s, const SettingValue& v) {
         s.render.background = parse_colour(as_text(v), "background");
     }},
    // [scene]
    {"scene.camera", "--camera", SettingForm::Option,
     "Camera ex,ey,ez,gx,gy,gz,ux,uy,uz: eye, gaze point, up; replaces the scene's own camera "
     "(default: the OBJ camera block, the glTF camera or the piano's path, else a camera "
     "framing the scene)",
     true,
     [](const Settings& s) -> std::optional<SettingValue> {
         if (!s.scene.camera) return std::nullopt;
         const CameraSpec& c = *s.scene.camera;
         return format_vec3(c.eye) + "," + format_vec3(c.gaze) + "," + format_vec3(c.up);
     },
     [](Settings& s, const SettingValue& v) { s.scene.camera = parse_camera_spec(as_text(v)); }},
    {"scene.lights", "--light", SettingForm::Repeated,
     "A light, repeatable: x,y,z or point:x,y,z (a point light), dir:x,y,z (a directional "
     "light shining along the vector), each with an optional @intensity; replaces the scene's "
     "own lights (default: its lights file or glTF lights, else one point light at the eye "
     "moved by half the scene radius along the camera's up and right)",
     true,
     [](const Settings& s) -> std::optional<SettingValue> {
         if (s.scene.lights.empty()) return std::nullopt;
         std::vector<std::string> out;
         for (const Light& l : s.scene.lights) out.push_back(format_light(l));
         return out;
     },
     [](Settings& s, const SettingValue& v) {
         s.scene.lights.clear();
         for (const std::string& text : as_list(v)) s.scene.lights.push_back(parse_light(text));
     }},
    {"scene.auto_smooth", "--auto-smooth", SettingForm::Option,
     "Smooth normals for meshes without vertex normals: faces meeting at less than ANGLE "
     "degrees shade as one smooth surface, sharper edges stay creases (as Blender's "
     "auto-smooth; default off)",
     true,
     [](const Settings& s) -> std::optional<SettingValue> {
         if (!s.scene.auto_smooth) return std::nullopt;
         return number(*s.scene.auto_smooth);
     },
     [](Settings& s, const SettingValue& v) { s.scene.auto_smooth = as_float(v, 0, 180); }},
    // [shading]
    {"shading.ramp", "--ramp", SettingForm::Option,
     "Toon bands LEVELS@THRESHOLDS, e.g. 0.5,0.75,1.0@0.25,0.5 (the seed's ramp, the default): "
     "diffuse light below the first threshold gives the first level, and so on",
     true,
     [](const Settings& s) -> std::optional<SettingValue> {
         return format_ramp(s.render.shading.ramp);
     },
     [](Settings& s, const SettingValue& v) { s.render.shading.ramp = parse_ramp(as_text(v)); }},
    {"shading.shadows", "--shadows", SettingForm::Flag,
     "Toon shadows: lights blocked by geometry do not light a point", true,
     [](const Settings& s) -> std::optional<SettingValue> { return s.render.shading.shadows; },
     [](Settings& s, const SettingValue& v) { s.render.shading.shadows = as_bool(v); }},
    {"shading.specular", "--specular", SettingForm::Flag,
     "A hard-edged highlight band from the material's Ks and Ns", true,
     [](const Settings& s) -> std::optional<SettingValue> { return s.render.shading.specular; },
     [](Settings& s, const SettingValue& v) { s.render.shading.specular = as_bool(v); }},
    {"shading.rim", "--rim", SettingForm::Option,
     "Rim band width in [0,0.99] (0 = off): brightens surfaces seen edge-on", true,
     [](const Settings& s) -> std::optional<SettingValue> { return number(s.render.shading.rim); },
     [](Settings& s, const SettingValue& v) { s.render.shading.rim = as_float(v, 0.0, 0.99); }},
    {"shading.rim_strength", "--rim-strength", SettingForm::Option,
     "How much the rim band brightens: albedo times this is added", true,
     [](const Settings& s) -> std::optional<SettingValue> {
         return number(s.render.shading.rim_strength);
     },
     [](Settings& s, const SettingValue& v) {
         s.render.shading.rim_strength = as_float(v, 0.0, 10.0);
     }},
    {"shading.textures", "--no-textures", SettingForm::NegatedFlag,
     "Multiply Kd by map_Kd textures (--no-textures: ignore them)", true,
     [](const Settings& s) -> std::optional<SettingValue> { return s.render.shading.textures; },
     [](Settings& s, const SettingValue& v) { s.render.shading.textures = as_bool(v); }},
    // [lines]
    {"lines.mode", "--edges", SettingForm::Option,
     "Line mode: ink (lines found on the geometry, with ray-traced visibility, drawn as exact "
     "strokes; the default), robust (supersampled, plane-aware lines found between samples) or "
     "classic (the seed's Sobel pipeline, exactly)",
     true,
     [](const Settings& s) -> std::optional<SettingValue> {
         return std::string(line_mode_name(s.render.lines.mode));
     },
     [](Settings& s, const SettingValue& v) {
         s.render.lines.mode = parse_line_mode(as_text(v), "mode");
     }},
    {"lines.types", "--lines", SettingForm::Option,
     "Line types to draw, from silhouette,crease,depth,object,material (all: those five, the "
     "default), band (boundaries between cel bands, the terminator included) and shadow "
     "(boundaries of toon shadows, with --shadows), or none; the ink mode has no depth lines, "
     "only the ink mode has band and shadow lines",
     true,
     [](const Settings& s) -> std::optional<SettingValue> {
         return format_line_types(s.render.lines.types);
     },
     [](Settings& s, const SettingValue& v) {
         s.render.lines.types = parse_line_types(as_text(v));
     }},
    {"lines.crease_angle", "--crease-angle", SettingForm::Option,
     "Degrees between neighbouring surfaces above which a crease is drawn", true,
     [](const Settings& s) -> std::optional<SettingValue> {
         return number(s.render.lines.crease_angle);
     },
     [](Settings& s, const SettingValue& v) { s.render.lines.crease_angle = as_float(v, 0, 180); }},
    {"lines.width", "--line-width", SettingForm::Option,
     "Line width in pixels at 720 lines; scales with the image height", true,
     [](const Settings& s) -> std::optional<SettingValue> { return number(s.render.lines.width); },
     [](Settings& s, const SettingValue& v) { s.render.lines.width = as_float(v, 0, 100); }},
    {"lines.colour", "--line-color", SettingForm::Option, "Line colour r,g,b in [0,1] or #rrggbb",
     true,
     [](const Settings& s) -> std::optional<SettingValue> {
         return format_colour(s.render.lines.colour);
     },
     [](Settings& s, const SettingValue& v) {
         s.render.lines.colour = parse_colour(as_text(v), "colour");
     }},
    {"lines.classic.depth_threshold", "--depth-threshold", SettingForm::Option,
     "Classic: Sobel magnitude on the 8-bit depth map above which a pixel is a line", true,
     [](const Settings& s) -> std::optional<SettingValue> {
         return number(s.render.lines.classic.depth_threshold);
     },
     [](Settings& s, const SettingValue& v) {
         s.render.lines.classic.depth_threshold = as_float(v, 0, 1e6);
     }},
    {"lines.classic.normal_threshold", "--normal-threshold", SettingForm::Option,
     "Classic: Sobel magnitude on the 8-bit normal map above which a pixel is a line", true,
     [](const Settings& s) -> std::optional<SettingValue> {
         return number(s.render.lines.classic.normal_threshold);
     },
     [](Settings& s, const SettingValue& v) {
         s.render.lines.classic.normal_threshold = as_float(v, 0, 1e6);
     }},
    {"lines.robust.depth_step", "--depth-step", SettingForm::Option,
     "Robust: relative jump in depth (second difference of 1/z over 1/z) that makes a depth line",
     true,
     [](const Settings& s) -> std::optional<SettingValue> {
         return number(s.render.lines.robust.depth_step);
     },
     [](Settings& s, const SettingValue& v) {
         s.render.lines.robust.depth_step = as_float(v, 1e-9, 1e6);
     }},
    {"lines.robust.silhouette_ratio", "", SettingForm::Option,
     "Robust: a depth step larger than this fraction of the nearer depth is a silhouette, not a "
     "depth line",
     true,
     [](const Settings& s) -> std::optional<SettingValue> {
         return number(s.render.lines.robust.silhouette_ratio);
     },
     [](Settings& s, const SettingValue& v) {
         s.render.lines.robust.silhouette_ratio = as_float(v, 0, 1e6);
     }},
    {"lines.ink.taper", "--line-taper", SettingForm::Option,
     "Strokes: open strokes thin to nothing at their ends over this many pixels at 720 lines "
     "(0 = off); a style's taper overrides it",
     true,
     [](const Settings& s) -> std::optional<SettingValue> {
         return number(s.render.lines.ink.taper);
     },
     [](Settings& s, const SettingValue& v) { s.render.lines.ink.taper = as_float(v, 0, 1000); }},
    {"lines.ink.width_by_depth", "--line-width-by-depth", SettingForm::Flag,
     "Strokes: thinner farther away: full width at the distance of the scene's centre, scaled "
     "by it over the line's distance, within 0.25x-2x",
     true,
     [](const Settings& s) -> std::optional<SettingValue> {
         return s.render.lines.ink.width_by_depth;
     },
     [](Settings& s, const SettingValue& v) { s.render.lines.ink.width_by_depth = as_bool(v); }},
    // [tone]
    {"tone.mode", "--tone", SettingForm::Option,
     "Tone look: cel (the ramp's levels scale the colour; the default), hatch (hatch strokes "
     "over every band's full colour, as dark as the band) or screentone (dots likewise); hatch "
     "and screentone are drawn as ink (the ink line mode)",
     true,
     [](const Settings& s) -> std::optional<SettingValue> {
         return std::string(ink::tone_mode_name(s.render.tone.mode));
     },
     [](Settings& s, const SettingValue& v) {
         s.render.tone.mode = ink::parse_tone_mode(as_text(v));
     },
     false},
    {"tone.anchor", "--tone-anchor", SettingForm::Option,
     "What tone strokes and dots are fixed to: object (they move with the surfaces; hatching's "
     "default) or screen (locked to the image; screentone's default)",
     true,
     [](const Settings& s) -> std::optional<SettingValue> {
         if (!s.render.tone.anchor) return std::nullopt;
         return std::string(ink::tone_anchor_name(*s.render.tone.anchor));
     },
     [](Settings& s, const SettingValue& v) {
         s.render.tone.anchor = ink::parse_tone_anchor(as_text(v));
     },
     false},
    {"tone.hatch_direction", "--hatch-direction", SettingForm::Option,
     "Object-anchored hatch strokes cross: curvature (per object, the direction its normals vary "
     "least along, so strokes run around the form; the default), light (the light's direction: "
     "strokes follow the band boundaries), an axis x, y, z or X,Y,Z, or screen (strokes at "
     "--tone-angle on the image)",
     true,
     [](const Settings& s) -> std::optional<SettingValue> {
         return ink::format_hatch_direction(s.render.tone.direction);
     },
     [](Settings& s, const SettingValue& v) {
         s.render.tone.direction = ink::parse_hatch_direction(as_text(v));
     },
     false},
    {"tone.spacing", "--tone-spacing", SettingForm::Option,
     "Tone spacing in pixels at 720 lines (scales with the image height): hatch strokes of one "
     "direction at their closest, the side of a screentone cell",
     true,
     [](const Settings& s) -> std::optional<SettingValue> { return number(s.render.tone.spacing); },
     [](Settings& s, const SettingValue& v) { s.render.tone.spacing = as_float(v, 0.5, 1000); },
     false},
    {"tone.angle", "--tone-angle", SettingForm::Option,
     "Degrees counter-clockwise on the image of screen-locked hatch strokes and of screentone "
     "rows",
     true,
     [](const Settings& s) -> std::optional<SettingValue> { return number(s.render.tone.angle); },
     [](Settings& s, const SettingValue& v) { s.render.tone.angle = as_float(v, -360, 360); },
     false},
    // [sampling]
    {"sampling.samples", "--samples", SettingForm::Option,
     "Robust and ink: samples per pixel on a regular grid (1, 4, 9 or 16); lines and colours are "
     "filtered down from it",
     true,
     [](const Settings& s) -> std::optional<SettingValue> {
         return std::int64_t{s.render.sampling.samples};
     },
     [](Settings& s, const SettingValue& v) {
         const auto samples = static_cast<int>(as_int(v, 1, 16));
         (void)samples_per_side(samples);  // 1, 4, 9 or 16
         s.render.sampling.samples = samples;
     }},
    {"sampling.adaptive", "--adaptive", SettingForm::Option,
     "Robust and ink: on traces one sample per pixel and the rest of the grid only where the "
     "surfaces of neighbours differ; off traces every sample of every pixel (full supersampling)",
     true,
     [](const Settings& s) -> std::optional<SettingValue> { return s.render.sampling.adaptive; },
     [](Settings& s, const SettingValue& v) { s.render.sampling.adaptive = as_bool(v); }},
    {"sampling.tile_size", "--tile-size", SettingForm::Option,
     "Pixels per side of the buckets a frame is rendered in; memory follows the bucket, and the "
     "image is the same for any size",
     false,
     [](const Settings& s) -> std::optional<SettingValue> {
         return std::int64_t{s.render.sampling.tile_size};
     },
     [](Settings& s, const SettingValue& v) {
         s.render.sampling.tile_size = static_cast<int>(as_int(v, 1, 4096));
     }},
    {"render.threads", "--threads", SettingForm::Option, "Threads to use (0 = all)", false,
     [](const Settings& s) -> std::optional<SettingValue> {
         return std::int64_t{s.render.threads};
     },
     [](Settings& s, const SettingValue& v) {
         s.render.threads = static_cast<int>(as_int(v, 0, 1024));
     }},
    {"render.bvh_leaf_size", "--bvh-leaf-size", SettingForm::Option,
     "Largest number of triangles in a BVH leaf", false,
     [](const Settings& s) -> std::optional<SettingValue> {
         return std::int64_t{s.bvh.max_leaf_size};
     },
     [](Settings& s, const SettingValue& v) {
         s.bvh.max_leaf_size = static_cast<int>(as_int(v, 1, 64));
     }},
    // [output]
    {"output.png_level", "--png-level", SettingForm::Option,
     "PNG compression level, 1 (fast) to 12 (small)", false,
     [](const Settings& s) -> std::optional<SettingValue> { return std::int64_t{s.png.level}; },
     [](Settings& s, const SettingValue& v) { s.png.level = static_cast<int>(as_int(v, 1, 12)); }},
    {"output.svg_hidden", "--hidden-lines,--svg-hidden", SettingForm::Flag,
     "With --svg: also write the hidden lines, in a layer of their own", true,
     [](const Settings& s) -> std::optional<SettingValue> { return s.svg_hidden; },
     [](Settings& s, const SettingValue& v) { s.svg_hidden = as_bool(v); }},
    {"output.svg_fill", "--svg-fill", SettingForm::Flag,
     "With --svg: the cel-shaded colours as an embedded PNG under the lines", true,
     [](const Settings& s) -> std::optional<SettingValue> { return s.svg_fill; },
     [](Settings& s, const SettingValue& v) { s.svg_fill = as_bool(v); }},
    {"output.svg_plotter", "--svg-plotter", SettingForm::Flag,
     "With --svg: for a pen plotter: one Inkscape layer per pen (colour and width), touching "
     "paths merged, paths ordered to cut pen-up travel, centrelines only; hidden lines only with "
     "--hidden-lines; no fill",
     true, [](const Settings& s) -> std::optional<SettingValue> { return s.svg_plotter; },
     [](Settings& s, const SettingValue& v) { s.svg_plotter = as_bool(v); }, false},
    // [limits]: the help given on the command line is limit_help's, with the defaults.
    {"limits.triangles", "--max-triangles", SettingForm::Option, "Largest scene, in triangles",
     false, get_limit<&LimitSettings::triangles>,
     set_limit<&LimitSettings::triangles, parse_count>},
    {"limits.vertices", "--max-vertices", SettingForm::Option,
     "Most OBJ v, vn and vt statements, each", false, get_limit<&LimitSettings::vertices>,
     set_limit<&LimitSettings::vertices, parse_count>},
    {"limits.image_pixels", "--max-image-pixels", SettingForm::Option,
     "Largest image, width x height", false, get_limit<&LimitSettings::image_pixels>,
     set_limit<&LimitSettings::image_pixels, parse_count>},
    {"limits.memory", "--max-memory", SettingForm::Option, "Memory the estimate of a run may reach",
     false, get_limit<&LimitSettings::memory>, set_limit<&LimitSettings::memory, parse_bytes>},
    {"limits.input_size", "--max-input-size", SettingForm::Option, "Largest input file", false,
     get_limit<&LimitSettings::input_size>, set_limit<&LimitSettings::input_size, parse_bytes>},
};

}  // namespace

std::span<const Setting> settings_table() { return kSettings; }

const Setting* find_setting(std::string_view key) {
    for (const Setting& s : kSettings)
        if (s.key == key) return &s;
    return nullptr;
}

void set_setting(Settings& settings, std::string_view key, const SettingValue& value) {
    const Setting* setting = find_setting(key);
    if (!setting) throw Error(fmt::format("unknown key '{}'", key));
    try {
        setting->set(settings, value);
    } catch (const Error& e) {
        throw Error(fmt::format("{}: {}", key, e.what()));
    }
}

void add_line_rule(Settings& settings, std::span<const std::pair<std::string, std::string>> entries,
                   const std::string& where) {
    settings.render.lines.ink.styles.rules.push_back(
        ink::make_line_style_rule(entries, ink::RuleLocation{where, "."}));
}

SceneSetup Settings::scene_setup() const {
    SceneSetup setup = scene;
    setup.width = render.width;
    setup.height = render.height;
    return setup;
}

FrameOptions Settings::frame_options() const {
    FrameOptions o;
    o.settings = render;
    o.bvh = bvh;
    o.png = png;
    o.svg_hidden = svg_hidden;
    o.svg_fill = svg_fill;
    o.svg_plotter = svg_plotter;
    o.record = output_record(*this);
    return o;
}

Limits Settings::applied_limits(const Limits& base) const {
    Limits l = base;
    auto apply = [](const std::optional<std::string>& text, const char* key, auto parse,
                    std::uint64_t& out) {
        if (!text) return;
        try {
            out = parse(*text);
        } catch (const Error& e) {
            throw Error(fmt::format("{}: {}", key, e.what()));
        }
    };
    apply(limits.triangles, "limits.triangles", parse_count, l.max_triangles);
    apply(limits.vertices, "limits.vertices", parse_count, l.max_vertices);
    apply(limits.image_pixels, "limits.image_pixels", parse_count, l.max_image_pixels);
    apply(limits.memory, "limits.memory", parse_bytes, l.max_memory);
    apply(limits.input_size, "limits.input_size", parse_bytes, l.max_input_bytes);
    return l;
}

void check_settings(const Settings& settings) {
    try {
        check_line_settings(settings.render.lines);
    } catch (const Error& e) {
        throw Error(fmt::format("lines.types: {}", e.what()));
    }
    if ((settings.render.lines.types & kLineShadow) && !settings.render.shading.shadows)
        throw Error(
            "lines.types: shadow lines are the boundaries of toon shadows, which are off: add "
            "--shadows (shading.shadows = true)");
    if (settings.render.tone.mode != ink::ToneMode::Cel &&
        settings.render.lines.mode != LineMode::Ink)
        throw Error(fmt::format(
            "tone.mode: {} is drawn as ink, under the ink lines; the {} lines are drawn into "
            "pixels with the colours: use --edges ink (the default)",
            ink::tone_mode_name(settings.render.tone.mode),
            line_mode_name(settings.render.lines.mode)));
}

OutputRecord output_record(const Settings& settings) {
    return {fmt::format("toonray {}", toonray_version()), settings_toml(settings, true)};
}

}  // namespace toonray
