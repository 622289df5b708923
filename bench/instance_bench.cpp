// toonray_instance_bench: instanced scenes (docs/performance.md, "Instances").
//
//   toonray_instance_bench --write-crowd OUT.glb --count N [--mesh FILE.obj] [--eye-height H]
//       A field of N instances of one mesh (default: the 70k-triangle scan of
//       toonray_ink_bench --make-scan, or tests/data/spot.obj), each turned about the vertical
//       and scaled a little, on a ground quad, seen by a camera at one corner looking across
//       the field: EXT_mesh_gpu_instancing on one node. The same bytes on every machine
//       (portable_math, a fixed generator).
//   toonray_instance_bench --compare FILE.glb [--size WxH] [--threads N]
//       Renders the scene in the default look instanced and flattened (flatten_instances), in
//       process, and compares the pictures pixel by pixel: the share of equal pixels, and of the
//       others how many lie within 2 pixels of a line, a change of object or a change of toon
//       band in either picture ("along edges"), with the largest difference; and the time of
//       each frame.
//   toonray_instance_bench --quick
//       CTest's instance_bench_quick: a 100-instance crowd of the teapot at 640x360, instanced
//       against flattened, at least 99.9% of the pixels equal and all others along edges.

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "toonray/accel/scene_accel.h"
#include "toonray/core/error.h"
#include "toonray/core/portable_math.h"
#include "toonray/io/file.h"
#include "toonray/io/png.h"
#include "toonray/render/renderer.h"
#include "toonray/scene/gltf_animation.h"
#include "toonray/scene/gltf_loader.h"
#include "toonray/scene/obj_loader.h"
#include "toonray/scene/scene_source.h"

