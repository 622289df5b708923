#pragma once
/// Scenes the test suites share: the OBJ files of tests/data, and a camera that frames a scene.

#include <string>
#include <vector>

#include "toonray/scene/camera.h"
#include "toonray/scene/obj_loader.h"

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

}  // namespace toonray::test_support
