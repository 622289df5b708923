#include "toonray/anim/frame_scheduler.h"

#include <gtest/gtest.h>

#include <atomic>
#include <fstream>
#include <limits>
#include <map>
#include <mutex>
#include <set>

#include "toonray/io/png.h"
#include "support/test_support.h"

using namespace toonray;
namespace fs = std::filesystem;

namespace {

// Frames that write a tiny PNG each; frames in `bad` fail, those in `limited` exceed a limit.
// Records what every job was asked, to check the scheduler's order.
class FakeFrames : public FrameSource {
public:
    explicit FakeFrames(fs::path dir) : dir_(std::move(dir)) {}

    [[nodiscard]] fs::path output(int frame) const override {
        return dir_ / ("f" + std::to_string(frame) + ".png");
    }

    std::unique_ptr<FrameJob> make_job(int jobs) override {
        jobs_seen = jobs;
        ++jobs_made;
        return std::make_unique<Job>(*this);
    }

    std::set<int> bad, limited, warned;
    std::atomic<int> jobs_made{0};
    std::atomic<int> jobs_seen{0};
    std::atomic<bool>* cancel_after_first = nullptr;
    std::mutex mutex;
    std::multiset<int> produced;
    std::vector<std::string> broken_promises;  // a `next` that was not the job's next frame

private:
    class Job : public FrameJob {
    public:
        explicit Job(FakeFrames& source) : source_(source) {}
        void produce(int frame, std::optional<int> next, Warnings& warnings) override {
            {
                std::lock_guard lock(source_.mutex);
                if (expected_ && *expected_ != frame)
                    source_.broken_promises.push_back(std::to_string(*expected_) + " then " +
                                                      std::to_string(frame));
                source_.produced.insert(frame);
            }
            expected_ = next;
            if (source_.cancel_after_first) *source_.cancel_after_first = true;
            if (source_.warned.count(frame)) warnings.push_back("look at " + std::to_string(frame));
            if (source_.bad.count(frame)) throw Error("frame " + std::to_string(frame) + " is bad");
            if (source_.limited.count(frame))
                throw LimitError(Limit::Triangles, "too many triangles");
            write_png(source_.output(frame), ImageGray8(2, 2));
        }

    private:
        FakeFrames& source_;
        std::optional<int> expected_;
    };

    fs::path dir_;
};

struct Recorder : BatchObserver {
    void frame_done(int frame, FrameStatus status, const std::string& message) override {
        done[frame] = status;
        if (!message.empty()) messages[frame] = message;
    }
    void warning(int frame, const std::string& message) override {
        warnings.emplace_back(frame, message);
    }
    std::map<int, FrameStatus> done;
    std::map<int, std::string> messages;
    std::vector<std::pair<int, std::string>> warnings;
};

std::vector<int> range(int first, int last) {
    std::vector<int> frames;
    for (int f = first; f <= last; ++f) frames.push_back(f);
    return frames;
}

}  // namespace

TEST(FramePlan, MemoryOfTheFramesInFlightSaturates) {
    constexpr std::uint64_t kMost = std::numeric_limits<std::uint64_t>::max();
    FramePlan plan{3, 1000};
    EXPECT_EQ(plan.bytes(), 3000u);
    EXPECT_EQ(plan.bytes(24), 3072u);
    plan.frame_bytes = std::uint64_t{1} << 62;
    EXPECT_EQ(plan.bytes(), 3 * plan.frame_bytes);
    EXPECT_EQ(plan.bytes(plan.frame_bytes), kMost);  // 3 * 2^63
    plan.jobs = 5;
    EXPECT_EQ(plan.bytes(), kMost);
    plan.jobs = 1;
    EXPECT_EQ(plan.bytes(kMost), kMost);
}

