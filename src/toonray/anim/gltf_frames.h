#pragma once
/// The frames of a glTF animation for the batch scheduler: frame N is the file posed at
/// N / fps seconds (anim/gltf_animation.h).

#include <memory>

#include "toonray/anim/frame_pattern.h"
#include "toonray/anim/frame_scheduler.h"
#include "toonray/anim/gltf_animation.h"

namespace toonray {

/// Frame options for one posed frame: the file's lights replace the default light unless
/// lights were given (`options.settings.shading.lights` not empty).
[[nodiscard]] FrameOptions with_gltf_lights(const FrameOptions& options,
                                            const std::vector<Light>& lights);

/// Renders frames of `animator` to `output_dir / output_pattern`.
class GltfFrames : public FrameSource {
public:
    GltfFrames(const GltfAnimator& animator, double fps, const FrameOptions& render,
               std::filesystem::path output_dir, FramePattern output_pattern);

    [[nodiscard]] std::filesystem::path output(int frame) const override;
    std::unique_ptr<FrameJob> make_job(int jobs) override;

    [[nodiscard]] const GltfAnimator& animator() const { return animator_; }
    [[nodiscard]] double fps() const { return fps_; }
    [[nodiscard]] const FrameOptions& render() const { return render_; }

private:
    const GltfAnimator& animator_;
    double fps_;
    FrameOptions render_;
    std::filesystem::path output_dir_;
    FramePattern output_pattern_;
};

}  // namespace toonray
