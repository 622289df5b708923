#pragma once
/// A glTF document posed at a time: its animations (translation, rotation, scale and morph
/// weight channels; LINEAR with slerp for rotations, STEP, CUBICSPLINE) applied to the node
/// hierarchy, skins (linear blend skinning) and morph targets evaluated, and the result as a
/// Scene, a camera and toon lights. docs/gltf.md has the rules.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/scene/light.h"
#include "toonray/scene/gltf_loader.h"
#include "toonray/scene/scene.h"
#include "toonray/scene/scene_source.h"

namespace toonray {

struct GltfPoseOptions {
    /// The animation played, by name or index; nullopt plays all of them at once (as Blender
    /// exports one animation per object).
    std::optional<std::string> animation;
    /// The camera: the node of this name; nullopt takes the scene's first camera node in
    /// depth-first order.
    std::optional<std::string> camera_node;
};

/// The time of frame `frame` at `fps` frames per second: frame / fps seconds (frame 0 at 0 s,
/// as Blender's glTF exporter writes frame f of a scene starting at frame 0).
[[nodiscard]] double gltf_frame_time(int frame, double fps);

class GltfAnimator {
public:
    /// Throws Error naming the file when the animation or camera node asked for does not exist.
    GltfAnimator(GltfDocument document, const GltfPoseOptions& options);

    /// The scene at `seconds` (clamped to each sampler's keys), its camera for a
    /// `width` x `height` image (scene.camera; unset when the file has no camera), and the
    /// file's lights, in toon units, in `lights` (empty when the file has none).
    void pose(double seconds, int width, int height, Scene& scene,
              std::vector<Light>& lights) const;

    /// A warning when the camera's aspect ratio differs from the image's, else nothing.
    [[nodiscard]] std::optional<std::string> aspect_warning(int width, int height) const;

    [[nodiscard]] const GltfDocument& document() const { return doc_; }
    /// Whether the scene has the camera posing gives (else frames need one of their own).
    [[nodiscard]] bool has_camera() const { return camera_node_ >= 0; }
    /// The last key time of the animations played, seconds (0 without animations).
    [[nodiscard]] double duration() const;

private:
    GltfDocument doc_;
    std::vector<int> animations_;  ///< played
    int camera_node_ = -1;
    /// Per glTF mesh, its triangles in object space when it is instanced
    /// (GltfDocument::instanced_meshes), else null: every pose shares these objects, so a
    /// renderer keeps its work on them from frame to frame.
    std::vector<std::shared_ptr<const TriangleMesh>> meshes_;
};

/// The frames of a glTF animation: frame N is the document posed at gltf_frame_time(N, fps),
/// lit by its own lights unless the setup gives lights.
class GltfSource : public SceneSource {
public:
    GltfSource(GltfDocument document, const GltfPoseOptions& options, double fps, SceneSetup setup);

    void load(int frame, SceneFrame& out, Warnings& warnings) const override;
    /// The scene at `seconds`, finished (finish_scene).
    void load_at(double seconds, SceneFrame& out) const;
    /// Without a camera in the file or the setup, every frame gets the automatic camera that
    /// frames the scene at `seconds`, so that an animation moves in a still frame.
    void hold_automatic_camera(double seconds);

    [[nodiscard]] const GltfAnimator& animator() const { return animator_; }
    [[nodiscard]] double fps() const { return fps_; }

private:
    GltfAnimator animator_;
    double fps_;
    SceneSetup setup_;
};

}  // namespace toonray
