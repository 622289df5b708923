#include "toonray/anim/scene_frames.h"

#include <exception>
#include <future>

namespace toonray {
namespace {

// A job: one renderer, and two scenes when the source reads files, so that the next frame
// loads while this one renders.
class SceneFrameJob : public FrameJob {
public:
    SceneFrameJob(const RenderedFrames& frames, int jobs)
        : frames_(frames), render_(frames.render()) {
        render_.settings.threads = threads_per_frame(render_.settings.threads, jobs);
    }

    void produce(int frame, std::optional<int> next, Warnings& warnings) override {
        const SceneSource& scenes = frames_.scenes();
        Loaded current;
        if (pending_.valid()) current = pending_.get();  // loaded into frames_[slot_]
        if (pending_frame_ != frame) current = load_into(frame, scene_[slot_]);
        pending_frame_ = -1;
        if (next && scenes.reads_files()) {
            SceneFrame& target = scene_[1 - slot_];
            const int n = *next;
            pending_frame_ = n;
            pending_ =
                std::async(std::launch::async, [this, n, &target] { return load_into(n, target); });
        }
        const SceneFrame& scene = scene_[slot_];
        if (scenes.reads_files()) slot_ = 1 - slot_;
        warnings.insert(warnings.end(), current.warnings.begin(), current.warnings.end());
        if (current.error) std::rethrow_exception(current.error);
        render_.settings.frame = frame;  // sketchy strokes boil with it
        renderer_.render(scene, frames_.output(frame), render_, warnings);
    }

private:
    // A frame's scene as loaded, and what went wrong; nothing escapes the loading thread.
    struct Loaded {
        Warnings warnings;
        std::exception_ptr error;
    };

    Loaded load_into(int frame, SceneFrame& scene) const {
        Loaded loaded;
        try {
            frames_.scenes().load(frame, scene, loaded.warnings);
        } catch (...) {
            loaded.error = std::current_exception();
        }
        return loaded;
    }

    const RenderedFrames& frames_;
    FrameOptions render_;
    FrameRenderer renderer_;
    SceneFrame scene_[2];
    int slot_ = 0;  ///< the scene of the frame produced next
    std::future<Loaded> pending_;
    int pending_frame_ = -1;
};

}  // namespace

RenderedFrames::RenderedFrames(const SceneSource& scenes, const FrameOptions& render,
                               std::filesystem::path output_dir, FramePattern output_pattern)
    : scenes_(scenes),
      render_(render),
      output_dir_(std::move(output_dir)),
      output_pattern_(std::move(output_pattern)) {}

std::filesystem::path RenderedFrames::output(int frame) const {
    return output_dir_ / output_pattern_.format(frame);
}

bool RenderedFrames::done(int frame) const { return frame_complete(output(frame), render_); }

std::unique_ptr<FrameJob> RenderedFrames::make_job(int jobs) {
    return std::make_unique<SceneFrameJob>(*this, jobs);
}

}  // namespace toonray
