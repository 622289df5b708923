#pragma once
/// Where a frame's scene comes from (an OBJ file, a numbered OBJ sequence, a posed glTF
/// animation, the piano) and the steps every one of them shares once the scene is loaded or
/// posed: auto-smooth, the camera and the lights (docs/rendering.md, "Scenes").

#include <filesystem>
#include <optional>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/scene/camera.h"
#include "toonray/scene/light.h"
#include "toonray/scene/obj_loader.h"
#include "toonray/scene/scene.h"

namespace toonray {

/// How a scene is finished after it is loaded or posed, from the settings.
struct SceneSetup {
    /// Auto-smooth angle in degrees for triangles without normals (scene/auto_smooth.h);
    /// unset: off.
    std::optional<float> auto_smooth;
    /// Lights that replace the scene's own (its lights file, its glTF lights); empty: the
    /// scene's own, else the default light.
    std::vector<Light> lights;
    /// A camera that replaces the scene's own (the OBJ camera block, the glTF camera, the
    /// piano's camera path); unset: the scene's own, else an automatic camera.
    std::optional<CameraSpec> camera;
    /// The image the automatic camera frames.
    int width = 1280, height = 720;
};

/// One frame's scene as it is rendered: the scene, the camera that sees it and its lights.
struct SceneFrame {
    Scene scene;
    CameraSpec camera;
    std::vector<Light> lights;  ///< never empty once finished
};

/// The camera a scene is seen by: setup.camera, else the scene's own (scene.camera), else an
/// automatic camera framing the vertices that triangles and polylines use (auto_camera).
[[nodiscard]] CameraSpec choose_camera(const Scene& scene, const SceneSetup& setup);

/// The lights a frame is lit by: setup.lights when given, else `own_lights` (the scene's lights
/// file or glTF lights) when there are any, else the default light (default_light) for
/// `camera`.
[[nodiscard]] std::vector<Light> choose_lights(const Scene& scene, const CameraSpec& camera,
                                               std::vector<Light> own_lights,
                                               const SceneSetup& setup);

/// The steps after loading or posing, in this order: auto-smooth; the camera (choose_camera);
/// the lights (choose_lights).
void finish_scene(SceneFrame& frame, std::vector<Light> own_lights, const SceneSetup& setup);

/// Frames of a scene, loaded or posed by number.
class SceneSource {
public:
    virtual ~SceneSource() = default;
    /// Loads or poses frame `frame` into `out` (whose buffers it may reuse) and finishes it
    /// (finish_scene). Safe to call from several threads at once, each with its own `out`.
    /// Throws Error.
    virtual void load(int frame, SceneFrame& out, Warnings& warnings) const = 0;
    /// Whether loading reads files, so that it is worth overlapping with rendering.
    [[nodiscard]] virtual bool reads_files() const { return false; }
};

/// One OBJ file (with its MTL files and its lights file, scene_file_lights), the same for every
/// frame number.
class ObjFileSource : public SceneSource {
public:
    ObjFileSource(std::filesystem::path path, SceneSetup setup, ObjOptions obj = {});
    void load(int frame, SceneFrame& out, Warnings& warnings) const override;
    [[nodiscard]] bool reads_files() const override { return true; }

    /// Loads `path` into `out` and finishes it: the step every OBJ source shares.
    static void load_file(const std::filesystem::path& path, const SceneSetup& setup,
                          const ObjOptions& obj, SceneFrame& out, Warnings& warnings);

private:
    std::filesystem::path path_;
    SceneSetup setup_;
    ObjOptions obj_;
};

}  // namespace toonray
