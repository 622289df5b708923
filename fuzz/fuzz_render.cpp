// OBJ text through the whole pipeline at a tiny size: load, build the BVH, trace, shade and draw
// lines in both line modes. Finds what a scene that loads can do to the accelerator and the
// renderer (huge or tiny coordinates, degenerate triangles, odd cameras). Scenes with extreme
// coordinates used to be skipped here (the old BVH binning cast NaN to int); the rewritten
// builder handles them, and the inputs that found that bug are kept in
// tests/robustness/data/fuzz/render/.
//
// Beyond "no crash", the accelerator's promise (docs/accel.md, "Exactness") is checked on every
// instruction set this CPU runs: for each camera ray, the tile traversal, the single-ray
// traversal and brute force over all triangles give the same hit bit for bit, and the rendered
// images are identical.

#include <algorithm>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "fuzz_util.h"
#include "toonray/accel/triangle_accel.h"
#include "toonray/core/error.h"
#include "toonray/render/renderer.h"
#include "toonray/scene/light.h"
#include "toonray/scene/obj_loader.h"

using namespace toonray;

namespace {

constexpr int kWidth = 24, kHeight = 16;

std::uint32_t bits(float f) {
    std::uint32_t u;
    std::memcpy(&u, &f, sizeof u);
    return u;
}

bool same_hit(const Hit& a, const Hit& b) {
    return a.prim == b.prim && bits(a.t) == bits(b.t) && bits(a.u) == bits(b.u) &&
           bits(a.v) == bits(b.v);
}

// The lowest (t, index) over the triangles whose watertight test passes: what the accelerator
// must return whatever its tree (tests/accel/tile_test.cpp has the same reference).
Hit brute_force(const Scene& scene, const Ray& ray) {
    Hit best;
    for (std::uint32_t i = 0; i < scene.tri_positions.size(); ++i) {
        const auto& tri = scene.tri_positions[i];
        Ray r = ray;
        r.tmax = std::min(best.t, ray.tmax);
        float t, u, v;
        if (intersect_triangle(r, scene.positions[tri[0]], scene.positions[tri[1]],
                               scene.positions[tri[2]], t, u, v))
            best = Hit{t, i, u, v};
    }
    return best;
}

// The instruction sets to check: the portable one, and AVX2 and AVX-512 where the CPU has them.
const std::vector<std::string>& isas() {
    static const std::vector<std::string> list = [] {
        std::vector<std::string> out{"sse4.2"};
        for (const char* isa : {"avx2", "avx512"})
            if (set_accel_isa(isa)) out.push_back(isa);
        set_accel_isa("auto");
        return out;
    }();
    return list;
}

// Restores the default kernels however the run ends (the replay test runs other targets after).
struct IsaGuard {
    ~IsaGuard() { set_accel_isa("auto"); }
};

// Traces the camera's pixel rays (as the renderer makes them) as one tile and one by one with
// the current kernels; both must agree with each other and with `reference` (brute force on the
// first instruction set, then that set's hits), which is filled on the first call.
void check_hits(const Scene& scene, const TriangleAccel& accel, const ViewPlane& view,
                std::vector<Hit>& reference) {
    std::vector<Vec3f> dirs(kWidth * kHeight);
    for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x)
            dirs[y * kWidth + x] = normalize(view.pixel_point(x + 0.5f, y + 0.5f) - view.eye);
    std::vector<Hit> tile(dirs.size());
    std::unique_ptr<bool[]> found(new bool[dirs.size()]);
    accel.intersect_tile(view.eye, dirs.data(), kWidth, kHeight, tile.data(), found.get());
    const bool first = reference.empty();
    for (std::size_t i = 0; i < dirs.size(); ++i) {
        const Ray ray{view.eye, dirs[i]};
        Hit single;
        const bool hit = accel.intersect(ray, single);
        FUZZ_CHECK(found[i] == hit && hit == single.valid());
        FUZZ_CHECK(same_hit(tile[i], single));
        if (first) reference.push_back(brute_force(scene, ray));
        FUZZ_CHECK(same_hit(single, reference[i]));
    }
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
    // Keeps each run fast: brute force costs 384 rays times the triangles, per instruction set.
    if (scene.triangle_count() > 1024) return 0;
    RenderSettings settings;
    settings.width = kWidth;
    settings.height = kHeight;
    settings.threads = 1;
    CameraSpec camera = scene.camera
                            ? *scene.camera
                            : auto_camera(scene.positions, settings.width, settings.height);
    ViewPlane view;
    try {
        view = make_view_plane(camera, settings.width, settings.height);
    } catch (const Error&) {
        return 0;  // the renderer's contract: the camera is validated first
    }
    TriangleAccel accel;
    accel.build(scene.positions, scene.tri_positions);
    const std::vector<Light> lights{default_light(scene, camera)};

    IsaGuard restore_default_kernels;
    std::vector<Hit> reference_hits;
    ImageRgb8 reference_images[2];
    Renderer renderer;
    for (const std::string& isa : isas()) {
        FUZZ_CHECK(set_accel_isa(isa));
        check_hits(scene, accel, view, reference_hits);
        int m = 0;
        for (LineMode mode : {LineMode::Classic, LineMode::Robust}) {
            settings.lines.mode = mode;
            // The first instruction set also computes the feature images: the others, without
            // them, must give the same final image.
            settings.layers = reference_images[m].width() == 0;
            const ImageRgb8& image = renderer.render(scene, accel, camera, lights, settings);
            FUZZ_CHECK(image.width() == settings.width && image.height() == settings.height);
            ImageRgb8& reference = reference_images[m++];
            if (reference.width() == 0) {
                reference = image;
            } else {
                FUZZ_CHECK(std::memcmp(image.data(), reference.data(),
                                       sizeof(Rgb8) * kWidth * kHeight) == 0);
            }
        }
    }
    return 0;
}