TEST(FrameScheduler, ProducesEveryFrameOnceAndReportsEach) {
    for (int jobs : {1, 3}) {
        test_support::TempDir dir("scheduler");
        FakeFrames source(dir.path);
        source.bad = {4};
        source.limited = {7};
        source.warned = {2};
        Recorder recorder;
        ScheduleOptions options;
        options.jobs = jobs;
        const BatchReport report = run_frames(source, range(1, 10), options, &recorder);
        EXPECT_EQ(report.total, 10);
        EXPECT_EQ(report.rendered, 8);
        EXPECT_EQ(report.failed, 2);
        EXPECT_FALSE(report.cancelled);
        EXPECT_EQ(source.produced, (std::multiset<int>{1, 2, 3, 4, 5, 6, 7, 8, 9, 10}));
        EXPECT_TRUE(source.broken_promises.empty()) << source.broken_promises.front();
        // A job is made by each thread that claims a frame (a fast one may claim them all).
        EXPECT_GE(source.jobs_made.load(), 1);
        EXPECT_LE(source.jobs_made.load(), jobs);
        EXPECT_EQ(source.jobs_seen.load(), jobs);
        ASSERT_EQ(report.failures.size(), 2u);
        EXPECT_EQ(report.failures[0].frame, 4);
        EXPECT_EQ(report.failures[0].message, "frame 4 is bad");
        EXPECT_FALSE(report.failures[0].limit.has_value());
        EXPECT_EQ(report.failures[1].frame, 7);
        EXPECT_EQ(report.failures[1].limit, Limit::Triangles);
        EXPECT_EQ(recorder.done.size(), 10u);
        EXPECT_EQ(recorder.done[4], FrameStatus::Failed);
        EXPECT_EQ(recorder.messages[7], "too many triangles");
        ASSERT_EQ(recorder.warnings.size(), 1u);
        EXPECT_EQ(recorder.warnings[0], (std::pair<int, std::string>{2, "look at 2"}));
    }
}

TEST(FrameScheduler, ResumeSkipsValidOutputsAndRedoesBrokenOnes) {
    test_support::TempDir dir("scheduler_resume");
    FakeFrames source(dir.path);
    write_png(source.output(2), ImageGray8(2, 2));
    std::ofstream(source.output(3)) << "truncated";
    ScheduleOptions options;
    options.resume = true;
    Recorder recorder;
    const BatchReport report = run_frames(source, range(1, 4), options, &recorder);
    EXPECT_EQ(report.skipped, 1);
    EXPECT_EQ(report.rendered, 3);
    EXPECT_EQ(recorder.done[2], FrameStatus::Skipped);
    EXPECT_EQ(source.produced, (std::multiset<int>{1, 3, 4}));
    EXPECT_TRUE(is_valid_png(source.output(3)));
}

TEST(FrameScheduler, FailFastAndCancelStopClaiming) {
    test_support::TempDir dir("scheduler_stop");
    {
        FakeFrames source(dir.path);
        source.bad = {1};
        ScheduleOptions options;
        options.fail_fast = true;
        const BatchReport report = run_frames(source, range(1, 20), options);
        EXPECT_EQ(report.failed, 1);
        EXPECT_LE(report.rendered, 1);  // at most the frame claimed with the failed one
        EXPECT_TRUE(report.cancelled);
    }
    {
        FakeFrames source(dir.path);
        std::atomic<bool> cancel{false};
        source.cancel_after_first = &cancel;
        ScheduleOptions options;
        options.cancel = &cancel;
        const BatchReport report = run_frames(source, range(1, 20), options);
        EXPECT_TRUE(report.cancelled);
        EXPECT_LE(report.rendered, 2);
    }
    {
        FakeFrames source(dir.path);
        const BatchReport report = run_frames(source, {}, ScheduleOptions{});
        EXPECT_EQ(report.total, 0);
        EXPECT_EQ(source.jobs_made.load(), 0);
    }
}

TEST(FrameScheduler, SeveralFramesAtOnceUseOneThreadEachUnlessAsked) {
    EXPECT_EQ(threads_per_frame(0, 1), 0);
    EXPECT_EQ(threads_per_frame(0, 4), 1);
    EXPECT_EQ(threads_per_frame(3, 4), 3);
}
