// OBJ text (materials not followed: the fuzzer must not read files). Checks that a scene that
// loads is consistent: every index in range, every number finite.

#include <cmath>

#include "fuzz_util.h"
#include "toonray/core/error.h"
#include "toonray/scene/obj_loader.h"

using namespace toonray;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    Scene scene;
    Warnings warnings;
    ObjOptions options;
    options.load_materials = false;
    try {
        parse_obj(toonray_fuzz::as_text(data, size), "fuzz.obj", scene, warnings, options);
    } catch (const Error&) {
        return 0;
    }
    const std::size_t n = scene.triangle_count();
    FUZZ_CHECK(scene.tri_normals.size() == n && scene.tri_texcoords.size() == n);
    FUZZ_CHECK(scene.tri_material.size() == n && scene.tri_object.size() == n);
    for (std::size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) {
            FUZZ_CHECK(scene.tri_positions[i][c] < scene.positions.size());
            FUZZ_CHECK(scene.tri_normals[i][c] == kNoIndex ||
                       scene.tri_normals[i][c] < scene.normals.size());
            FUZZ_CHECK(scene.tri_texcoords[i][c] == kNoIndex ||
                       scene.tri_texcoords[i][c] < scene.texcoords.size());
        }
        FUZZ_CHECK(scene.tri_material[i] < scene.materials.size());
        FUZZ_CHECK(scene.tri_object[i] < scene.objects.size());
    }
    for (const Polyline& line : scene.polylines) {
        FUZZ_CHECK(line.count >= 2 && line.first + line.count <= scene.polyline_points.size());
        FUZZ_CHECK(line.material < scene.materials.size() && line.object < scene.objects.size());
    }
    for (std::uint32_t v : scene.polyline_points) FUZZ_CHECK(v < scene.positions.size());
    // Non-finite coordinates are read as warnings, stored as 0, and their faces dropped.
    for (const Vec3f& p : scene.positions) FUZZ_CHECK(is_finite(p));
    for (const Vec3f& p : scene.normals) FUZZ_CHECK(is_finite(p));
    for (const Vec2f& t : scene.texcoords) FUZZ_CHECK(std::isfinite(t.x) && std::isfinite(t.y));
    if (scene.camera) {
        FUZZ_CHECK(is_finite(scene.camera->eye) && is_finite(scene.camera->gaze) &&
                   is_finite(scene.camera->up));
        FUZZ_CHECK(!(scene.camera->eye == scene.camera->gaze));
    }
    (void)scene.bounds();
    return 0;
}
