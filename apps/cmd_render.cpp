#include <memory>
#include <string>

#include "commands.h"
#include "toonray/anim/batch.h"
#include "toonray/core/error.h"
#include "toonray/core/limits.h"
#include "toonray/frame/frame_renderer.h"
#include "toonray/frame/lights.h"
#include "toonray/scene/auto_smooth.h"
#include "toonray/scene/obj_loader.h"

namespace toonray::cli {
namespace {

struct RenderCommandArgs {
    RenderArgs render;
    SceneArgs scene;
    std::string input, output, svg;
    bool svg_hidden = false;
};

int run_render(const RenderCommandArgs& args) {
    FrameOptions options = args.render.resolve();
    if (!args.svg.empty()) {
        if (options.settings.edges != EdgeMode::Ink) throw Error("--svg needs --edges ink");
        options.svg = args.svg;
        options.svg_hidden = args.svg_hidden;
    } else if (args.svg_hidden) {
        throw Error("--svg-hidden needs --svg");
    }
    {  // The frame buffers come first: the loader counts them in its memory estimate.
        Limits l = limits();
        l.reserved_memory = plan_frame_jobs(options, 1, 1).frame_bytes;
        set_limits(l);
    }
    Warnings warnings;
    Scene scene;
    load_obj(args.input, scene, warnings);
    // The scene's own lights (NAME.lights next to it) unless the command line gives lights.
    options.settings.shading.lights = frame_lights(args.input, options.settings.shading.lights);
    if (auto angle = args.scene.auto_smooth_angle()) auto_smooth(scene, *angle);
    FrameRenderer renderer;
    renderer.render(scene, choose_camera(scene, options), args.output, options, warnings);
    print_warnings(warnings);
    return 0;
}

}  // namespace

Subcommand add_render_command(CLI::App& app, LimitArgs& limit_args) {
    auto args = std::make_shared<RenderCommandArgs>();
    CLI::App* render = app.add_subcommand("render", "Render one OBJ scene to a PNG image");
    render->add_option("scene", args->input, "OBJ file (with its camera block, if any)")
        ->required()
        ->check(CLI::ExistingFile);
    render->add_option("-o,--output", args->output, "Output PNG file")->required();
    args->render.add_to(*render);
    args->scene.add_to(*render);
    render->add_option(
        "--svg", args->svg,
        "With --edges ink: also write the visible lines as SVG paths in pixel units, "
        "grouped by type (silhouette, border, crease, material, intersection)");
    render->add_flag("--svg-hidden", args->svg_hidden,
                     "With --svg: also write the hidden lines, in a layer of their own");
    limit_args.add_to(*render);
    return {render, [args] { return run_render(*args); }};
}

}  // namespace toonray::cli
