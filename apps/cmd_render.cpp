#include <memory>
#include <string>

#include "commands.h"
#include "gltf_args.h"
#include "toonray/anim/batch.h"
#include "toonray/core/error.h"
#include "toonray/core/limits.h"
#include "toonray/core/saturating.h"
#include "toonray/frame/frame_renderer.h"
#include "toonray/scene/gltf_animation.h"
#include "toonray/scene/gltf_loader.h"
#include "toonray/scene/scene_source.h"

namespace toonray::cli {
namespace {

struct RenderCommandArgs {
    SettingsArgs render;
    std::string input, output;
    SvgArgs svg;
    GltfArgs gltf;
};

// A glTF scene posed at the time asked for, lit by its own lights unless lights are given.
void load_gltf_frame(const RenderCommandArgs& args, const SceneSetup& setup, SceneFrame& frame,
                     Warnings& warnings) {
    GltfDocument document = load_gltf(args.input, warnings);
    check_memory(
        add_saturated(limits().reserved_memory,
                      scene_bytes(document.vertices, document.triangles, document.instances)),
        args.input);
    const GltfSource source(std::move(document), args.gltf.pose(), args.gltf.fps, setup);
    if (auto w = source.animator().aspect_warning(setup.width, setup.height))
        warnings.push_back(*w);
    source.load_at(args.gltf.seconds(), frame);
}

int run_render(const RenderCommandArgs& args) {
    const Settings settings = args.render.apply();
    FrameOptions options = args.render.frame_options(settings);
    args.svg.apply(options, false, args.render);
    const SceneSetup setup = settings.scene_setup();
    {  // The frame buffers come first: the loader counts them in its memory estimate.
        Limits l = limits();
        l.reserved_memory = plan_frame_jobs(options, 1, 1).frame_bytes;
        set_limits(l);
    }
    Warnings warnings;
    SceneFrame frame;
    if (is_gltf_path(args.input)) {
        load_gltf_frame(args, setup, frame, warnings);
    } else {
        if (args.gltf.given())
            throw Error("--animation, --camera-node, --time and --frame need a glTF scene");
        ObjFileSource(args.input, setup).load(0, frame, warnings);
    }
    FrameRenderer renderer;
    renderer.render(frame, args.output, options, warnings);
    print_warnings(warnings);
    return 0;
}

}  // namespace

Subcommand add_render_command(CLI::App& app) {
    auto args = std::make_shared<RenderCommandArgs>();
    CLI::App* render = app.add_subcommand("render", "Render one OBJ or glTF scene to a PNG image");
    render
        ->add_option("scene", args->input,
                     "OBJ file (with its camera block, if any), or glTF (.gltf, .glb)")
        ->required()
        ->check(CLI::ExistingFile);
    render->add_option("-o,--output", args->output, "Output PNG file")->required();
    args->render.add_to(*render);
    args->svg.add_to(*render, false);
    args->gltf.add_to(*render, true);
    return {render, [args] { return run_render(*args); }};
}

}  // namespace toonray::cli
