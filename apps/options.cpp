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

void RenderArgs::add_to(CLI::App& app) {
    app.add_option("--size", size, "Image size WIDTHxHEIGHT")->capture_default_str();
    app.add_option(
        "--light", lights,
        "A light, repeatable: x,y,z or point:x,y,z (a point light), dir:x,y,z (a directional "
        "light shining along the vector), each with an optional @intensity (default: one "
        "point light at the eye moved by half the scene radius along the camera's up and right)");
    app.add_option(
           "--lights", lights_file,
           "File of lights, one per line: point x y z [intensity] | directional x y z [intensity]")
        ->check(CLI::ExistingFile);
    app.add_option(
        "--ramp", ramp,
        "Toon bands LEVELS@THRESHOLDS, e.g. 0.5,0.75,1.0@0.25,0.5 (the seed's ramp, the default): "
        "diffuse light below the first threshold gives the first level, and so on");
    app.add_flag("--shadows", shadows,
                 "Toon shadows: lights blocked by geometry do not light a point");
    app.add_flag("--specular", specular,
                 "A hard-edged highlight band from the material's Ks and Ns");
    app.add_option("--rim", rim,
                   "Rim band width in [0,1) (0 = off): brightens surfaces seen edge-on")
        ->check(CLI::Range(0.0f, 0.99f))
        ->capture_default_str();
    app.add_flag("--no-textures", no_textures, "Ignore map_Kd textures");
    app.add_option("--auto-smooth", auto_smooth,
                   "Smooth normals for meshes without vertex normals: faces meeting at less than "
                   "ANGLE degrees shade as one smooth surface, sharper edges stay creases "
                   "(as Blender's auto-smooth; default off)")
        ->check(CLI::Range(0.0f, 180.0f));
    app.add_option("--camera", camera,
                   "Camera ex,ey,ez,gx,gy,gz,ux,uy,uz: eye, gaze point, up; overrides the "
                   "file's camera block (default: the block, else a camera framing the scene)");
    app.add_option("--background", background, "Background colour r,g,b in [0,1] or #rrggbb")
        ->capture_default_str();
    app.add_option(
           "--edges", edges,
           "Line mode: ink (lines found on the geometry, with ray-traced visibility, drawn as "
           "exact strokes; render --svg writes them), robust (supersampled, plane-aware lines "
           "found between samples) or classic (the seed's Sobel pipeline, exactly)")
        ->check(CLI::IsMember({"robust", "classic", "ink"}))
        ->capture_default_str();
    app.add_option(
           "--lines", lines,
           "Robust: line types to draw, from silhouette,crease,depth,object,material (or all, none)")
        ->capture_default_str();
    app.add_option(
           "--crease-angle", crease_angle,
           "Robust: angle in degrees between neighbouring surfaces above which a crease is drawn")
        ->check(CLI::Range(0.0f, 180.0f))
        ->capture_default_str();
    app.add_option(
           "--depth-step", depth_step,
           "Robust: relative jump in depth (second difference of 1/z over 1/z) that makes a depth line")
        ->check(CLI::PositiveNumber)
        ->capture_default_str();
    app.add_option("--line-width", line_width,
                   "Robust: line width in pixels at 720 lines; scales with the image height")
        ->check(CLI::Range(0.0f, 100.0f))
        ->capture_default_str();
    app.add_option("--line-color", line_colour, "Robust: line colour r,g,b in [0,1] or #rrggbb")
        ->capture_default_str();
    app.add_option("--samples", samples,
                   "Robust and ink: samples per pixel on a regular grid (1, 4, 9 or 16); lines and "
                   "colours are filtered down from it")
        ->check(CLI::IsMember({1, 4, 9, 16}))
        ->capture_default_str();
    app.add_option("--adaptive", adaptive,
                   "Robust and ink: on traces one sample per pixel and the rest of the grid only "
                   "where neighbours differ (colour, and for robust lines ids, normals, depth "
                   "steps); off traces every sample of every pixel (full supersampling)")
        ->check(CLI::IsMember({"on", "off"}))
        ->capture_default_str();
    app.add_option("--tile-size", tile_size,
                   "Robust and ink: pixels per side of the buckets a frame is rendered in; "
                   "memory follows the bucket, and the image is the same for any size")
        ->check(CLI::Range(1, 4096))
        ->capture_default_str();
    app.add_option(
           "--depth-threshold", depth_threshold,
           "Classic mode: Sobel magnitude on the 8-bit depth map above which a pixel is a line")
        ->capture_default_str();
    app.add_option(
           "--normal-threshold", normal_threshold,
           "Classic mode: Sobel magnitude on the 8-bit normal map above which a pixel is a line")
        ->capture_default_str();
    app.add_option(
        "--aov", aov_dir,
        "Also write feature images to this directory, named after the output: "
        "NAME_depth, _normal, _edges, _cel .png, and per mode: classic _edges_depth, "
        "_edges_normal; robust _lines_silhouette, _lines_crease, _lines_depth, _lines_object, "
        "_lines_material, _object_id, _material_id, _samples; ink _lines_silhouette, "
        "_lines_crease, _lines_material, _lines_border, _lines_intersection, _lines_polyline, "
        "_object_id, _material_id, _samples");
    app.add_option("--aov-exr", aov_exr,
                   "Also write the feature images as one multi-layer OpenEXR (docs/exr.md): "
                   "render: this .exr file; batch, piano, demo: a directory, one NAME.exr a frame");
    app.add_option("--threads", threads, "Threads to use (0 = all)")
        ->check(CLI::Range(0, 1024))
        ->capture_default_str();
    app.add_option("--bvh-leaf-size", leaf_size, "Largest number of triangles in a BVH leaf")
        ->check(CLI::Range(1, 64))
        ->capture_default_str();
    app.add_option("--png-level", png_level, "PNG compression level, 1 (fast) to 12 (small)")
        ->check(CLI::Range(1, 12))
        ->capture_default_str();
    add_ink_style_options(app);
}