namespace toonray::bench {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

template <typename T>
void put(std::vector<std::uint8_t>& bin, T v) {
    std::uint8_t b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    bin.insert(bin.end(), b, b + sizeof(T));
}

struct Crowd {
    int count = 100;
    fs::path mesh;
    double eye_height = 0.0;  ///< 0: a default for the field's size
};

// The GLB of a crowd (see the top of this file).
std::vector<std::uint8_t> crowd_glb(const Crowd& crowd) {
    Scene source;
    Warnings warnings;
    load_obj(crowd.mesh, source, warnings);
    if (source.triangle_count() == 0) throw Error(crowd.mesh.string() + ": no triangles");
    const BBox box = source.triangle_bounds();
    const Vec3f extent = box.extent();
    const double size = std::max(extent.x, extent.z);
    const int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(crowd.count))));
    const double spacing = 1.6 * size;
    const double field = spacing * side;

    std::vector<std::uint8_t> bin;
    struct View {
        std::size_t offset, length;
    };
    std::vector<View> views;
    auto view_of = [&](auto&& write) {
        while (bin.size() % 4) bin.push_back(0);
        const std::size_t at = bin.size();
        write();
        views.push_back({at, bin.size() - at});
        return views.size() - 1;
    };
    // The mesh: its positions, and its normals when every corner has one in the OBJ (by
    // position: a scan has none).
    const std::size_t positions = view_of([&] {
        for (const Vec3f& p : source.positions) {
            put(bin, p.x);
            put(bin, p.y);
            put(bin, p.z);
        }
    });
    const std::size_t indices = view_of([&] {
        for (const auto& t : source.tri_positions)
            for (std::uint32_t v : t) put(bin, v);
    });
    // Instances: a fixed linear congruential generator for the turns and scales.
    std::uint64_t state = 0x2545F4914F6CDD1Dull;
    auto next = [&] {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return static_cast<double>(state >> 11) / 9007199254740992.0;  // [0, 1)
    };
    std::vector<std::array<float, 3>> t;
    std::vector<std::array<float, 4>> r;
    std::vector<std::array<float, 3>> s;
    for (int i = 0; i < crowd.count; ++i) {
        const double yaw = 6.283185307179586 * next();
        const double scale = 0.85 + 0.3 * next();
        const double x = (i % side + 0.5) * spacing + (next() - 0.5) * 0.3 * spacing;
        const double z = (i / side + 0.5) * spacing + (next() - 0.5) * 0.3 * spacing;
        t.push_back(
            {static_cast<float>(x), static_cast<float>(-box.lo.y * scale), static_cast<float>(z)});
        r.push_back({0.0f, static_cast<float>(portable::sin(0.5 * yaw)), 0.0f,
                     static_cast<float>(portable::cos(0.5 * yaw))});
        s.push_back(
            {static_cast<float>(scale), static_cast<float>(scale), static_cast<float>(scale)});
    }
    const std::size_t tv = view_of([&] {
        for (const auto& v : t)
            for (float f : v) put(bin, f);
    });
    const std::size_t rv = view_of([&] {
        for (const auto& v : r)
            for (float f : v) put(bin, f);
    });
    const std::size_t sv = view_of([&] {
        for (const auto& v : s)
            for (float f : v) put(bin, f);
    });
    // The ground: a quad under the field with a margin.
    const float g0 = static_cast<float>(-0.5 * field), g1 = static_cast<float>(1.5 * field);
    const std::size_t ground = view_of([&] {
        for (const float p : {g0, 0.0f, g0, g1, 0.0f, g0, g1, 0.0f, g1, g0, 0.0f, g1}) put(bin, p);
    });
    const std::size_t ground_indices = view_of([&] {
        for (const std::uint32_t i : {0u, 2u, 1u, 0u, 3u, 2u}) put(bin, i);
    });
    while (bin.size() % 4) bin.push_back(0);

    // The camera: from outside one corner, looking across the diagonal and a little down.
    const double height = crowd.eye_height > 0 ? crowd.eye_height : 0.08 * field + 2.0 * extent.y;
    const double eye[3] = {-0.04 * field, height, -0.04 * field};
    const double gaze[3] = {0.55 * field, 0.0, 0.55 * field};
    double f[3] = {gaze[0] - eye[0], gaze[1] - eye[1], gaze[2] - eye[2]};
    const double fl = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (double& v : f) v /= fl;
    double right[3] = {-f[2], 0.0, f[0]};  // f x (0, 1, 0)
    const double rl = std::sqrt(right[0] * right[0] + right[2] * right[2]);
    for (double& v : right) v /= rl;
    const double up[3] = {right[1] * f[2] - right[2] * f[1], right[2] * f[0] - right[0] * f[2],
                          right[0] * f[1] - right[1] * f[0]};
    // Columns right, up, -forward: the node's rotation as a quaternion.
    const double m[3][3] = {
        {right[0], up[0], -f[0]}, {right[1], up[1], -f[1]}, {right[2], up[2], -f[2]}};
    double q[4];
    const double trace = m[0][0] + m[1][1] + m[2][2];
    if (trace > 0) {
        const double k = 0.5 / std::sqrt(trace + 1.0);
        q[3] = 0.25 / k;
        q[0] = (m[2][1] - m[1][2]) * k;
        q[1] = (m[0][2] - m[2][0]) * k;
        q[2] = (m[1][0] - m[0][1]) * k;
    } else if (m[0][0] > m[1][1] && m[0][0] > m[2][2]) {
        const double k = 2.0 * std::sqrt(1.0 + m[0][0] - m[1][1] - m[2][2]);
        q[3] = (m[2][1] - m[1][2]) / k;
        q[0] = 0.25 * k;
        q[1] = (m[0][1] + m[1][0]) / k;
        q[2] = (m[0][2] + m[2][0]) / k;
    } else if (m[1][1] > m[2][2]) {
        const double k = 2.0 * std::sqrt(1.0 + m[1][1] - m[0][0] - m[2][2]);
        q[3] = (m[0][2] - m[2][0]) / k;
        q[0] = (m[0][1] + m[1][0]) / k;
        q[1] = 0.25 * k;
        q[2] = (m[1][2] + m[2][1]) / k;
    } else {
        const double k = 2.0 * std::sqrt(1.0 + m[2][2] - m[0][0] - m[1][1]);
        q[3] = (m[1][0] - m[0][1]) / k;
        q[0] = (m[0][2] + m[2][0]) / k;
        q[1] = (m[1][2] + m[2][1]) / k;
        q[2] = 0.25 * k;
    }

    std::string views_json, accessors;
    for (std::size_t i = 0; i < views.size(); ++i)
        views_json += fmt::format("{}{{\"buffer\": 0, \"byteOffset\": {}, \"byteLength\": {}}}",
                                  i ? ", " : "", views[i].offset, views[i].length);
    auto accessor = [&](std::size_t view, std::size_t count, int type_code, const char* type,
                        const std::string& extra = "") {
        accessors += fmt::format(
            "{}{{\"bufferView\": {}, \"componentType\": {}, \"count\": {}, \"type\": \"{}\"{}}}",
            accessors.empty() ? "" : ", ", view, type_code, count, type, extra);
    };
    accessor(positions, source.positions.size(), 5126, "VEC3",
             fmt::format(", \"min\": [{}, {}, {}], \"max\": [{}, {}, {}]", box.lo.x, box.lo.y,
                         box.lo.z, box.hi.x, box.hi.y, box.hi.z));   // 0
    accessor(indices, 3 * source.triangle_count(), 5125, "SCALAR");  // 1
    accessor(tv, t.size(), 5126, "VEC3");                            // 2
    accessor(rv, r.size(), 5126, "VEC4");                            // 3
    accessor(sv, s.size(), 5126, "VEC3");                            // 4
    accessor(ground, 4, 5126, "VEC3",
             fmt::format(", \"min\": [{}, 0, {}], \"max\": [{}, 0, {}]", g0, g0, g1, g1));  // 5
    accessor(ground_indices, 6, 5125, "SCALAR");                                            // 6
    const std::string json = fmt::format(
        R"({{"asset": {{"version": "2.0", "generator": "toonray_instance_bench"}},
"extensionsUsed": ["EXT_mesh_gpu_instancing"],
"scene": 0, "scenes": [{{"nodes": [0, 1, 2]}}],
"nodes": [
 {{"name": "crowd", "mesh": 0, "extensions": {{"EXT_mesh_gpu_instancing": {{"attributes": {{"TRANSLATION": 2, "ROTATION": 3, "SCALE": 4}}}}}}}},
 {{"name": "ground", "mesh": 1}},
 {{"name": "camera", "camera": 0, "translation": [{}, {}, {}], "rotation": [{}, {}, {}, {}]}}],
"cameras": [{{"type": "perspective", "perspective": {{"yfov": 0.6, "znear": 0.01, "aspectRatio": 1.7777778}}}}],
"meshes": [{{"name": "mesh", "primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1}}]}},
           {{"name": "ground", "primitives": [{{"attributes": {{"POSITION": 5}}, "indices": 6}}]}}],
"accessors": [{}],
"bufferViews": [{}],
"buffers": [{{"byteLength": {}}}]}})",
        eye[0], eye[1], eye[2], q[0], q[1], q[2], q[3], accessors, views_json, bin.size());
    std::string padded = json;
    while (padded.size() % 4) padded.push_back(' ');
    std::vector<std::uint8_t> out;
    auto u32 = [&](std::uint32_t v) { put(out, v); };
    out.insert(out.end(), {'g', 'l', 'T', 'F'});
    u32(2);
    u32(static_cast<std::uint32_t>(12 + 8 + padded.size() + 8 + bin.size()));
    u32(static_cast<std::uint32_t>(padded.size()));
    out.insert(out.end(), {'J', 'S', 'O', 'N'});
    out.insert(out.end(), padded.begin(), padded.end());
    u32(static_cast<std::uint32_t>(bin.size()));
    out.insert(out.end(), {'B', 'I', 'N', '\0'});
    out.insert(out.end(), bin.begin(), bin.end());
    return out;
}

