#include "toonray/frame/frame_renderer.h"

#include "toonray/core/saturating.h"

#include <fmt/format.h>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/core/parallel.h"
#include "toonray/frame/feature_images.h"
#include "toonray/ink/svg.h"
#include "toonray/io/exr.h"
#include "toonray/io/file.h"

namespace toonray {
RenderSettings FrameOptions::render_settings() const {
    RenderSettings s = settings;
    const bool svg_asked = svg.has_value() || svg_dir.has_value() || keep_strokes;
    // The SVG's fill is the cel layer.
    s.layers = aov_dir.has_value() || aov_exr.has_value() || (svg_asked && svg_fill) || keep_layers;
    s.strokes = svg_asked;
    s.hidden_lines = svg_asked && svg_hidden;
    return s;
}

std::optional<std::filesystem::path> FrameOptions::svg_path(
    const std::filesystem::path& output) const {
    if (svg) return svg;
    if (svg_dir) return *svg_dir / (output.stem().string() + ".svg");
    return std::nullopt;
}

bool frame_complete(const std::filesystem::path& output, const FrameOptions& options) {
    if (!is_valid_png(output)) return false;
    const auto svg = options.svg_path(output);
    if (!svg) return true;
    std::error_code ec;
    if (!std::filesystem::is_regular_file(*svg, ec)) return false;
    try {
        const std::string text = read_file(*svg);
        static constexpr std::string_view kEnd = "</svg>\n";
        return text.size() >= kEnd.size() &&
               text.compare(text.size() - kEnd.size(), kEnd.size(), kEnd) == 0;
    } catch (const Error&) {
        return false;
    }
}

PngOptions frame_png_options(const FrameOptions& options) {
    PngOptions png = options.png;
    if (!options.record.software.empty())
        png.text.emplace_back("Software", options.record.software);
    if (!options.record.settings.empty())
        png.text.emplace_back("toonray settings", options.record.settings);
    return png;
}

std::string frame_svg(const FrameLayers& layers, const FrameOptions& options) {
    if (!layers.strokes) throw Error("the frame kept no strokes for an SVG");
    const RenderSettings settings = options.render_settings();
    const ink::InkLines& lines = *layers.strokes;
    ink::SvgSettings svg;
    svg.width = settings.width;
    svg.height = settings.height;
    svg.thickness = ink::stroke_thickness(settings.lines.width, settings.height);
    svg.colour = settings.lines.colour;
    svg.hidden = options.svg_hidden;
    svg.pens = lines.pens;
    svg.plotter = options.svg_plotter;
    svg.software = options.record.software;
    svg.metadata = options.record.settings;
    if (options.svg_fill && !options.svg_plotter) {
        const ImageRgb8& cel = layers.cel;
        svg.fill_href = ink::png_data_uri(
            encode_png(cel.width(), cel.height(), 3,
                       reinterpret_cast<const std::uint8_t*>(cel.data()), options.png));
    }
    return ink::svg_text(lines.strokes, svg);
}

namespace {

// Reads the brushes the rules name that are not read yet into `brushes`; whether any rule
// names one.
bool read_brushes(const ink::LineStyleSet& styles, ink::BrushSet& brushes) {
    bool any = false;
    for (const ink::LineStyleRule& rule : styles.rules) {
        if (!rule.sets_field(&ink::LineStyle::brush) || rule.values.brush.empty()) continue;
        any = true;
        if (brushes.contains(rule.values.brush)) continue;
        try {
            const DecodedPng png = read_png(rule.values.brush);
            brushes.emplace(rule.values.brush,
                            std::make_shared<const ink::Brush>(ink::make_brush(png.rgb)));
        } catch (const Error& e) {
            throw Error(fmt::format("line style brush '{}': {}", rule.values.brush, e.what()));
        }
    }
    return any;
}

}  // namespace

std::filesystem::path aov_path(const std::filesystem::path& dir,
                               const std::filesystem::path& output, std::string_view name) {
    return dir / (output.stem().string() + "_" + std::string(name) + ".png");
}

std::filesystem::path exr_path(const std::filesystem::path& aov_exr,
                               const std::filesystem::path& output) {
    if (aov_exr.extension() == ".exr" || aov_exr.extension() == ".EXR") return aov_exr;
    return aov_exr / (output.stem().string() + ".exr");
}

void check_exr_sequence(const std::filesystem::path& aov_exr) {
    if (!exr_available())
        throw Error("EXR feature images are not available: this toonray was built without OpenEXR");
    if (exr_path(aov_exr, "frame.png") == aov_exr)
        throw Error(
            fmt::format("{}: EXR feature images of a sequence go to a directory (one file "
                        "a frame), not one .exr file",
                        aov_exr.string()));
}

std::uint64_t frame_bytes(const FrameOptions& options) {
    const RenderSettings settings = options.render_settings();
    const std::uint64_t pixels = static_cast<std::uint64_t>(std::max(settings.width, 0)) *
                                 static_cast<std::uint64_t>(std::max(settings.height, 0));
    // Every written image is RGB or smaller; its encoding holds the filtered rows, the
    // compressed bound and the file's bytes, about three copies, and a compressor of under 1 MiB.
    const std::uint64_t png =
        pixels > UINT64_MAX / 16 ? UINT64_MAX : pixels * 3 * sizeof(Rgb8) + 1024 * 1024;
    std::uint64_t total = add_saturated(frame_buffer_bytes(settings), png);
    if (options.aov_dir)  // one feature image at a time, encoded
        total = add_saturated(total, mul_saturated(pixels, feature_image_bytes_per_pixel()));
    if (options.aov_exr) total = add_saturated(total, feature_exr_bytes(pixels));
    if (options.svg || options.svg_dir || options.keep_strokes) {
        // The ink line layer of an SVG asked of another mode (coverage and style), and the
        // embedded fill: its PNG and the base64 text, within twice the RGB pixels.
        const std::uint64_t per_pixel =
            (settings.lines.mode != LineMode::Ink ? sizeof(float) + sizeof(std::uint16_t) : 0) +
            (options.svg_fill ? 2 * sizeof(Rgb8) : 0);
        total = add_saturated(total, pixels > UINT64_MAX / 16 ? UINT64_MAX : pixels * per_pixel);
    }
    return add_saturated(total, total / 5);
}

const FrameLayers& FrameRenderer::render_layers(const Scene& scene, const CameraSpec& camera,
                                                std::span<const Light> lights,
                                                const FrameOptions& options, Warnings& warnings,
                                                RenderProgress* progress) {
    const RenderSettings settings = options.render_settings();
    // Validate the camera before any work so a bad one fails with nothing done.
    validate_camera(camera);
    // Tone strokes and dots, band and shadow lines are found on the scene's own triangles, so
    // under a tone look or with those lines the instances are drawn flattened (each copy its
    // own triangles, as a flat scene would be).
    drawn_ = &scene;
    if (!scene.instances.empty() && settings.lines.mode == LineMode::Ink &&
        (settings.tone.mode != ink::ToneMode::Cel ||
         (settings.lines.types & (kLineBand | kLineShadow)) != 0)) {
        flattened_ = flatten_instances(scene);
        drawn_ = &flattened_;
    }
    const Scene& drawn = *drawn_;
    // The acceleration structure's build and the textures' decoding keep to the frame's
    // threads too (they take no thread count of their own).
    const TriangleAccel* built = nullptr;
    const TextureSet* textures = nullptr;
    with_threads(settings.threads, [&] {
        built = &accel_.update(drawn, options.bvh);
        if (settings.shading.textures) textures = &textures_.load(drawn, warnings);
    });
    const TriangleAccel& accel = *built;
    RenderSettings with_brushes = settings;
    if (read_brushes(settings.lines.ink.styles, brushes_)) with_brushes.brushes = &brushes_;
    renderer_.render(drawn, accel, camera, lights, with_brushes, textures, progress);
    return renderer_.layers();
}

void FrameRenderer::render(const SceneFrame& frame, const std::filesystem::path& output,
                           const FrameOptions& options, Warnings& warnings) {
    const RenderSettings settings = options.render_settings();
    // Checked before any work so that a frame that cannot be written fails with nothing written.
    validate_camera(frame.camera);
    if (options.aov_exr && !exr_available())
        throw Error("EXR feature images are not available: this toonray was built without OpenEXR");
    const FrameLayers& layers =
        render_layers(frame.scene, frame.camera, frame.lights, options, warnings);
    const PngOptions png = frame_png_options(options);
    if (options.aov_dir) {
        std::filesystem::create_directories(*options.aov_dir);
        FeatureBytes bytes;
        for (const FeatureImage& feature : feature_images()) {
            if (!feature.in(settings.lines.mode)) continue;
            feature.encode(layers, settings.threads, bytes);
            const std::filesystem::path path = aov_path(*options.aov_dir, output, feature.name);
            if (bytes.channels == 1) write_png(path, bytes.gray, png);
            else write_png(path, bytes.rgb, png);
        }
    }
    if (options.aov_exr) {
        // Before the frame's PNG, as the PNG feature images: a frame whose PNG is valid has its
        // EXR too, so resuming a sequence skips it safely.
        const std::filesystem::path path = exr_path(*options.aov_exr, output);
        if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
        gather_feature_layers(layers, exr_layers_);
        write_feature_exr(path, exr_layers_, options.record);
    }
    if (const auto svg_path = options.svg_path(output)) {
        if (options.svg_dir && !options.svg) std::filesystem::create_directories(*options.svg_dir);
        const std::string text = frame_svg(layers, options);
        write_file_atomic(
            *svg_path, std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
    }
    write_png(output, layers.image, png);
}

}  // namespace toonray
