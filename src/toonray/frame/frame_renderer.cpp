#include "toonray/frame/frame_renderer.h"

#include "toonray/core/saturating.h"

#include <variant>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/ink/svg.h"
#include "toonray/io/file.h"

namespace toonray {
RenderSettings FrameOptions::render_settings() const {
    RenderSettings s = settings;
    s.feature_images = aov_dir.has_value();
    s.hidden_lines = svg.has_value() && svg_hidden;
    return s;
}

namespace {

// The strokes of the last ink frame as SVG, written atomically.
void write_svg(const Renderer& renderer, const RenderSettings& settings,
               const FrameOptions& options) {
    ink::SvgSettings svg;
    svg.width = settings.width;
    svg.height = settings.height;
    svg.thickness = ink::stroke_thickness(settings.lines.width, settings.height);
    svg.colour = settings.lines.colour;
    svg.hidden = options.svg_hidden;
    const std::string text = ink::svg_text(renderer.ink_lines().strokes, svg);
    write_file_atomic(*options.svg,
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
    return auto_camera(used, options.settings.width, options.settings.height);
}

std::filesystem::path aov_path(const std::filesystem::path& dir,
                               const std::filesystem::path& output, std::string_view name) {
    return dir / (output.stem().string() + "_" + std::string(name) + ".png");
}

std::uint64_t frame_bytes(const FrameOptions& options) {
    const RenderSettings settings = options.render_settings();
    const std::uint64_t pixels = static_cast<std::uint64_t>(std::max(settings.width, 0)) *
                                 static_cast<std::uint64_t>(std::max(settings.height, 0));
    // Every written image is RGB or smaller; its encoding holds the filtered rows, the
    // compressed bound and the file's bytes, about three copies, and a compressor of under 1 MiB.
    const std::uint64_t png =
        pixels > UINT64_MAX / 16 ? UINT64_MAX : pixels * 3 * sizeof(Rgb8) + 1024 * 1024;
    const std::uint64_t total = add_saturated(frame_buffer_bytes(settings), png);
    return add_saturated(total, total / 5);
}

void FrameRenderer::render(const Scene& scene, const CameraSpec& camera,
                           const std::filesystem::path& output, const FrameOptions& options,
                           Warnings& warnings) {
    const RenderSettings settings = options.render_settings();
    // Validate the camera before any work so a bad one fails with nothing written.
    validate_camera(camera);
    if (options.svg && settings.edges != EdgeMode::Ink)
        throw Error("an SVG drawing needs the ink line mode");
    const TriangleAccel& accel = accel_.update(scene, options.bvh);
    const TextureSet* textures =
        settings.shading.textures ? &textures_.load(scene, warnings) : nullptr;
    const ImageRgb8& image = renderer_.render(scene, accel, camera, settings, textures);
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
    if (options.svg) write_svg(renderer_, settings, options);
    write_png(output, image, options.png);
}

}  // namespace toonray