void RenderArgs::add_ink_style_options(CLI::App& app) {
    app.add_option("--line-style", line_style,
                   "Ink: line sets and styles file (docs/ink.md): rules matching objects, "
                   "materials, line types and visible/hidden lines, setting draw, color, width, "
                   "opacity, dash and taper")
        ->check(CLI::ExistingFile);
    app.add_option("--line-taper", line_taper,
                   "Ink: open strokes thin to nothing at their ends over this many pixels at 720 "
                   "lines (0 = off); a style's taper overrides it")
        ->check(CLI::Range(0.0f, 1000.0f))
        ->capture_default_str();
    app.add_flag("--line-width-by-depth", line_width_by_depth,
                 "Ink: lines thinner farther away: full width at the distance of the scene's "
                 "centre, scaled by it over the line's distance, within 0.25x-2x");
}

void RenderArgs::resolve_ink_style(FrameOptions& options) const {
    options.settings.lines.ink.taper = line_taper;
    options.settings.lines.ink.width_by_depth = line_width_by_depth;
    if (!line_style.empty())
        options.settings.lines.ink.styles =
            ink::parse_line_styles(read_file(line_style), line_style);
}

FrameOptions RenderArgs::resolve() const {
    FrameOptions o;
    ImageSize s = parse_image_size(size, "--size");
    o.settings.width = s.width;
    o.settings.height = s.height;
    if (!ramp.empty())
        o.settings.shading.ramp = with_flag("--ramp", [&] { return parse_ramp(ramp); });
    o.settings.shading.shadows = shadows;
    o.settings.shading.specular = specular;
    o.settings.shading.rim = rim;
    o.settings.shading.textures = !no_textures;
    o.settings.background = parse_colour(background, "--background");
    o.settings.lines.mode = parse_line_mode(edges, "--edges");
    o.settings.lines.types = with_flag("--lines", [&] { return parse_line_types(lines); });
    o.settings.lines.crease_angle = crease_angle;
    o.settings.lines.robust.depth_step = depth_step;
    o.settings.lines.width = line_width;
    o.settings.lines.colour = parse_colour(line_colour, "--line-color");
    o.settings.sampling.samples = samples;
    o.settings.sampling.adaptive = adaptive == "on";
    o.settings.sampling.tile_size = tile_size;
    o.settings.lines.classic.depth_threshold = depth_threshold;
    o.settings.lines.classic.normal_threshold = normal_threshold;
    o.settings.threads = threads;
    o.bvh.max_leaf_size = leaf_size;
    o.png.level = png_level;
    if (!aov_dir.empty()) o.aov_dir = aov_dir;
    if (!aov_exr.empty()) o.aov_exr = aov_exr;
    resolve_ink_style(o);
    with_flag("--lines", [&] { check_line_settings(o.settings.lines); });
    return o;
}

