#include "toonray/render/render_file.h"

#include "toonray/scene/obj_loader.h"

namespace toonray {

std::filesystem::path aov_path(const std::filesystem::path& dir, const std::filesystem::path& output,
                               const std::string& name) {
    return dir / (output.stem().string() + "_" + name + ".png");
}

std::vector<std::string> aov_names(EdgeMode mode) {
    if (mode == EdgeMode::Classic) return {"depth", "normal", "edges_depth", "edges_normal", "edges", "cel"};
    return {"depth",        "normal",       "edges",          "cel",       "lines_silhouette", "lines_crease",
            "lines_depth",  "lines_object", "lines_material", "object_id", "material_id"};
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
    render(scene_, output, options, warnings);
}

void FileRenderer::render(const Scene& scene, const std::filesystem::path& output,
                          const FileRenderOptions& options, Warnings& warnings) {
    CameraSpec camera = choose_camera(scene, options);
    // Validate the camera before any work so a bad one fails with nothing written.
    make_view_plane(camera, options.settings.width, options.settings.height);
    prepare_accel(scene, options.bvh);
    if (options.settings.shading.textures) textures_.load(scene, warnings);
    const ImageRgb8& image = renderer_.render(scene, accel_, camera, options.settings,
                                              options.settings.shading.textures ? &textures_ : nullptr);
    write_frame(renderer_, image, output, options);
}

void FileRenderer::prepare_accel(const Scene& scene, const Bvh::Config& config) {
    const bool same_triangles = accel_valid_ && config == accel_config_ && scene.tri_positions == accel_tris_;
    if (same_triangles && refits_in_a_row_ < kMaxRefitsInARow) {
        accel_.refit(scene.positions, scene.tri_positions);
        ++refits_in_a_row_;
        return;
    }
    accel_valid_ = false;  // stays false if the build throws
    accel_.build(scene.positions, scene.tri_positions, config);
    accel_tris_ = scene.tri_positions;
    accel_config_ = config;
    refits_in_a_row_ = 0;
    accel_valid_ = true;
}

void write_frame(const Renderer& renderer, const ImageRgb8& image, const std::filesystem::path& output,
                 const FileRenderOptions& options) {
    if (options.aov_dir) {
        std::filesystem::create_directories(*options.aov_dir);
        const Aovs& a = renderer.aovs();
        for (const std::string& name : aov_names(options.settings.edges)) {
            std::filesystem::path path = aov_path(*options.aov_dir, output, name);
            if (name == "depth") write_png(path, a.depth, options.png);
            else if (name == "normal") write_png(path, a.normal, options.png);
            else if (name == "edges_depth") write_png(path, a.edges_depth, options.png);
            else if (name == "edges_normal") write_png(path, a.edges_normal, options.png);
            else if (name == "edges") write_png(path, a.edges, options.png);
            else if (name == "cel") write_png(path, a.cel, options.png);
            else if (name == "lines_silhouette") write_png(path, a.lines_silhouette, options.png);
            else if (name == "lines_crease") write_png(path, a.lines_crease, options.png);
            else if (name == "lines_depth") write_png(path, a.lines_depth, options.png);
            else if (name == "lines_object") write_png(path, a.lines_object, options.png);
            else if (name == "lines_material") write_png(path, a.lines_material, options.png);
            else if (name == "object_id") write_png(path, a.object_id, options.png);
            else if (name == "material_id") write_png(path, a.material_id, options.png);
        }
    }
    write_png(output, image, options.png);
}

}  // namespace toonray
