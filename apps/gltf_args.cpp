#include "gltf_args.h"

namespace toonray::cli {

void GltfArgs::add_to(CLI::App& app, bool one_frame) {
    const char* group = "glTF scenes";
    app.add_option("--animation", animation,
                   "glTF: the animation to play, by name or index (default: all at once)")
        ->group(group);
    app.add_option("--camera-node", camera_node,
                   "glTF: the camera node to look through (default: the scene's first)")
        ->group(group);
    app.add_option("--fps", fps, "glTF: frames per second; frame N is at N/fps seconds")
        ->check(CLI::Range(0.001, 100000.0))
        ->capture_default_str()
        ->group(group);
    if (!one_frame) return;
    auto* t = app.add_option("--time", time, "glTF: the time to render, in seconds")
                  ->check(CLI::Range(-1e9, 1e9))
                  ->group(group);
    app.add_option("--frame", frame, "glTF: the frame to render, at frame/fps seconds")
        ->check(CLI::Range(-1000000000, 1000000000))
        ->excludes(t)
        ->group(group);
}

GltfPoseOptions GltfArgs::pose() const {
    GltfPoseOptions o;
    if (!animation.empty()) o.animation = animation;
    if (!camera_node.empty()) o.camera_node = camera_node;
    return o;
}

double GltfArgs::seconds() const {
    if (time) return *time;
    if (frame) return gltf_frame_time(*frame, fps);
    return 0.0;
}

bool GltfArgs::given() const { return !animation.empty() || !camera_node.empty() || time || frame; }

}  // namespace toonray::cli
