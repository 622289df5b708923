#pragma once
/// The frames of a scene source (scene/scene_source.h) rendered to numbered files: what batch,
/// the piano and the demo schedule (anim/frame_scheduler.h).

#include <filesystem>
#include <memory>

#include "toonray/anim/frame_pattern.h"
#include "toonray/anim/frame_scheduler.h"
#include "toonray/frame/frame_renderer.h"
#include "toonray/scene/scene_source.h"

namespace toonray {

/// Renders frame N of `scenes` to `output_dir / output_pattern.format(N)`. Each job keeps its
/// own FrameRenderer (its BVH refits from frame to frame when the triangles stay the same) and
/// its own scenes; when the source reads files, a job loads its next frame while it renders
/// the current one.
class RenderedFrames : public FrameSource {
public:
    RenderedFrames(const SceneSource& scenes, const FrameOptions& render,
                   std::filesystem::path output_dir, FramePattern output_pattern);

    [[nodiscard]] std::filesystem::path output(int frame) const override;
    [[nodiscard]] bool done(int frame) const override;
    std::unique_ptr<FrameJob> make_job(int jobs) override;

    [[nodiscard]] const SceneSource& scenes() const { return scenes_; }
    [[nodiscard]] const FrameOptions& render() const { return render_; }

private:
    const SceneSource& scenes_;
    FrameOptions render_;
    std::filesystem::path output_dir_;
    FramePattern output_pattern_;
};

}  // namespace toonray