struct Options {
    std::optional<fs::path> write;
    std::optional<fs::path> compare;
    Crowd crowd;
    int width = 1280, height = 720;
    int threads = 0;
    bool quick = false;
    std::optional<fs::path> out;
};

struct Comparison {
    std::uint64_t pixels = 0, equal = 0, along_edges = 0;
    int largest = 0;
    double instanced_s = 0, flattened_s = 0;
};

// A frame of the scene in the default look, its layers kept (object ids and lines).
const FrameLayers& render_frame(Renderer& renderer, const Scene& scene, const TriangleAccel& accel,
                                const SceneFrame& frame, const Options& options, double& seconds) {
    RenderSettings settings;
    settings.width = options.width;
    settings.height = options.height;
    settings.threads = options.threads;
    settings.layers = true;
    const auto start = Clock::now();
    renderer.render(scene, accel, frame.camera, frame.lights, settings);
    seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return renderer.layers();
}

Comparison compare(const fs::path& path, const Options& options) {
    Warnings warnings;
    SceneSetup setup;
    setup.width = options.width;
    setup.height = options.height;
    GltfSource source(load_gltf(path, warnings), {}, 24.0, setup);
    SceneFrame frame;
    source.load_at(0.0, frame);
    const Scene flat = flatten_instances(frame.scene);
    const TriangleAccel accel = build_scene_accel(frame.scene);
    const TriangleAccel flat_accel = build_scene_accel(flat);
    Renderer a, b;
    Comparison c;
    const FrameLayers& la = render_frame(a, frame.scene, accel, frame, options, c.instanced_s);
    const FrameLayers& lb = render_frame(b, flat, flat_accel, frame, options, c.flattened_s);
    const int w = options.width, h = options.height;
    // Pixels within 2 of a line (coverage > 0), of a change of object or of a change of the
    // toon band (the edges of the shading), in either picture.
    auto edge = [&](int x, int y) {
        for (int dy = -2; dy <= 2; ++dy)
            for (int dx = -2; dx <= 2; ++dx) {
                const int u = std::clamp(x + dx, 0, w - 1), v = std::clamp(y + dy, 0, h - 1);
                if (la.lines(u, v) > 0.0f || lb.lines(u, v) > 0.0f) return true;
                if (la.object(u, v) != la.object(x, y) || lb.object(u, v) != lb.object(x, y))
                    return true;
                if (la.band(u, v) != la.band(x, y) || lb.band(u, v) != lb.band(x, y)) return true;
            }
        return false;
    };
    std::vector<std::uint8_t> diff(static_cast<std::size_t>(w) * h * 3, 255);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            ++c.pixels;
            const Rgb8& p = la.image(x, y);
            const Rgb8& q = lb.image(x, y);
            int d = 0;
            for (int k = 0; k < 3; ++k) d = std::max(d, std::abs(int(p[k]) - int(q[k])));
            if (d == 0) {
                ++c.equal;
                continue;
            }
            c.largest = std::max(c.largest, d);
            const bool along = edge(x, y);
            c.along_edges += along;
            if (!along && c.pixels - c.equal - c.along_edges <= 8)
                fmt::print(
                    "  not along an edge: ({}, {}) colour {},{},{} / {},{},{}; object {} / {}; band "
                    "{} / {}; distance {} / {}; normal ({}, {}, {}) / ({}, {}, {})\n",
                    x, y, p[0], p[1], p[2], q[0], q[1], q[2], la.object(x, y), lb.object(x, y),
                    la.band(x, y), lb.band(x, y), la.distance(x, y), lb.distance(x, y),
                    la.normal(x, y).x, la.normal(x, y).y, la.normal(x, y).z, lb.normal(x, y).x,
                    lb.normal(x, y).y, lb.normal(x, y).z);
            std::uint8_t* o = &diff[(static_cast<std::size_t>(y) * w + x) * 3];
            o[0] = along ? 255 : 0;
            o[1] = 0;
            o[2] = along ? 0 : 255;
        }
    if (options.out) {
        fs::create_directories(*options.out);
        write_png(*options.out / "instanced.png", la.image);
        write_png(*options.out / "flattened.png", lb.image);
        write_file_atomic(*options.out / "difference.png", encode_png(w, h, 3, diff.data()));
    }
    fmt::print(
        "{}: {} instances of {} triangles ({} flattened), {}x{}\n"
        "  pixels equal: {} of {} ({:.4f}%); of the {} others {} along edges (within 2 px of a "
        "line, an object change or a band change), largest difference {}\n"
        "  frame (render only, {} thread{}): instanced {:.1f} ms, flattened {:.1f} ms\n",
        path.filename().string(), frame.scene.instances.size(),
        frame.scene.meshes.empty() ? 0 : frame.scene.meshes[0]->triangle_count(),
        flat.triangle_count(), w, h, c.equal, c.pixels, 100.0 * double(c.equal) / double(c.pixels),
        c.pixels - c.equal, c.along_edges, c.largest,
        options.threads == 0 ? std::string("all") : std::to_string(options.threads),
        options.threads == 1 ? "" : "s", 1e3 * c.instanced_s, 1e3 * c.flattened_s);
    return c;
}

