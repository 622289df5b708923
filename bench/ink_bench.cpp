// toonray_ink_bench: whole `--edges ink` frames (at the default 4 samples per pixel, and at 1
// like classic) and the ink stages (feature edges, visibility, chaining, drawing) timed on one
// thread against whole classic and robust frames of the same view, with medians of repeated
// runs after a warm-up. It also counts specks (8-connected groups of at
// most 12 pixels darker than 8% luminance) in the ink line image and in the robust `_edges`
// image, and with --out writes both, the ink lines over the cel colours, and the SVG.
//
// Usage: toonray_ink_bench [--repeats N] [--size WxH] [--out DIR] [--quick] [--previous PREV.obj]
//        [--lines-only] scene.obj ...
//        toonray_ink_bench --make-scan OUT.obj [--scan-splits N]
// With --previous, each scene is also timed as the next frame of an animation after PREV.obj
// (ink at 1 sample, the intersection lines of unmoved triangles kept from PREV.obj).
// With no scenes: tests/data/teapot.obj. --quick runs each stage once and checks that the
// ink lines do not depend on the thread count (CTest: ink_bench_quick). --lines-only times
// the ink stages alone (no whole frames), for profiles: under callgrind,
// --toggle-collect='*fresh_frame_lines*' counts the frames on their own and
// --toggle-collect='*next_frame_lines*' the frames after PREV.obj. --make-scan writes the
// 70k-triangle scan of docs/ink.md: tests/data/spot.obj with each triangle split into 4 at its
// edges' midpoints (shared), then into 3 at its centroid (70,272 triangles, shared vertices, no
// normals), with a camera block. --scan-splits N splits into 4 N times before the split into 3
// (default 1): 2 gives 281,088 triangles, 3 gives 1,124,352, 4 gives 4,497,408, 5 gives
// 17,989,632 (the sizes docs/performance.md measures the ink lines at).

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/ink/ink.h"
#include "toonray/ink/svg.h"
#include "toonray/io/png.h"
#include "toonray/frame/frame_renderer.h"
#include "toonray/io/file.h"
#include "toonray/render/renderer.h"
#include "toonray/scene/obj_loader.h"

namespace toonray::bench {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty()
               ? 0.0
               : (v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]));
}

int count_specks(const ImageGray8& lines) {
    const int w = lines.width(), h = lines.height();
    std::vector<std::uint8_t> seen(static_cast<std::size_t>(w) * h, 0);
    auto dark = [&](int x, int y) { return lines(x, y) < 0.08f * 255.0f; };
    int specks = 0;
    std::vector<std::pair<int, int>> stack;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (seen[static_cast<std::size_t>(y) * w + x] || !dark(x, y)) continue;
            int size = 0;
            stack.assign(1, {x, y});
            seen[static_cast<std::size_t>(y) * w + x] = 1;
            while (!stack.empty()) {
                const auto [cx, cy] = stack.back();
                stack.pop_back();
                ++size;
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        const int nx = cx + dx, ny = cy + dy;
                        if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
                        auto& flag = seen[static_cast<std::size_t>(ny) * w + nx];
                        if (flag || !dark(nx, ny)) continue;
                        flag = 1;
                        stack.push_back({nx, ny});
                    }
            }
            specks += size <= 12;
        }
    return specks;
}

// The ink stages of one frame on its own and of one frame after another, in functions of their
// own so that a profiler can count each case apart.
[[gnu::noinline]] void fresh_frame_lines(const Scene& scene, const TriangleAccel& accel,
                                         const CameraSpec& camera, int width, int height,
                                         ink::InkLines& lines) {
    lines.intersections = {};  // nothing kept from an earlier frame
    ink::draw_ink_lines(scene, accel, camera, width, height, {}, 1, lines);
}

[[gnu::noinline]] void next_frame_lines(const Scene& scene, const TriangleAccel& accel,
                                        const CameraSpec& camera, int width, int height,
                                        ink::InkLines& lines) {
    ink::draw_ink_lines(scene, accel, camera, width, height, {}, 1, lines);
}

