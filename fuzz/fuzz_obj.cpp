// OBJ text (materials not followed: the fuzzer must not read files). Checks that a scene that
// loads is consistent: every index in range, every number finite; and that the text reads the
// same when a padding comment follows it, which puts all of it in the fast path's padded zone
// (obj_fast_path.h): the fast path must never change what a line means.

#include <cmath>
#include <cstring>
#include <string>

#include "fuzz_util.h"
#include "toonray/core/error.h"
#include "toonray/scene/obj_loader.h"

using namespace toonray;

namespace {

template <typename T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
    return a.size() == b.size() &&
           (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

// The padded text reads to the same scene, warnings and error as the text itself. An empty line
// comes first: a last line continued with `\` is then joined with nothing, as at the end.
void check_padded_reads_the_same(std::string_view text, const Scene& scene,
                                 const Warnings& warnings, const std::string& error) {
    const std::string padded = std::string(text) + "\n\n#" + std::string(80, ' ') + "\n";
    Scene other;
    Warnings other_warnings;
    ObjOptions options;
    options.load_materials = false;
    std::string other_error;
    try {
        parse_obj(padded, "fuzz.obj", other, other_warnings, options);
    } catch (const Error& e) {
        other_error = e.what();
    }
    FUZZ_CHECK(error == other_error);
    FUZZ_CHECK(warnings == other_warnings);
    if (!error.empty()) return;
    FUZZ_CHECK(same_bytes(scene.positions, other.positions));
    FUZZ_CHECK(same_bytes(scene.normals, other.normals));
    FUZZ_CHECK(same_bytes(scene.texcoords, other.texcoords));
    FUZZ_CHECK(same_bytes(scene.tri_positions, other.tri_positions));
    FUZZ_CHECK(same_bytes(scene.tri_normals, other.tri_normals));
    FUZZ_CHECK(same_bytes(scene.tri_texcoords, other.tri_texcoords));
    FUZZ_CHECK(same_bytes(scene.tri_material, other.tri_material));
    FUZZ_CHECK(same_bytes(scene.tri_object, other.tri_object));
    FUZZ_CHECK(same_bytes(scene.polyline_points, other.polyline_points));
    FUZZ_CHECK(same_bytes(scene.polylines, other.polylines));
    FUZZ_CHECK(scene.objects == other.objects);
    FUZZ_CHECK(scene.camera.has_value() == other.camera.has_value());
    FUZZ_CHECK(!scene.camera ||
               std::memcmp(&*scene.camera, &*other.camera, sizeof(CameraSpec)) == 0);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    Scene scene;
    Warnings warnings;
    ObjOptions options;
    options.load_materials = false;
    const std::string_view text = toonray_fuzz::as_text(data, size);
    std::string error;
    try {
        parse_obj(text, "fuzz.obj", scene, warnings, options);
    } catch (const Error& e) {
        error = e.what();
    }
    check_padded_reads_the_same(text, scene, warnings, error);
    if (!error.empty()) return 0;
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
