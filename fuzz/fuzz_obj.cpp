// OBJ text (materials not followed: the fuzzer must not read files). Checks that a scene that
// loads is consistent: every index in range, every number finite; and that the text reads the
// same on the fast path (obj_fast_path.h) and in chunks read ahead and merged: neither may
// change what a line means.

#include <cmath>
#include <cstring>
#include <string>

#include "fuzz_util.h"
#include "toonray/core/error.h"
#include "toonray/scene/obj_fast_path.h"
#include "toonray/scene/obj_loader.h"

using namespace toonray;

namespace {

template <typename T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
    return a.size() == b.size() &&
           (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

// What parse_obj (or another way of reading) makes of a text.
struct Reading {
    Scene scene;
    Warnings warnings;
    std::string error;
};

template <typename Read>
Reading reading(const Read& read) {
    Reading out;
    try {
        read(out.scene, out.warnings);
    } catch (const Error& e) {
        out.error = e.what();
    }
    return out;
}

void check_same(const Reading& a, const Reading& b) {
    FUZZ_CHECK(a.error == b.error);
    FUZZ_CHECK(a.warnings == b.warnings);
    if (!a.error.empty()) return;
    FUZZ_CHECK(same_bytes(a.scene.positions, b.scene.positions));
    FUZZ_CHECK(same_bytes(a.scene.normals, b.scene.normals));
    FUZZ_CHECK(same_bytes(a.scene.texcoords, b.scene.texcoords));
    FUZZ_CHECK(same_bytes(a.scene.tri_positions, b.scene.tri_positions));
    FUZZ_CHECK(same_bytes(a.scene.tri_normals, b.scene.tri_normals));
    FUZZ_CHECK(same_bytes(a.scene.tri_texcoords, b.scene.tri_texcoords));
    FUZZ_CHECK(same_bytes(a.scene.tri_material, b.scene.tri_material));
    FUZZ_CHECK(same_bytes(a.scene.tri_object, b.scene.tri_object));
    FUZZ_CHECK(same_bytes(a.scene.polyline_points, b.scene.polyline_points));
    FUZZ_CHECK(same_bytes(a.scene.polylines, b.scene.polylines));
    FUZZ_CHECK(a.scene.objects == b.scene.objects);
    FUZZ_CHECK(a.scene.camera.has_value() == b.scene.camera.has_value());
    FUZZ_CHECK(!a.scene.camera ||
               std::memcmp(&*a.scene.camera, &*b.scene.camera, sizeof(CameraSpec)) == 0);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    ObjOptions options;
    options.load_materials = false;
    const std::string_view text = toonray_fuzz::as_text(data, size);
    const Reading plain = reading([&](Scene& scene, Warnings& warnings) {
        parse_obj(text, "fuzz.obj", scene, warnings, options);
    });
    // The same text followed by a padding comment, which puts all of it in the fast path's
    // padded zone (an empty line first: a last line continued with `\` is then joined with
    // nothing, as at the end of the text); and that read in chunks of a few bytes, each read
    // ahead and merged. Every way must read the same.
    const std::string padded = std::string(text) + "\n\n#" + std::string(80, ' ') + "\n";
    check_same(plain, reading([&](Scene& scene, Warnings& warnings) {
                   parse_obj(padded, "fuzz.obj", scene, warnings, options);
               }));
    check_same(plain, reading([&](Scene& scene, Warnings& warnings) {
                   wavefront::parse_obj_in_chunks(padded, "fuzz.obj", scene, warnings, options,
                                                  1 + size % 61, 0);
               }));
    if (!plain.error.empty()) return 0;
    const Scene& scene = plain.scene;
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
