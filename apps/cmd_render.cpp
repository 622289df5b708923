#include <memory>
#include <string>

#include "commands.h"
#include "gltf_args.h"
#include "toonray/anim/batch.h"
#include "toonray/anim/gltf_frames.h"
#include "toonray/core/error.h"
#include "toonray/core/limits.h"
#include "toonray/core/saturating.h"
#include "toonray/frame/frame_renderer.h"
#include "toonray/scene/gltf_loader.h"
#include "toonray/frame/lights.h"
#include "toonray/scene/auto_smooth.h"
#include "toonray/scene/obj_loader.h"

namespace toonray::cli {
namespace {

struct RenderCommandArgs {
    RenderArgs render;
    SceneArgs scene;
    std::string input, output;
    SvgArgs svg;
    GltfArgs gltf;
};

// A glTF scene posed at the time asked for, lit by its own lights unless lights are given.
void render_gltf(const RenderCommandArgs& args, const FrameOptions& options, Warnings& warnings) {
    GltfDocument document = load_gltf(args.input, warnings);
    check_memory(
        add_saturated(limits().reserved_memory, scene_bytes(document.vertices, document.triangles)),
        args.input);
    const GltfAnimator animator(std::move(document), args.gltf.pose());
    if (auto w = animator.aspect_warning(options.settings.width, options.settings.height))
        warnings.push_back(*w);
    Scene scene;
    std::vector<Light> lights;
    animator.pose(args.gltf.seconds(), options.settings.width, options.settings.height, scene,
                  lights);
    if (auto angle = args.scene.auto_smooth_angle()) auto_smooth(scene, *angle);
    const FrameOptions lit = with_gltf_lights(options, lights);
    FrameRenderer renderer;
    renderer.render(scene, choose_camera(scene, lit), args.output, lit, warnings);
}

int run_render(const RenderCommandArgs& args) {
    FrameOptions options = args.render.resolve();
    args.svg.apply(options, false);
    {  // The frame buffers come first: the loader counts them in its memory estimate.
        Limits l = limits();
        l.reserved_memory = plan_frame_jobs(options, 1, 1).frame_bytes;
        set_limits(l);
    }
    Warnings warnings;
    if (is_gltf_path(args.input)) {
        render_gltf(args, options, warnings);
        print_warnings(warnings);
        return 0;
    }
    if (args.gltf.given())
        throw Error("--animation, --camera-node, --time and --frame need a glTF scene");
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
    CLI::App* render = app.add_subcommand("render", "Render one OBJ or glTF scene to a PNG image");
    render
        ->add_option("scene", args->input,
                     "OBJ file (with its camera block, if any), or glTF (.gltf, .glb)")
        ->required()
        ->check(CLI::ExistingFile);
    render->add_option("-o,--output", args->output, "Output PNG file")->required();
    args->render.add_to(*render);
    args->scene.add_to(*render);
    args->svg.add_to(*render, false);
    args->gltf.add_to(*render, true);
    limit_args.add_to(*render);
    return {render, [args] { return run_render(*args); }};
}

}  // namespace toonray::cli
