#pragma once
// The Python module `toonray` (docs/python.md): a thin layer that converts Python and numpy
// values to the library's types and calls it. What it shares between its files.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "toonray/frame/settings.h"
#include "toonray/scene/camera.h"
#include "toonray/scene/gltf_animation.h"
#include "toonray/scene/light.h"
#include "toonray/scene/scene.h"

namespace toonray::python {

namespace py = pybind11;

// ---- Settings (settings.cpp) -----------------------------------------------------------------

/// The settings document from Python: None (the defaults), a path to a TOML document (str or
/// os.PathLike), or a dict of keys ("lines.width") or nested dicts ({"lines": {"width": 2}}),
/// whose "lines.rule" is a list of dicts (the [[lines.rule]] tables). Throws Error with the
/// library's message for a bad key or value.
Settings settings_from(const py::object& document);

void bind_settings(py::module_& m);

// ---- Scenes (scene.cpp) ----------------------------------------------------------------------

/// A camera as the module takes it: the seed's camera block (eye, gaze, up, shift), a lens
/// camera (LensCamera), or a glTF file's camera, posed again for each image size (its
/// horizontal field of view follows the image, as the command line's).
struct PyCamera {
    struct Gltf {
        std::shared_ptr<const GltfAnimator> animator;
        double seconds = 0.0;
    };
    std::variant<CameraSpec, LensCamera, Gltf> camera;
    /// The last glTF camera posed, and for which size.
    mutable std::optional<CameraSpec> posed{};
    mutable int posed_width = 0, posed_height = 0;

    /// The camera for an image of this size. Throws Error.
    [[nodiscard]] CameraSpec spec(int width, int height) const;
};

/// A mesh added to a scene, to be placed by instances (docs/python.md, "Instances").
struct MeshData {
    std::string name;
    std::vector<Vec3f> positions;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    std::vector<Vec3f> normals;
    std::vector<Vec2f> uvs;
    std::vector<std::uint32_t> materials;
    const void* scene = nullptr;  ///< the PyScene it belongs to (its material ids are that scene's)
    /// Its index in the scene's meshes (Scene::meshes) once an instance placed it.
    std::uint32_t scene_mesh = kNoIndex;
};

/// The module's Scene: the library's scene with its own camera and lights.
struct PyScene {
    Scene scene;
    std::vector<Light> lights;          ///< the scene's own lights
    std::optional<PyCamera> camera;     ///< replaces scene.camera (the OBJ block) when set
    std::atomic<int> rendering{0};      ///< renders in flight: the scene must not change meanwhile
    std::vector<std::string> warnings;  ///< of loading

    PyScene() = default;
    PyScene(const PyScene&) = delete;
    PyScene& operator=(const PyScene&) = delete;

    /// Throws a Python RuntimeError while a render reads the scene.
    void check_not_rendering() const;
    /// The camera for an image of this size: the settings' (scene.camera key), else the scene's
    /// own, else the automatic camera (choose_camera).
    [[nodiscard]] CameraSpec frame_camera(const SceneSetup& setup) const;
};

void bind_scene(py::module_& m);

// ---- Rendering (render.cpp) ------------------------------------------------------------------

void bind_render(py::module_& m);

// ---- Errors (module.cpp) ---------------------------------------------------------------------

/// The settings key that raises a limit ("limits.triangles"), or empty.
[[nodiscard]] std::string_view limit_setting(Limit limit);

}  // namespace toonray::python
