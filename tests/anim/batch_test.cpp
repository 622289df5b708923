#include "toonray/anim/batch.h"

#include <gtest/gtest.h>

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define TOONRAY_HAS_ASAN 1
#endif
#endif
#ifndef TOONRAY_HAS_ASAN
#define TOONRAY_HAS_ASAN 0
#endif

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>

#include "toonray/core/error.h"
#include "toonray/io/file.h"
#include "toonray/io/png.h"
#include "support/test_support.h"

using namespace toonray;
namespace fs = std::filesystem;

namespace {

using toonray::test_support::TempDir;

// A small animated scene: a box whose corners and camera move with the frame number, and a
// tessellated strip whose length varies so that frames differ in size.
std::string frame_obj(int frame) {
    std::string s = "mtllib frame.mtl\n";
    float a = 0.05f * frame;
    s += "# Camera start\nv " + std::to_string(3 * std::sin(a)) + " 1.5 " +
         std::to_string(3 * std::cos(a)) + "\nv " + std::to_string(2 * std::sin(a)) + " 1.2 " +
         std::to_string(2 * std::cos(a)) + "\nvn 0 1 0\nc -2 -1 -1\n# Camera end\n";
    s += "o box\nusemtl red\n";
    for (int i = 0; i < 8; ++i)
        s += "v " + std::to_string((i & 1) ? 0.5f : -0.5f) + " " +
             std::to_string((i & 2) ? 1.0f : 0.0f) + " " + std::to_string((i & 4) ? 0.5f : -0.5f) +
             "\n";
    s +=
        "f -8 -7 -5 -6\nf -4 -3 -1 -2\nf -8 -6 -2 -4\nf -7 -3 -1 -5\nf -8 -4 -3 -7\nf -6 -5 -1 -2\n";
    s += "o strip\nusemtl blue\n";
    int n = 10 + frame % 37;
    for (int i = 0; i <= n; ++i)
        s += "v " + std::to_string(-1 + 2.0f * i / n) + " 0 1\nv " +
             std::to_string(-1 + 2.0f * i / n) + " 0.3 1.2\n";
    for (int i = 0; i < n; ++i) {
        int b = -2 * (n + 1) + 2 * i;
        s += "f " + std::to_string(b) + " " + std::to_string(b + 2) + " " + std::to_string(b + 3) +
             " " + std::to_string(b + 1) + "\n";
    }
    return s;
}

void write_frames(const fs::path& dir, int first, int last, const std::string& name = "keys") {
    fs::create_directories(dir);
    std::ofstream(dir / "frame.mtl") << "newmtl red\nKd 0.9 0.2 0.2\nnewmtl blue\nKd 0.2 0.3 0.9\n";
    for (int f = first; f <= last; ++f) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%s_%06d.obj", name.c_str(), f);
        std::ofstream(dir / buf) << frame_obj(f);
    }
}

BatchOptions small_options(const fs::path& in, const fs::path& out) {
    BatchOptions o;
    o.name = "keys";
    o.input_dir = in;
    o.output_dir = out;
    o.render.settings.width = 96;
    o.render.settings.height = 64;
    return o;
}

std::string bytes(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(f), {}};
}

long status_kib(const char* field) {
    std::ifstream f("/proc/self/status");
    std::string line;
    while (std::getline(f, line))
        if (line.rfind(field, 0) == 0) return std::atol(line.c_str() + std::strlen(field));
    return -1;
}

}  // namespace

TEST(FramePattern, FormatsAndValidates) {
    EXPECT_EQ(FramePattern("keys_%06d.obj").format(42), "keys_000042.obj");
    EXPECT_EQ(FramePattern("k%d.obj").format(7), "k7.obj");
    EXPECT_EQ(FramePattern("100%%_%04d.png").format(3), "100%_0003.png");
    for (const char* bad :
         {"keys.obj", "%d_%d.obj", "%s.obj", "%6d.obj", "%010d.obj", "a/%d.obj", "%"})
        EXPECT_THROW(FramePattern{bad}, Error) << bad;
}

TEST(FramePattern, DefaultCandidatesInOrder) {
    TempDir dir("patterns");
    auto patterns = default_input_patterns("keys");
    EXPECT_FALSE(find_frame_file(dir.path, patterns, 5));
    std::ofstream(dir.path / "keys_5.obj") << "";
    EXPECT_EQ(find_frame_file(dir.path, patterns, 5)->filename(), "keys_5.obj");
    std::ofstream(dir.path / "keys5.obj") << "";
    EXPECT_EQ(find_frame_file(dir.path, patterns, 5)->filename(), "keys5.obj");
    std::ofstream(dir.path / "keys_0005.obj") << "";
    EXPECT_EQ(find_frame_file(dir.path, patterns, 5)->filename(), "keys_0005.obj");
    std::ofstream(dir.path / "keys_000005.obj") << "";
    EXPECT_EQ(find_frame_file(dir.path, patterns, 5)->filename(), "keys_000005.obj");
}

