#include "toonray/frame/frame_renderer.h"

#include "toonray/core/saturating.h"

#include <fmt/format.h>
#include <variant>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/ink/polylines.h"
#include "toonray/ink/svg.h"
#include "toonray/io/exr.h"
#include "toonray/io/file.h"

namespace toonray {
RenderSettings FrameOptions::render_settings() const {
    RenderSettings s = settings;
    s.feature_images = aov_dir.has_value() || aov_exr.has_value();
    s.hidden_lines = (svg.has_value() || svg_dir.has_value()) && svg_hidden;
    s.feature_images = s.feature_images || ((svg.has_value() || svg_dir.has_value()) && svg_fill);
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

namespace {

// The strokes of the frame's ink lines as SVG, written atomically.
void write_svg(const Renderer& renderer, const ink::InkLines& lines, const RenderSettings& settings,
               const FrameOptions& options, const std::filesystem::path& path) {
    ink::SvgSettings svg;
    svg.width = settings.width;
    svg.height = settings.height;
    svg.thickness = ink::stroke_thickness(settings.lines.width, settings.height);
    svg.colour = settings.lines.colour;
    svg.hidden = options.svg_hidden;
    svg.pens = lines.pens;
    if (options.svg_fill) {
        const ImageRgb8& cel = renderer.aovs().cel;
        svg.fill_href = ink::png_data_uri(
            encode_png(cel.width(), cel.height(), 3,
                       reinterpret_cast<const std::uint8_t*>(cel.data()), options.png));
    }
    const std::string text = ink::svg_text(lines.strokes, svg);
    write_file_atomic(path,
                      std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

}  // namespace

CameraSpec choose_camera(const Scene& scene, const FrameOptions& options) {
    if (options.camera) return *options.camera;
    if (scene.camera) return *scene.camera;
    // Frame the vertices that triangles use.
    std::vector<Vec3f> used;
    used.reserve(scene.triangle_count() * 3);
    for (const auto& tri : scene.tri_positions)
        for (std::uint32_t v : tri) used.push_back(scene.positions[v]);
    for (std::uint32_t v : scene.polyline_points) used.push_back(scene.positions[v]);
    return auto_camera(used, options.settings.width, options.settings.height);
}

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
    if (options.aov_exr) total = add_saturated(total, feature_exr_bytes(pixels));
    if (options.svg || options.svg_dir) {
        // The ink line layer of an SVG asked of another mode (coverage and style), and the
        // embedded fill: its PNG and the base64 text, within twice the RGB pixels.
        const std::uint64_t per_pixel =
            (settings.edges != EdgeMode::Ink ? sizeof(float) + sizeof(std::uint16_t) : 0) +
            (options.svg_fill ? 2 * sizeof(Rgb8) : 0);
        total = add_saturated(total, pixels > UINT64_MAX / 16 ? UINT64_MAX : pixels * per_pixel);
    }
    return add_saturated(total, total / 5);
}

void FrameRenderer::render(const Scene& scene, const CameraSpec& camera,
                           const std::filesystem::path& output, const FrameOptions& options,
                           Warnings& warnings) {
    const RenderSettings settings = options.render_settings();
    // Validate the camera before any work so a bad one fails with nothing written.
    validate_camera(camera);
    if (options.aov_exr && !exr_available())
        throw Error("EXR feature images are not available: this toonray was built without OpenEXR");
    const TriangleAccel& accel = accel_.update(scene, options.bvh);
    const TextureSet* textures =
        settings.shading.textures ? &textures_.load(scene, warnings) : nullptr;
    const ImageRgb8* image = &renderer_.render(scene, accel, camera, settings, textures);
    if (!scene.polylines.empty() && settings.edges != EdgeMode::Ink) {
        // The ink mode draws polylines with its lines; the others get them over the frame.
        with_polylines_ = *image;
        ink::draw_polylines_over(scene, accel, camera, ink_settings(settings),
                                 settings.lines.colour, settings.threads, with_polylines_,
                                 polyline_coverage_);
        image = &with_polylines_;
    }
    if (options.aov_dir) {
        std::filesystem::create_directories(*options.aov_dir);
        const Aovs& aovs = renderer_.aovs();
        for (const FeatureImage& feature : feature_images()) {
            if (!feature.in(settings.edges)) continue;
            const std::filesystem::path path = aov_path(*options.aov_dir, output, feature.name);
            std::visit([&](auto member) { write_png(path, aovs.*member, options.png); },
                       feature.image);
        }
    }
    if (options.aov_exr) {
        // Before the frame's PNG, as the PNG feature images: a frame whose PNG is valid has its
        // EXR too, so resuming a sequence skips it safely.
        const std::filesystem::path path = exr_path(*options.aov_exr, output);
        if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
        const bool drawn_over = !scene.polylines.empty() && settings.edges != EdgeMode::Ink;
        gather_feature_layers(scene, accel, camera, settings, renderer_, layers_,
                              drawn_over ? &polyline_coverage_ : nullptr);
        write_feature_exr(path, layers_);
    }
    if (const auto svg_path = options.svg_path(output)) {
        if (options.svg_dir && !options.svg) std::filesystem::create_directories(*options.svg_dir);
        const bool ink = settings.edges == EdgeMode::Ink;
        if (!ink)  // the lines for the SVG only
            ink::draw_ink_lines(scene, accel, camera, settings.width, settings.height,
                                ink_settings(settings), settings.threads, svg_lines_);
        write_svg(renderer_, ink ? renderer_.ink_lines() : svg_lines_, settings, options,
                  *svg_path);
    }
    write_png(output, *image, options.png);
}

}  // namespace toonray
