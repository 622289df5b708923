// OBJ text through the whole pipeline at a tiny size: load, build the BVH, trace, shade and draw
// lines in both line modes. Finds what a scene that loads can do to the accelerator and the
// renderer (huge or tiny coordinates, degenerate triangles, odd cameras).

#include <algorithm>
#include <cmath>
#include <vector>

#include "fuzz_util.h"
#include "toonray/accel/triangle_accel.h"
#include "toonray/core/error.h"
#include "toonray/render/renderer.h"
#include "toonray/scene/obj_loader.h"

using namespace toonray;

namespace {

/// Known bug, reported to the accel owners (docs/robustness.md, "Open"): the BVH's SAH binning
/// computes (c - lo) * (bins / (hi - lo)) in float, which is NaN when the span of triangle
/// centres overflows to infinity or is so small that bins / span does, and then casts it to int
/// (undefined behaviour; an out-of-bounds bin index in practice). Until it is fixed, scenes
/// that can reach it are skipped here so that fuzzing goes on finding other bugs; the input
/// that found it is kept in tests/robustness/data/known/.
bool reaches_known_bvh_binning_bug(const Scene& scene) {
    for (int axis = 0; axis < 3; ++axis) {
        std::vector<float> c;
        c.reserve(scene.triangle_count());
        for (const auto& t : scene.tri_positions) {
            float lo = scene.positions[t[0]][axis], hi = lo;
            for (int k = 1; k < 3; ++k) {
                lo = std::min(lo, scene.positions[t[k]][axis]);
                hi = std::max(hi, scene.positions[t[k]][axis]);
            }
            c.push_back((lo + hi) * 0.5f);
        }
        std::sort(c.begin(), c.end());
        if (c.empty()) continue;
        if (!std::isfinite(c.back() - c.front())) return true;
        for (std::size_t i = 1; i < c.size(); ++i)
            if (c[i] > c[i - 1] && !std::isfinite(64.0f / (c[i] - c[i - 1]))) return true;
        for (float v : c)
            if (!std::isfinite(v)) return true;
    }
    return false;
}

}  // namespace

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
    if (scene.triangle_count() > 4096) return 0;  // keep each run fast
    if (reaches_known_bvh_binning_bug(scene)) return 0;
    RenderSettings settings;
    settings.width = 24;
    settings.height = 16;
    settings.threads = 1;
    CameraSpec camera = scene.camera ? *scene.camera : auto_camera(scene.positions, settings.width, settings.height);
    try {
        make_view_plane(camera, settings.width, settings.height);
    } catch (const Error&) {
        return 0;  // the renderer's contract: the camera is validated first
    }
    TriangleAccel accel;
    accel.build(scene.positions, scene.tri_positions);
    Renderer renderer;
    for (EdgeMode mode : {EdgeMode::Classic, EdgeMode::Robust}) {
        settings.edges = mode;
        const ImageRgb8& image = renderer.render(scene, accel, camera, settings);
        FUZZ_CHECK(image.width() == settings.width && image.height() == settings.height);
    }
    return 0;
}