TEST(Shard, InterleavedSharesCoverEveryFrameOnce) {
    for (int n : {1, 3, 4, 7}) {
        std::multiset<int> all;
        for (int k = 1; k <= n; ++k)
            for (int f : shard_frames(1, 2229, {k, n})) all.insert(f);
        ASSERT_EQ(all.size(), 2229u);
        for (int f = 1; f <= 2229; ++f) ASSERT_EQ(all.count(f), 1u) << f;
    }
    EXPECT_EQ(shard_frames(10, 20, {2, 4}), (std::vector<int>{11, 15, 19}));
    EXPECT_TRUE(shard_frames(1, 2, {3, 3}).empty());
}

TEST(Shard, ParsesKOverN) {
    Shard s = parse_shard("3/4");
    EXPECT_EQ(s.index, 3);
    EXPECT_EQ(s.count, 4);
    for (const char* bad : {"0/4", "5/4", "3", "a/b", "3/0", "-1/4", "1/4/5"})
        EXPECT_THROW(parse_shard(bad), Error) << bad;
    try {
        parse_shard("5/4");
        FAIL();
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), "shard '5/4': expected K/N with 1 <= K <= N");
    }
}

TEST(Shard, FromSlurmArrayVariables) {
    ::unsetenv("SLURM_ARRAY_TASK_ID");
    ::unsetenv("SLURM_ARRAY_TASK_COUNT");
    ::unsetenv("SLURM_ARRAY_TASK_MIN");
    EXPECT_FALSE(shard_from_environment());
    ::setenv("SLURM_ARRAY_TASK_ID", "2", 1);
    ::setenv("SLURM_ARRAY_TASK_COUNT", "3", 1);
    auto s = shard_from_environment();
    ASSERT_TRUE(s);
    EXPECT_EQ(s->index, 2);
    EXPECT_EQ(s->count, 3);
    ::setenv("SLURM_ARRAY_TASK_ID", "5", 1);  // --array=4-6
    ::setenv("SLURM_ARRAY_TASK_MIN", "4", 1);
    s = shard_from_environment();
    ASSERT_TRUE(s);
    EXPECT_EQ(s->index, 2);
    ::setenv("SLURM_ARRAY_TASK_ID", "9", 1);
    EXPECT_THROW(shard_from_environment(), Error);
    ::unsetenv("SLURM_ARRAY_TASK_ID");
    ::unsetenv("SLURM_ARRAY_TASK_COUNT");
    ::unsetenv("SLURM_ARRAY_TASK_MIN");
}

TEST(Batch, JobsAndThreadsGiveByteIdenticalFrames) {
    TempDir dir("jobs");
    write_frames(dir.path / "in", 1, 12);
    std::vector<std::pair<int, int>> configs = {{1, 1}, {2, 0}, {3, 2}};
    for (auto [jobs, threads] : configs) {
        BatchOptions o = small_options(dir.path / "in", dir.path / ("out" + std::to_string(jobs)));
        o.first = 1;
        o.last = 12;
        o.jobs = jobs;
        o.render.settings.threads = threads;
        BatchReport r = run_batch(o);
        ASSERT_EQ(r.rendered, 12);
        ASSERT_EQ(r.failed, 0);
    }
    for (int f = 1; f <= 12; ++f) {
        char name[32];
        std::snprintf(name, sizeof name, "keys_%06d.png", f);
        std::string a = bytes(dir.path / "out1" / name);
        ASSERT_FALSE(a.empty());
        EXPECT_EQ(a, bytes(dir.path / "out2" / name)) << name;
        EXPECT_EQ(a, bytes(dir.path / "out3" / name)) << name;
    }
    // Frames differ from each other (the camera moves).
    EXPECT_NE(bytes(dir.path / "out1/keys_000001.png"), bytes(dir.path / "out1/keys_000012.png"));
}

