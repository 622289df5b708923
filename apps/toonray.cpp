// toonray command line: parses arguments into options and calls the library. Errors from the
// library carry file and line; they are caught here once and printed.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <fmt/format.h>
#include <optional>
#include <string>

#include "toonray/core/error.h"
#include "toonray/core/parse.h"
#include "toonray/render/render_file.h"

namespace {

using namespace toonray;

/// Options shared by every command that renders, kept as text until validated.
struct RenderArgs {
    std::string size = "1280x720";
    std::string light;
    std::string camera;
    std::string background = "1,1,1";
    std::string edges = "classic";
    float depth_threshold = 8.0f;
    float normal_threshold = 4.0f;
    int threads = 0;
    int leaf_size = Bvh::Config{}.max_leaf_size;
    int png_level = PngOptions{}.level;
    std::string aov_dir;

    void add_to(CLI::App& app) {
        app.add_option("--size", size, "Image size WIDTHxHEIGHT")->capture_default_str();
        app.add_option("--light", light,
                       "Point light position x,y,z (default: the eye moved by half the scene "
                       "radius along the camera's up and right)");
        app.add_option("--camera", camera,
                       "Camera ex,ey,ez,gx,gy,gz,ux,uy,uz: eye, gaze point, up; overrides the "
                       "file's camera block (default: the block, else a camera framing the scene)");
        app.add_option("--background", background, "Background colour r,g,b in [0,1] or #rrggbb")
            ->capture_default_str();
        app.add_option("--edges", edges, "Line mode: classic (the seed's Sobel pipeline)")
            ->check(CLI::IsMember({"classic"}))
            ->capture_default_str();
        app.add_option("--depth-threshold", depth_threshold,
                       "Classic mode: Sobel magnitude on the 8-bit depth map above which a pixel is a line")
            ->capture_default_str();
        app.add_option("--normal-threshold", normal_threshold,
                       "Classic mode: Sobel magnitude on the 8-bit normal map above which a pixel is a line")
            ->capture_default_str();
        app.add_option("--aov", aov_dir,
                       "Also write feature images to this directory: NAME_depth, _normal, "
                       "_edges_depth, _edges_normal, _edges, _cel .png");
        app.add_option("--threads", threads, "Threads to use (0 = all)")
            ->check(CLI::Range(0, 1024))
            ->capture_default_str();
        app.add_option("--bvh-leaf-size", leaf_size, "Largest number of triangles in a BVH leaf")
            ->check(CLI::Range(1, 64))
            ->capture_default_str();
        app.add_option("--png-level", png_level, "PNG compression level, 1 (fast) to 12 (small)")
            ->check(CLI::Range(1, 12))
            ->capture_default_str();
    }

    FileRenderOptions resolve() const {
        FileRenderOptions o;
        ImageSize s = parse_image_size(size, "--size");
        o.settings.width = s.width;
        o.settings.height = s.height;
        if (!light.empty()) o.settings.light = parse_vec3(light, "--light");
        if (!camera.empty()) o.camera = parse_camera_spec(camera);
        o.settings.background = parse_colour(background, "--background");
        o.settings.edges = EdgeMode::Classic;
        o.settings.depth_threshold = depth_threshold;
        o.settings.normal_threshold = normal_threshold;
        o.settings.threads = threads;
        o.bvh.max_leaf_size = leaf_size;
        o.png.level = png_level;
        if (!aov_dir.empty()) o.aov_dir = aov_dir;
        return o;
    }
};

void print_warnings(const Warnings& warnings) {
    for (const auto& w : warnings) fmt::print(stderr, "toonray: warning: {}\n", w);
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"toonray: a toon ray tracer. OBJ/MTL scenes in, cel-shaded and outlined PNG out."};
    app.require_subcommand(1);
    app.set_version_flag("--version", "toonray 0.1.0");

    RenderArgs render_args;
    std::string render_input, render_output;
    CLI::App* render = app.add_subcommand("render", "Render one OBJ scene to a PNG image");
    render->add_option("scene", render_input, "OBJ file (with its camera block, if any)")
        ->required()
        ->check(CLI::ExistingFile);
    render->add_option("-o,--output", render_output, "Output PNG file")->required();
    render_args.add_to(*render);

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    }

    try {
        if (*render) {
            FileRenderOptions options = render_args.resolve();
            Warnings warnings;
            FileRenderer renderer;
            renderer.render(render_input, render_output, options, warnings);
            print_warnings(warnings);
        }
    } catch (const Error& e) {
        fmt::print(stderr, "toonray: error: {}\n", e.what());
        return 1;
    } catch (const std::exception& e) {
        fmt::print(stderr, "toonray: error: {}\n", e.what());
        return 1;
    }
    return 0;
}
