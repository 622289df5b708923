#pragma once
// TEMPORARY compatibility shim for apps/toonray.cpp until the CLI moves to frame/; removed
// before the branch is final.
#include "toonray/anim/frame_scheduler.h"
#include "toonray/frame/frame_renderer.h"
#include "toonray/frame/lights.h"
#include "toonray/scene/obj_loader.h"

namespace toonray {
using FileRenderOptions = FrameOptions;
class FileRenderer {
public:
    void render(const std::filesystem::path& input, const std::filesystem::path& output, const FrameOptions& options,
                Warnings& warnings) {
        Scene scene;
        load_obj(input, scene, warnings);
        renderer_.render(scene, choose_camera(scene, options), output, options, warnings);
    }

private:
    FrameRenderer renderer_;
};
inline FramePlan plan_frame_jobs(const RenderSettings& settings, int requested, std::size_t frames) {
    FrameOptions options;
    options.settings = settings;
    return plan_frame_jobs(options, requested, frames);
}
}  // namespace toonray
