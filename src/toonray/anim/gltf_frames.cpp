#include "toonray/anim/gltf_frames.h"

namespace toonray {
namespace {

// A job poses the animation into its own scene and renders it; the BVH is refitted from frame
// to frame (AnimationAccel), since posing keeps the triangles.
class GltfFrameJob : public FrameJob {
public:
    GltfFrameJob(const GltfFrames& source, int jobs) : source_(source), render_(source.render()) {
        render_.settings.threads = threads_per_frame(render_.settings.threads, jobs);
    }

    void produce(int frame, std::optional<int>, Warnings& warnings) override {
        source_.animator().pose(gltf_frame_time(frame, source_.fps()), render_.settings.width,
                                render_.settings.height, scene_, lights_);
        const FrameOptions options = with_gltf_lights(render_, lights_);
        renderer_.render(scene_, choose_camera(scene_, options), source_.output(frame), options,
                         warnings);
    }

private:
    const GltfFrames& source_;
    FrameOptions render_;
    FrameRenderer renderer_;
    Scene scene_;
    std::vector<Light> lights_;
};

}  // namespace

FrameOptions with_gltf_lights(const FrameOptions& options, const std::vector<Light>& lights) {
    FrameOptions o = options;
    if (o.settings.shading.lights.empty()) o.settings.shading.lights = lights;
    return o;
}

GltfFrames::GltfFrames(const GltfAnimator& animator, double fps, const FrameOptions& render,
                       std::filesystem::path output_dir, FramePattern output_pattern)
    : animator_(animator),
      fps_(fps),
      render_(render),
      output_dir_(std::move(output_dir)),
      output_pattern_(std::move(output_pattern)) {}

std::filesystem::path GltfFrames::output(int frame) const {
    return output_dir_ / output_pattern_.format(frame);
}

std::unique_ptr<FrameJob> GltfFrames::make_job(int jobs) {
    return std::make_unique<GltfFrameJob>(*this, jobs);
}

}  // namespace toonray