std::string ms(double s) { return fmt::format("{:.1f} ms", s * 1e3); }

// --make-scan: a scan-like mesh from spot.obj (see the top of this file), computed in double
// and written with six decimals.
void make_scan(const fs::path& out_path, int splits) {
    using P = std::array<double, 3>;
    std::vector<P> v;
    std::vector<std::array<std::size_t, 3>> faces;
    std::ifstream in(TOONRAY_BENCH_DATA_DIR "/spot.obj");
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("v ", 0) == 0) {
            P p{};
            std::sscanf(line.c_str(), "v %lf %lf %lf", &p[0], &p[1], &p[2]);
            v.push_back(p);
        } else if (line.rfind("f ", 0) == 0) {
            std::array<std::size_t, 3> f{};
            std::size_t at = 2;
            for (auto& k : f) {
                k = std::stoul(line.substr(at)) - 1;
                at = line.find(' ', at) + 1;
            }
            faces.push_back(f);
        }
    }
    if (v.empty() || faces.empty()) throw Error("--make-scan: cannot read spot.obj");
    std::map<std::pair<std::size_t, std::size_t>, std::size_t> midpoints;
    auto midpoint = [&](std::size_t a, std::size_t b) {
        auto [it, inserted] = midpoints.try_emplace({std::min(a, b), std::max(a, b)}, v.size());
        if (inserted)
            v.push_back(
                {(v[a][0] + v[b][0]) / 2, (v[a][1] + v[b][1]) / 2, (v[a][2] + v[b][2]) / 2});
        return it->second;
    };
    std::vector<std::array<std::size_t, 3>> quarters;
    for (int split = 0; split < splits; ++split) {
        quarters.clear();
        for (const auto& [a, b, c] : faces) {
            const std::size_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
            for (const auto& q : {std::array{a, ab, ca}, std::array{ab, b, bc},
                                  std::array{ca, bc, c}, std::array{ab, bc, ca}})
                quarters.push_back(q);
        }
        faces = quarters;
        midpoints.clear();
    }
    auto fixed6 = [](const char* tag, const P& p) {  // as printf's %.6f rounds
        char buffer[128];
        std::snprintf(buffer, sizeof buffer, "%s %.6f %.6f %.6f\n", tag, p[0], p[1], p[2]);
        return std::string(buffer);
    };
    std::string text;
    // The camera: from (3.2, 1.0, 1.4) moved 1.35 times as far from (0, 0.11, 0.19), looking
    // at it with a 48-degree field of view, y up.
    const P centre{0.0, 0.11, 0.19}, from{3.2, 1.0, 1.4};
    P eye{}, dir{}, up{};
    for (int i = 0; i < 3; ++i) eye[i] = centre[i] + 1.35 * (from[i] - centre[i]);
    for (int i = 0; i < 3; ++i) dir[i] = centre[i] - eye[i];
    const double dir_len = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    for (double& d : dir) d /= dir_len;
    for (int i = 0; i < 3; ++i) up[i] = (i == 1 ? 1.0 : 0.0) - dir[1] * dir[i];
    const double up_len = std::sqrt(up[0] * up[0] + up[1] * up[1] + up[2] * up[2]);
    for (double& u : up) u /= up_len;
    text += "# Camera start\n" + fixed6("v", eye) +
            fixed6("v", {eye[0] + dir[0] * 2.2, eye[1] + dir[1] * 2.2, eye[2] + dir[2] * 2.2}) +
            fixed6("vn", up) + "c 1 2 1\n# Camera end\n";
    text += "# spot, each triangle split in 4 at edge midpoints, then in 3 at its centroid\n";
    std::string faces_text;
    for (const auto& [a, b, c] : quarters) {
        const std::size_t g = v.size();
        v.push_back({(v[a][0] + v[b][0] + v[c][0]) / 3, (v[a][1] + v[b][1] + v[c][1]) / 3,
                     (v[a][2] + v[b][2] + v[c][2]) / 3});
        for (const auto& [x, y] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}})
            faces_text += fmt::format("f {} {} {}\n", x + 3, y + 3, g + 3);  // after the camera's
    }
    for (const P& p : v) text += fixed6("v", p);
    text += faces_text;
    write_file_atomic(out_path,
                      std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

// Medians of the stage times of repeated draws.
struct StageTimes {
    std::vector<double> edges, visibility, chaining, drawing;
    void add(const ink::InkTimings& t) {
        edges.push_back(t.edges);
        visibility.push_back(t.visibility);
        chaining.push_back(t.chaining);
        drawing.push_back(t.drawing);
    }
    [[nodiscard]] std::string row() const {
        return fmt::format("{} | {} | {} | {}", ms(median(edges)), ms(median(visibility)),
                           ms(median(chaining)), ms(median(drawing)));
    }
};

struct Options {
    int repeats = 7;
    int width = 1280, height = 720;
    bool quick = false;
    bool lines_only = false;  ///< the ink stages only, no whole frames
    std::optional<fs::path> out;
    std::optional<fs::path> previous;  ///< a frame drawn before each scene, as in an animation
    std::vector<fs::path> scenes;
};

// A scene from an OBJ file with its accelerator and the camera a frame of it would have.
struct BenchScene {
    Scene scene;
    TriangleAccel accel;
    CameraSpec camera;
    std::vector<Light> lights;
};

BenchScene load_bench_scene(const fs::path& path, const FrameOptions& file_options) {
    BenchScene out;
    Warnings warnings;
    load_obj(path, out.scene, warnings);
    out.accel.build(out.scene.positions, out.scene.tri_positions);
    SceneSetup setup;
    setup.width = file_options.settings.width;
    setup.height = file_options.settings.height;
    out.camera = choose_camera(out.scene, setup);
    out.lights = {default_light(out.scene, out.camera)};
    return out;
}

// --lines-only: the stages of each scene on its own, and after --previous.
void run_lines_only(const Options& options) {
    fmt::print(
        "| scene | triangles | ink: edges | visibility | chaining | drawing |\n"
        "|---|---:|---:|---:|---:|---:|\n");
    FrameOptions file_options;
    file_options.settings.width = options.width;
    file_options.settings.height = options.height;
    BenchScene before;
    if (options.previous) before = load_bench_scene(*options.previous, file_options);
    for (const fs::path& path : options.scenes) {
        const BenchScene loaded = load_bench_scene(path, file_options);
        const Scene& scene = loaded.scene;
        const TriangleAccel& accel = loaded.accel;
        const CameraSpec& camera = loaded.camera;
        ink::InkLines lines;
        StageTimes fresh, next;
        for (int i = 0; i <= options.repeats; ++i) {
            fresh_frame_lines(scene, accel, camera, options.width, options.height, lines);
            if (i > 0 || options.repeats == 0) fresh.add(lines.timings);
        }
        fmt::print("| {} | {} | {} |\n", path.filename().string(), scene.triangle_count(),
                   fresh.row());
        if (!options.previous) continue;
        for (int i = 0; i <= options.repeats; ++i) {
            // The previous frame twice: the cache keeps corners from its second frame on.
            fresh_frame_lines(before.scene, before.accel, before.camera, options.width,
                              options.height, lines);
            ink::draw_ink_lines(before.scene, before.accel, before.camera, options.width,
                                options.height, {}, 1, lines);
            next_frame_lines(scene, accel, camera, options.width, options.height, lines);
            if (i > 0 || options.repeats == 0) next.add(lines.timings);
        }
        fmt::print("| {} after {} | | {} |\n", path.filename().string(),
                   options.previous->filename().string(), next.row());
    }
}

int run(const Options& options) {
    if (options.lines_only) {
        run_lines_only(options);
        return 0;
    }
    fmt::print(
        "| scene | triangles | classic frame | robust frame | ink frame | ink frame, 1 sample | "
        "ink 1 sample / classic | ink: edges | visibility | chaining | drawing | specks robust / ink |\n");
    fmt::print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    int failures = 0;
    std::vector<std::string> animation_rows;
    for (const fs::path& path : options.scenes) {
        FrameOptions file_options;
        file_options.settings.width = options.width;
        file_options.settings.height = options.height;
        const BenchScene loaded = load_bench_scene(path, file_options);
        const Scene& scene = loaded.scene;
        const TriangleAccel& accel = loaded.accel;
        const CameraSpec& camera = loaded.camera;
        const std::vector<Light>& lights = loaded.lights;
        const int repeats = options.quick ? 1 : options.repeats;

        // Whole frames on one thread: trace, shade, lines, compose.
        // Whole frames on one thread: trace, shade, lines, compose. Then once more with the
        // feature images, which the speck counts and --out read.
        // Before each ink frame the renderer draws a one-triangle scene, untimed: a renderer
        // keeps the last frame's intersection lines, which would make repeats of one frame
        // unfairly cheap (the animation table below measures that reuse between consecutive
        // frames), while its buffers stay allocated as for the other modes.
        Scene flush;
        for (const Vec3f& p : {Vec3f(0, 0, -1e3f), Vec3f(1, 0, -1e3f), Vec3f(0, 1, -1e3f)})
            flush.positions.push_back(p);
        flush.add_triangle({0, 1, 2}, 0, 0);
        TriangleAccel flush_accel;
        flush_accel.build(flush.positions, flush.tri_positions);
        auto time_frame = [&](LineMode mode, Renderer& renderer,
                              int samples = SamplingSettings{}.samples) {
            RenderSettings settings = file_options.settings;
            settings.lines.mode = mode;
            settings.sampling.samples = samples;
            settings.threads = 1;
            std::vector<double> t;
            for (int i = 0; i <= repeats; ++i) {
                if (mode == LineMode::Ink)
                    renderer.render(flush, flush_accel, camera, lights, settings);
                const auto start = Clock::now();
                renderer.render(scene, accel, camera, lights, settings);
                if (i > 0 || repeats == 0)
                    t.push_back(std::chrono::duration<double>(Clock::now() - start).count());
            }
            settings.layers = true;
            renderer.render(scene, accel, camera, lights, settings);
            return median(t);
        };
        Renderer classic, robust, inked;
        const double classic_s = time_frame(LineMode::Classic, classic);
        const double robust_s = time_frame(LineMode::Robust, robust);
        const double ink_s = time_frame(LineMode::Ink, inked);
        Renderer inked1;
        const double ink1_s = time_frame(LineMode::Ink, inked1, 1);

        ink::InkLines lines;
        StageTimes stages;
        for (int i = 0; i <= repeats; ++i) {
            fresh_frame_lines(scene, accel, camera, options.width, options.height, lines);
            if (i == 0 && repeats > 0) continue;
            stages.add(lines.timings);
        }
        if (options.quick) {
            ink::InkLines threaded;
            ink::draw_ink_lines(scene, accel, camera, options.width, options.height, {}, 0,
                                threaded);
            if (!std::equal(lines.coverage.data(), lines.coverage.data() + lines.coverage.size(),
                            threaded.coverage.data())) {
                fmt::print(stderr, "{}: ink lines differ between one thread and all threads\n",
                           path.string());
                ++failures;
            }
        }
        ImageGray8 ink_gray;
        ink::coverage_to_gray(lines.coverage, ink_gray);
        const int ink_specks = count_specks(ink_gray);
        ImageGray8 robust_gray;
        ink::coverage_to_gray(robust.layers().lines, robust_gray);
        const int robust_specks = count_specks(robust_gray);
        fmt::print("| {} | {} | {} | {} | {} | {} | {:.2f} | {} | {} / {} |\n",
                   path.filename().string(), scene.triangle_count(), ms(classic_s), ms(robust_s),
                   ms(ink_s), ms(ink1_s), ink1_s / classic_s, stages.row(), robust_specks,
                   ink_specks);
        if (options.previous) {
            // As in an animation: the previous frame first, untimed, then this one with what
            // the previous left (the intersection lines of the triangles that did not move).
            const BenchScene previous = load_bench_scene(*options.previous, file_options);
            const Scene& before = previous.scene;
            const TriangleAccel& before_accel = previous.accel;
            const CameraSpec& before_camera = previous.camera;
            std::vector<double> frame_t;
            StageTimes stages_t;
            RenderSettings settings = file_options.settings;
            settings.lines.mode = LineMode::Ink;
            settings.sampling.samples = 1;
            settings.threads = 1;
            Renderer renderer;
            ink::InkLines animated;
            for (int i = 0; i <= repeats; ++i) {
                renderer.render(before, before_accel, before_camera, previous.lights, settings);
                auto start = Clock::now();
                renderer.render(scene, accel, camera, lights, settings);
                const double frame_s = std::chrono::duration<double>(Clock::now() - start).count();
                ink::draw_ink_lines(before, before_accel, before_camera, options.width,
                                    options.height, {}, 1, animated);
                next_frame_lines(scene, accel, camera, options.width, options.height, animated);
                if (i == 0 && repeats > 0) continue;
                frame_t.push_back(frame_s);
                stages_t.add(animated.timings);
            }
            animation_rows.push_back(
                fmt::format("| {} after {} | {} | {:.2f} | {} |", path.filename().string(),
                            options.previous->filename().string(), ms(median(frame_t)),
                            median(frame_t) / classic_s, stages_t.row()));
        }
        if (options.out) {
            fs::create_directories(*options.out);
            const std::string stem = path.stem().string();
            RenderSettings settings = file_options.settings;
            settings.lines.mode = LineMode::Ink;
            write_png(*options.out / (stem + "_ink.png"),
                      inked.render(scene, accel, camera, lights, settings));
            write_png(*options.out / (stem + "_ink_edges.png"), ink_gray);
            write_png(*options.out / (stem + "_robust_edges.png"), robust_gray);
            ink::SvgSettings svg;
            svg.width = options.width;
            svg.height = options.height;
            svg.thickness = ink::stroke_thickness(2.0f, options.height);
            const std::string text = ink::svg_text(lines.strokes, svg);
            write_file_atomic(
                *options.out / (stem + "_ink.svg"),
                std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
        }
    }
    if (!animation_rows.empty()) {
        fmt::print(
            "\n| frame in an animation | ink frame, 1 sample | / classic | ink: edges | "
            "visibility | chaining | drawing |\n|---|---:|---:|---:|---:|---:|---:|\n");
        for (const std::string& row : animation_rows) fmt::print("{}\n", row);
    }
    return failures ? 1 : 0;
}

}  // namespace
}  // namespace toonray::bench

