#include "toonray/render/render_file.h"

#include "toonray/scene/obj_loader.h"

namespace toonray {

AovPaths aov_paths(const std::filesystem::path& dir, const std::filesystem::path& output) {
    std::string stem = output.stem().string();
    auto name = [&](const char* suffix) { return dir / (stem + "_" + suffix + ".png"); };
    return {name("depth"), name("normal"), name("edges_depth"), name("edges_normal"), name("edges"),
            name("cel")};
}

CameraSpec choose_camera(const Scene& scene, const FileRenderOptions& options) {
    if (options.camera) return *options.camera;
    if (scene.camera) return *scene.camera;
    // Frame the vertices that triangles use.
    std::vector<Vec3f> used;
    used.reserve(scene.triangle_count() * 3);
    for (const auto& tri : scene.tri_positions)
        for (std::uint32_t v : tri) used.push_back(scene.positions[v]);
    return auto_camera(used, options.settings.width, options.settings.height);
}

void FileRenderer::render(const std::filesystem::path& input, const std::filesystem::path& output,
                          const FileRenderOptions& options, Warnings& warnings) {
    load_obj(input, scene_, warnings);
    render(scene_, output, options);
}

void FileRenderer::render(const Scene& scene, const std::filesystem::path& output,
                          const FileRenderOptions& options) {
    CameraSpec camera = choose_camera(scene, options);
    // Validate the camera before any work so a bad one fails with nothing written.
    make_view_plane(camera, options.settings.width, options.settings.height);
    accel_.build(scene.positions, scene.tri_positions, options.bvh);
    const ImageRgb8& image = renderer_.render(scene, accel_, camera, options.settings);
    write_frame(renderer_, image, output, options);
}

void write_frame(const Renderer& renderer, const ImageRgb8& image, const std::filesystem::path& output,
                 const FileRenderOptions& options) {
    if (options.aov_dir) {
        std::filesystem::create_directories(*options.aov_dir);
        AovPaths paths = aov_paths(*options.aov_dir, output);
        const Aovs& aovs = renderer.aovs();
        write_png(paths.depth, aovs.depth, options.png);
        write_png(paths.normal, aovs.normal, options.png);
        write_png(paths.edges_depth, aovs.edges_depth, options.png);
        write_png(paths.edges_normal, aovs.edges_normal, options.png);
        write_png(paths.edges, aovs.edges, options.png);
        write_png(paths.cel, aovs.cel, options.png);
    }
    write_png(output, image, options.png);
}

}  // namespace toonray