SceneSetup RenderArgs::scene_setup() const {
    SceneSetup setup;
    const ImageSize s = parse_image_size(size, "--size");
    setup.width = s.width;
    setup.height = s.height;
    if (auto_smooth >= 0.0f) setup.auto_smooth = auto_smooth;
    for (const std::string& l : lights)
        setup.lights.push_back(with_flag("--light", [&] { return parse_light(l); }));
    if (!lights_file.empty()) {
        auto from_file = load_lights(lights_file);
        setup.lights.insert(setup.lights.end(), from_file.begin(), from_file.end());
    }
    if (!camera.empty())
        setup.camera = with_flag("--camera", [&] { return parse_camera_spec(camera); });
    return setup;
}

void SvgArgs::add_to(CLI::App& app, bool per_frame) {
    app.add_option("--svg", svg,
                   per_frame
                       ? "Also write each frame's ink lines as SVG into this directory, named "
                         "like its PNG (NAME_000030.svg), in any --edges mode; resumable like PNGs"
                       : "Also write the ink lines as SVG paths in pixel units, grouped by type "
                         "(silhouette, border, crease, material, intersection), in any --edges "
                         "mode");
    app.add_flag("--hidden-lines,--svg-hidden", hidden,
                 "With --svg: also write the hidden lines, in a layer of their own");
    app.add_flag("--svg-fill", fill,
                 "With --svg: the cel-shaded colours as an embedded PNG under the lines");
}

void SvgArgs::apply(FrameOptions& options, bool per_frame) const {
    if (svg.empty()) {
        if (hidden) throw Error("--hidden-lines needs --svg");
        if (fill) throw Error("--svg-fill needs --svg");
        return;
    }
    if (per_frame) options.svg_dir = svg;
    else options.svg = svg;
    options.svg_hidden = hidden;
    options.svg_fill = fill;
}

void LimitArgs::add_to(CLI::App& app) {
    const Limits d;
    app.add_option("--max-triangles", triangles,
                   fmt::format("Largest scene, in triangles (default {}; k, M, G suffixes)",
                               d.max_triangles))
        ->group("Limits");
    app.add_option(
           "--max-vertices", vertices,
           fmt::format("Most OBJ v, vn and vt statements, each (default {})", d.max_vertices))
        ->group("Limits");
    app.add_option("--max-image-pixels", pixels,
                   fmt::format("Largest image, width x height (default {} = 8192x8192)",
                               d.max_image_pixels))
        ->group("Limits");
    app.add_option(
           "--max-memory", memory,
           "Memory the estimate of a run may reach (frame buffers and scenes of all frames in "
           "flight), e.g. 4G (default: 3/4 of physical memory)")
        ->group("Limits");
    app.add_option("--max-input-size", input_size,
                   fmt::format("Largest input file: OBJ, MTL, score, camera path (default {})",
                               format_bytes(d.max_input_bytes)))
        ->group("Limits");
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
