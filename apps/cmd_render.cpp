#include <memory>
#include <string>

#include "commands.h"
#include "toonray/anim/batch.h"
#include "toonray/core/error.h"
#include "toonray/core/limits.h"
#include "toonray/frame/frame_renderer.h"
#include "toonray/scene/obj_loader.h"

namespace toonray::cli {
namespace {

struct RenderCommandArgs {
    RenderArgs render;
    std::string input, output;
    SvgArgs svg;
};

int run_render(const RenderCommandArgs& args) {
    FrameOptions options = args.render.resolve();
    args.svg.apply(options, false);
    {  // The frame buffers come first: the loader counts them in its memory estimate.
        Limits l = limits();
        l.reserved_memory = plan_frame_jobs(options, 1, 1).frame_bytes;
        set_limits(l);
    }
    Warnings warnings;
    Scene scene;
    load_obj(args.input, scene, warnings);
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
    args->svg.add_to(*render, false);
    limit_args.add_to(*render);
    return {render, [args] { return run_render(*args); }};
}

}  // namespace toonray::cli
