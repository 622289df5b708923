#pragma once
/// Scenes the test suites share: the OBJ files of tests/data, and a camera that frames a scene.

#include <string>
#include <vector>

#include "toonray/scene/camera.h"
#include "toonray/scene/light.h"
#include "toonray/scene/obj_loader.h"
#include "toonray/scene/scene_source.h"

namespace toonray::test_support {

/// tests/data/<name>, loaded as the renderer reads it.
inline Scene load_test_scene(const std::string& name) {
    Scene scene;
    Warnings warnings;
    load_obj(std::string(TOONRAY_TEST_DATA_DIR) + "/" + name, scene, warnings);
    return scene;
}

/// The automatic camera for the vertices the scene's triangles use, at width x height.
inline CameraSpec framing_camera(const Scene& scene, int width, int height) {
    std::vector<Vec3f> used;
    for (const auto& tri : scene.tri_positions)
        for (std::uint32_t v : tri) used.push_back(scene.positions[v]);
    return auto_camera(used, width, height);
}

/// The default light of a scene seen by a camera, as a scene source gives it.
inline std::vector<Light> default_lights(const Scene& scene, const CameraSpec& camera) {
    return {default_light(scene, camera)};
}

/// A scene finished as a scene source finishes it with `setup` (the camera, the lights).
inline SceneFrame scene_frame(Scene scene, const SceneSetup& setup = {}) {
    SceneFrame frame;
    frame.scene = std::move(scene);
    finish_scene(frame, {}, setup);
    return frame;
}

/// The same for an image of width x height: the scene's camera block, else an automatic camera.
inline SceneFrame scene_frame(Scene scene, int width, int height) {
    SceneSetup setup;
    setup.width = width;
    setup.height = height;
    return scene_frame(std::move(scene), setup);
}

/// The same seen by `camera` at width x height.
inline SceneFrame scene_frame(Scene scene, const CameraSpec& camera, int width = 1280,
                              int height = 720) {
    SceneSetup setup;
    setup.camera = camera;
    setup.width = width;
    setup.height = height;
    return scene_frame(std::move(scene), setup);
}

}  // namespace toonray::test_support
