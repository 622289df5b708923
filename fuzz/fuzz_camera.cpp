// The OBJ camera block (`c eye gaze up` after v/vn lines) and the camera built from it: a camera
// the loader accepts has passed validate_camera, so it must give a finite view plane, never an
// Error or NaN rays. The same bytes
// also go to parse_camera_spec (the --camera value).

#include <cmath>
#include <string>

#include "fuzz_util.h"
#include "toonray/core/error.h"
#include "toonray/scene/camera.h"
#include "toonray/scene/obj_loader.h"

using namespace toonray;

namespace {

// `valid`: the camera has passed validate_camera, so make_view_plane must not throw.
void check_plane(const CameraSpec& camera, int width, int height, bool valid) {
    try {
        ViewPlane plane = make_view_plane(camera, width, height);
        FUZZ_CHECK(is_finite(plane.eye) && is_finite(plane.upper_left));
        FUZZ_CHECK(is_finite(plane.step_x) && is_finite(plane.step_y));
        FUZZ_CHECK(is_finite(plane.right) && is_finite(plane.up));
    } catch (const Error&) {
        FUZZ_CHECK(!valid);
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text = toonray_fuzz::as_text(data, size);
    try {
        (void)parse_camera_spec(std::string(text));
    } catch (const Error&) {
    }
    Scene scene;
    Warnings warnings;
    ObjOptions options;
    options.load_materials = false;
    try {
        parse_obj(text, "fuzz.obj", scene, warnings, options);
    } catch (const Error&) {
        return 0;
    }
    if (scene.camera) {
        check_plane(*scene.camera, 64, 48, true);
        check_plane(*scene.camera, 1, 32768, true);
    }
    // Without a camera block the renderer frames the scene's vertices.
    CameraSpec automatic = auto_camera(scene.positions, 64, 48);
    check_plane(automatic, 64, 48, false);
    return 0;
}