TEST(Batch, BadFramesAreReportedAndTheRestRendered) {
    TempDir dir("bad");
    write_frames(dir.path / "in", 1, 5);
    std::ofstream(dir.path / "in/keys_000002.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n";
    fs::remove(dir.path / "in/keys_000004.obj");
    BatchOptions o = small_options(dir.path / "in", dir.path / "out");
    o.first = 1;
    o.last = 5;
    BatchReport r = run_batch(o);
    EXPECT_EQ(r.rendered, 3);
    ASSERT_EQ(r.failed, 2);
    EXPECT_EQ(r.failures[0].frame, 2);
    EXPECT_NE(r.failures[0].message.find("keys_000002.obj:4: face vertex index 9 out of range"),
              std::string::npos)
        << r.failures[0].message;
    EXPECT_EQ(r.failures[1].frame, 4);
    EXPECT_NE(r.failures[1].message.find("no input file for frame 4"), std::string::npos);
    EXPECT_FALSE(fs::exists(dir.path / "out/keys_000002.png"));
    EXPECT_TRUE(fs::exists(dir.path / "out/keys_000005.png"));
}

TEST(Batch, FailFastStopsEarly) {
    TempDir dir("failfast");
    write_frames(dir.path / "in", 1, 30);
    std::ofstream(dir.path / "in/keys_000001.obj") << "f 1 2 3\n";
    BatchOptions o = small_options(dir.path / "in", dir.path / "out");
    o.first = 1;
    o.last = 30;
    o.jobs = 1;
    o.fail_fast = true;
    BatchReport r = run_batch(o);
    EXPECT_EQ(r.failed, 1);
    EXPECT_LT(r.rendered, 3);  // at most the frame already loaded ahead
    EXPECT_TRUE(r.cancelled);
}

TEST(Batch, ResumeSkipsValidFramesAndRedoesBrokenOnes) {
    TempDir dir("resume");
    write_frames(dir.path / "in", 1, 6);
    BatchOptions o = small_options(dir.path / "in", dir.path / "out");
    o.first = 1;
    o.last = 6;
    ASSERT_EQ(run_batch(o).rendered, 6);
    std::string good = bytes(dir.path / "out/keys_000003.png");
    // Truncate one frame and delete another.
    std::string cut = good.substr(0, good.size() / 2);
    write_file_atomic(dir.path / "out/keys_000003.png",
                      std::span(reinterpret_cast<const std::uint8_t*>(cut.data()), cut.size()));
    fs::remove(dir.path / "out/keys_000005.png");
    o.resume = true;
    BatchReport r = run_batch(o);
    EXPECT_EQ(r.skipped, 4);
    EXPECT_EQ(r.rendered, 2);
    EXPECT_EQ(bytes(dir.path / "out/keys_000003.png"), good);
}

TEST(Batch, CustomPatternsAndAovs) {
    TempDir dir("pattern");
    fs::create_directories(dir.path / "in");
    std::ofstream(dir.path / "in/frame.mtl") << "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n";
    std::ofstream(dir.path / "in/shot-7.obj") << frame_obj(7);
    BatchOptions o = small_options(dir.path / "in", dir.path / "out");
    o.first = o.last = 7;
    o.input_pattern = "shot-%d.obj";
    o.output_pattern = "img%04d.png";
    o.render.aov_dir = dir.path / "aov";
    BatchReport r = run_batch(o);
    ASSERT_EQ(r.rendered, 1) << (r.failures.empty() ? "" : r.failures[0].message);
    EXPECT_TRUE(is_valid_png(dir.path / "out/img0007.png"));
    EXPECT_TRUE(is_valid_png(dir.path / "aov/img0007_depth.png"));
}

TEST(Batch, WholeRunErrors) {
    TempDir dir("errors");
    BatchOptions o = small_options(dir.path, dir.path / "out");
    o.first = 5;
    o.last = 4;
    EXPECT_THROW(run_batch(o), Error);
    o.first = 1;
    o.output_dir = "/proc/toonray-cannot-write";
    EXPECT_THROW(run_batch(o), Error);
}

TEST(Batch, CancelStopsTakingFrames) {
    TempDir dir("cancel");
    write_frames(dir.path / "in", 1, 20);
    std::atomic<bool> cancel{true};
    BatchOptions o = small_options(dir.path / "in", dir.path / "out");
    o.first = 1;
    o.last = 20;
    o.cancel = &cancel;
    BatchReport r = run_batch(o);
    EXPECT_TRUE(r.cancelled);
    EXPECT_EQ(r.rendered, 0);
}

namespace {
// Records the peak resident set size after given frames.
struct PeakRss : BatchObserver {
    int done = 0;
    long after_100 = -1, after_2000 = -1;
    void frame_done(int, FrameStatus status, const std::string& message) override {
        ASSERT_EQ(status, FrameStatus::Rendered) << message;
        ++done;
        if (done == 100) after_100 = status_kib("VmHWM:");
        if (done == 2000) after_2000 = status_kib("VmHWM:");
    }
    void warning(int, const std::string&) override {}
};
}  // namespace

TEST(Batch, MemoryStaysFlatOverThousandsOfFrames) {
    // The seed leaked until it crashed after ~750 frames. Peak RSS after frame 2000 must be
    // within 2 MiB of the peak after frame 100.
#if defined(__SANITIZE_ADDRESS__) || TOONRAY_HAS_ASAN
    // AddressSanitizer keeps freed memory in quarantine (256 MB), so RSS grows by design; its
    // leak checker covers this test's purpose in that build (scripts/sanitize.sh).
    GTEST_SKIP() << "peak RSS is not meaningful under AddressSanitizer";
#endif
    TempDir dir("memory");
    write_frames(dir.path / "in", 1, 2100);
    BatchOptions o = small_options(dir.path / "in", dir.path / "out");
    o.first = 1;
    o.last = 2100;
    o.jobs = 1;
    PeakRss rss;
    BatchReport r = run_batch(o, &rss);
    ASSERT_EQ(r.rendered, 2100);
    ASSERT_GT(rss.after_100, 0);
    std::printf("peak RSS after frame 100: %ld KiB, after frame 2000: %ld KiB (%.1f frames/s)\n",
                rss.after_100, rss.after_2000, r.rendered / r.seconds);
    EXPECT_LE(rss.after_2000 - rss.after_100, 2048);
}
