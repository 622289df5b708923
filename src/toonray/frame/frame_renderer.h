#pragma once
/// One frame from a scene to its PNG files: build or refit the BVH, load the textures, render,
/// and write the image and its feature images atomically. Between render (which does no file
/// I/O) and the animation drivers; holds its BVH, textures and image buffers so that the frames
/// of an animation reuse them.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "toonray/core/error.h"
#include "toonray/frame/animation_accel.h"
#include "toonray/frame/feature_exr.h"
#include "toonray/frame/textures.h"
#include "toonray/io/png.h"
#include "toonray/io/record.h"
#include "toonray/render/renderer.h"
#include "toonray/scene/camera.h"
#include "toonray/scene/scene.h"
#include "toonray/scene/scene_source.h"

namespace toonray {

struct FrameOptions {
    /// layers is set from aov_dir, aov_exr and svg_fill; strokes and hidden_lines from svg.
    RenderSettings settings;
    std::optional<CameraSpec> camera;              ///< overrides the scene's camera block
    std::optional<std::filesystem::path> aov_dir;  ///< write the feature images here
    /// Also write the feature images as one multi-layer EXR (frame/feature_exr.h): this file
    /// when it ends in ".exr", else `<aov_exr>/<stem>.exr` for each output (exr_path).
    std::optional<std::filesystem::path> aov_exr;
    /// Also write the strokes as SVG here (ink/svg.h), with hidden lines in a layer of their own
    /// when svg_hidden. In modes other than ink the ink lines are found for the SVG only.
    std::optional<std::filesystem::path> svg;
    bool svg_hidden = false;
    /// Animations: one SVG per frame in this directory, named like its PNG (`NAME.svg` for
    /// `NAME.png`); used when svg is not set.
    std::optional<std::filesystem::path> svg_dir;
    /// The SVG also holds the cel-shaded picture (without lines) as an embedded PNG under them.
    bool svg_fill = false;
    /// Outputs kept in memory rather than written (FrameRenderer::render_layers; the Python
    /// module and the Blender engine): every layer of the frame, and the strokes of its SVG
    /// (frame_svg), with hidden lines when svg_hidden.
    bool keep_layers = false;
    bool keep_strokes = false;
    /// The SVG is for a pen plotter (ink/plotter.h): layers per pen, merged and ordered paths.
    bool svg_plotter = false;
    Bvh::Config bvh;
    PngOptions png;
    /// Recorded in every PNG (tEXt chunks "Software" and "toonray settings"), in the EXR's
    /// header (string attributes "software" and "toonraySettings") and in the SVG (metadata).
    OutputRecord record;

    /// The settings a frame is rendered with: feature images exactly when they are written.
    [[nodiscard]] RenderSettings render_settings() const;
    /// The SVG file written with `output`, if any: svg, else svg_dir/<stem>.svg.
    [[nodiscard]] std::optional<std::filesystem::path> svg_path(
        const std::filesystem::path& output) const;
};

/// Whether a frame written to `output` with `options` is complete (for resume): the PNG is
/// valid and, when an SVG is asked for, the SVG exists and ends with its closing tag (it is
/// written atomically, so a complete file is a whole one).
[[nodiscard]] bool frame_complete(const std::filesystem::path& output, const FrameOptions& options);

/// The feature image file for an output and a feature name: `<dir>/<stem>_<name>.png`.
std::filesystem::path aov_path(const std::filesystem::path& dir,
                               const std::filesystem::path& output, std::string_view name);

/// The EXR feature image file of an output: `aov_exr` itself when it names an .exr file, else
/// `<aov_exr>/<stem>.exr`, named like the output's PNG.
std::filesystem::path exr_path(const std::filesystem::path& aov_exr,
                               const std::filesystem::path& output);

/// A sequence writes one EXR a frame: throws Error when `aov_exr` names a single .exr file, or
/// when the build has no OpenEXR (before any frame is rendered).
void check_exr_sequence(const std::filesystem::path& aov_exr);

/// Memory of one frame in flight: the renderer's buffers (frame_buffer_bytes), the PNG encoding
/// of the largest image written (filtered rows, the compressed bound and the file's bytes, and
/// the compressor), with a fifth on top for per-thread scratch and allocator overhead.
/// Saturates at UINT64_MAX.
[[nodiscard]] std::uint64_t frame_bytes(const FrameOptions& options);

/// The PNG options a frame's images are written with: `options.png` with the record's text
/// chunks ("Software", "toonray settings").
[[nodiscard]] PngOptions frame_png_options(const FrameOptions& options);

/// The SVG document of a rendered frame's strokes, exactly as FrameRenderer::render writes it.
/// The frame must have kept its strokes (options.svg, svg_dir or keep_strokes).
[[nodiscard]] std::string frame_svg(const FrameLayers& layers, const FrameOptions& options);

class FrameRenderer {
public:
    /// Renders a scene source's frame (scene/scene_source.h) to `output` (and, with
    /// options.aov_dir, its feature images, created if missing; with options.svg, the ink
    /// strokes). Throws Error for a bad camera (before anything is written) or a failed write;
    /// texture problems are appended to `warnings`.
    void render(const SceneFrame& frame, const std::filesystem::path& output,
                const FrameOptions& options, Warnings& warnings);

    /// Renders a frame into memory and writes nothing: the BVH (refitted when the triangles
    /// are those of the last frame), the textures, and the picture with the layers and strokes
    /// `options` asks for (render_settings()). The result is valid until the next call. Throws
    /// Error for a bad camera; with `progress`, RenderCancelled when it is cancelled
    /// (Renderer::render).
    const FrameLayers& render_layers(const Scene& scene, const CameraSpec& camera,
                                     std::span<const Light> lights, const FrameOptions& options,
                                     Warnings& warnings, RenderProgress* progress = nullptr);

    [[nodiscard]] const Renderer& renderer() const { return renderer_; }
    [[nodiscard]] const AnimationAccel& accel() const { return accel_; }
    /// The scene the last frame drew, whose triangles its strokes' segments name: the one
    /// given, or under a tone look or with band or shadow lines its instances flattened (those
    /// are found on a scene's own triangles). Null before the first frame.
    [[nodiscard]] const Scene* drawn_scene() const { return drawn_; }

private:
    Scene flattened_;  ///< the last frame's scene with its instances flattened, when drawn so
    const Scene* drawn_ = nullptr;
    AnimationAccel accel_;
    TextureCache textures_;
    ink::BrushSet brushes_;  ///< the line styles' brushes, read once
    Renderer renderer_;
    FeatureLayers exr_layers_;
};

}  // namespace toonray