int run(const Options& options) {
    if (options.write) {
        const std::vector<std::uint8_t> glb = crowd_glb(options.crowd);
        write_file_atomic(*options.write, glb);
        fmt::print("{}: {} instances of {}, {} bytes\n", options.write->string(),
                   options.crowd.count, options.crowd.mesh.filename().string(), glb.size());
        return 0;
    }
    if (options.quick) {
        Options o = options;
        o.width = 640;
        o.height = 360;
        o.crowd.count = 100;
        o.crowd.mesh = TOONRAY_BENCH_DATA_DIR "/teapot.obj";
        const fs::path file = fs::temp_directory_path() / "toonray_instance_bench_quick.glb";
        write_file_atomic(file, crowd_glb(o.crowd));
        const Comparison c = compare(file, o);
        const bool ok = c.equal * 1000 >= c.pixels * 999 && c.along_edges == c.pixels - c.equal;
        if (!ok) fmt::print(stderr, "instanced and flattened frames differ beyond the target\n");
        return ok ? 0 : 1;
    }
    if (options.compare) {
        compare(*options.compare, options);
        return 0;
    }
    throw Error("nothing to do: --write-crowd, --compare or --quick");
}

}  // namespace
}  // namespace toonray::bench

int main(int argc, char** argv) {
    using namespace toonray::bench;
    Options options;
    options.crowd.mesh = TOONRAY_BENCH_DATA_DIR "/spot.obj";
    try {
        for (int i = 1; i < argc; ++i) {
            const std::string arg = argv[i];
            auto value = [&]() -> std::string {
                if (i + 1 >= argc) throw toonray::Error(arg + " needs a value");
                return argv[++i];
            };
            if (arg == "--write-crowd") options.write = value();
            else if (arg == "--count") options.crowd.count = std::stoi(value());
            else if (arg == "--mesh") options.crowd.mesh = value();
            else if (arg == "--eye-height") options.crowd.eye_height = std::stod(value());
            else if (arg == "--compare") options.compare = value();
            else if (arg == "--threads") options.threads = std::stoi(value());
            else if (arg == "--out") options.out = value();
            else if (arg == "--quick") options.quick = true;
            else if (arg == "--size") {
                const std::string v = value();
                const auto x = v.find('x');
                if (x == std::string::npos) throw toonray::Error("--size takes WxH");
                options.width = std::stoi(v.substr(0, x));
                options.height = std::stoi(v.substr(x + 1));
            } else throw toonray::Error("unknown argument " + arg);
        }
        return run(options);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "toonray_instance_bench: %s\n", e.what());
        return 2;
    }
}
