#pragma once
/// One frame from an OBJ file to PNG files: load, build the BVH, render, write atomically.
/// Holds its scene, BVH and image buffers so that rendering many frames reuses memory.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "toonray/accel/triangle_accel.h"
#include "toonray/core/error.h"
#include "toonray/io/png.h"
#include "toonray/render/renderer.h"
#include "toonray/scene/scene.h"

namespace toonray {

struct FileRenderOptions {
    RenderSettings settings;
    std::optional<CameraSpec> camera;  ///< overrides the file's camera block
    std::optional<std::filesystem::path> aov_dir;  ///< write feature images here
    Bvh::Config bvh;
    PngOptions png;
};

/// The AOV file for an output and a feature name: `<dir>/<stem>_<name>.png`.
std::filesystem::path aov_path(const std::filesystem::path& dir, const std::filesystem::path& output,
                               const std::string& name);

/// Feature images written for a line mode. Classic: depth, normal, edges_depth, edges_normal,
/// edges (merged, before blur), cel. Robust: depth, normal, edges (line coverage), cel,
/// lines_silhouette, lines_crease, lines_depth, lines_object, lines_material, object_id,
/// material_id.
std::vector<std::string> aov_names(EdgeMode mode);

/// Writes a rendered frame (and, with options.aov_dir, its feature images) atomically.
void write_frame(const Renderer& renderer, const ImageRgb8& image, const std::filesystem::path& output,
                 const FileRenderOptions& options);

class FileRenderer {
public:
    /// Renders `input` to `output` (and AOVs). Throws Error on bad input or a failed write;
    /// no output is written for a scene that fails to load. Warnings are appended to `warnings`.
    void render(const std::filesystem::path& input, const std::filesystem::path& output,
                const FileRenderOptions& options, Warnings& warnings);

    /// Renders an already loaded scene (the camera comes from options or the scene).
    void render(const Scene& scene, const std::filesystem::path& output, const FileRenderOptions& options,
                Warnings& warnings);

    [[nodiscard]] const Renderer& renderer() const { return renderer_; }
    [[nodiscard]] const Scene& scene() const { return scene_; }

    /// An animation's frames usually keep their triangles while vertices move. When a scene has
    /// exactly the triangles of the one before (and the same BVH settings), the BVH is refitted
    /// instead of rebuilt, at most this many frames in a row: refitting costs a tenth of a build,
    /// but the tree loosens as vertices travel, so it is rebuilt now and then. Images do not
    /// depend on it: among hits at the same distance the lowest triangle index wins, whatever
    /// the tree.
    static constexpr int kMaxRefitsInARow = 15;

private:
    /// Builds or refits accel_ for `scene` (see kMaxRefitsInARow).
    void prepare_accel(const Scene& scene, const Bvh::Config& config);

    Scene scene_;
    TriangleAccel accel_;
    std::vector<std::array<std::uint32_t, 3>> accel_tris_;  ///< the triangles accel_ was built for
    Bvh::Config accel_config_;
    int refits_in_a_row_ = 0;
    bool accel_valid_ = false;
    Renderer renderer_;
    TextureSet textures_;
};

/// The camera a frame uses: the override, else the file's camera block, else an automatic one.
CameraSpec choose_camera(const Scene& scene, const FileRenderOptions& options);

}  // namespace toonray