int main(int argc, char** argv) {
    using namespace toonray::bench;
    Options options;
    std::optional<fs::path> make_scan_path;
    int scan_splits = 1;
    try {
        for (int i = 1; i < argc; ++i) {
            const std::string arg = argv[i];
            auto value = [&]() -> std::string {
                if (i + 1 >= argc) throw toonray::Error(arg + " needs a value");
                return argv[++i];
            };
            if (arg == "--repeats") options.repeats = std::stoi(value());
            else if (arg == "--size") {
                const std::string v = value();
                const auto x = v.find('x');
                if (x == std::string::npos) throw toonray::Error("--size takes WxH");
                options.width = std::stoi(v.substr(0, x));
                options.height = std::stoi(v.substr(x + 1));
            } else if (arg == "--out") options.out = value();
            else if (arg == "--quick") options.quick = true;
            else if (arg == "--lines-only") options.lines_only = true;
            else if (arg == "--make-scan") make_scan_path = value();
            else if (arg == "--scan-splits") scan_splits = std::stoi(value());
            else if (arg == "--previous") options.previous = value();
            else if (!arg.empty() && arg[0] == '-') throw toonray::Error("unknown option " + arg);
            else options.scenes.emplace_back(arg);
        }
        if (make_scan_path) {
            if (scan_splits < 1 || scan_splits > 5) throw toonray::Error("--scan-splits: 1 to 5");
            make_scan(*make_scan_path, scan_splits);
            return 0;
        }
        if (options.scenes.empty())
            options.scenes.emplace_back(TOONRAY_BENCH_DATA_DIR "/teapot.obj");
        return run(options);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "toonray_ink_bench: %s\n", e.what());
        return 2;
    }
}
