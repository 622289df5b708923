#include "toonray/anim/piano_movie.h"

#include <gtest/gtest.h>

#include <cmath>

#include <filesystem>
#include <fstream>

#include "toonray/anim/batch.h"
#include "toonray/io/png.h"
#include "toonray/piano/piano_animation.h"
#include "support/test_support.h"

using namespace toonray;
namespace fs = std::filesystem;

namespace {

using toonray::test_support::TempDir;

std::string bytes(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(f), {}};
}

}  // namespace

TEST(PianoMovie, DemoAssetsAreBuiltIn) {
    Score score = load_demo_score();
    EXPECT_EQ(score.notes.size(), 2621u);
    CameraPath path = load_demo_camera_path();
    EXPECT_FALSE(path.empty());
}

TEST(PianoMovie, FrameCountCoversTheLength) {
    EXPECT_EQ(frame_count(30.0, 24.0), 720);
    EXPECT_EQ(frame_count(0.5, 24.0), 12);
    EXPECT_EQ(frame_count(0.51, 24.0), 13);
}

TEST(PianoMovie, ExportedObjFramesRenderIdenticallyWithBatch) {
    // The seed's path (one OBJ per frame, rendered by batch) and the in-memory path (posing
    // and refitting) must give the same bytes. Frames from the middle of the piece, where keys,
    // roll holes, pedals and camera all move.
    TempDir dir("export");
    Score score = load_demo_score();
    CameraPath path = load_demo_camera_path();
    PianoMovieOptions options;
    options.start = 12.0;
    options.seconds = 0.25;
    options.fps = 24.0;
    options.render.settings.width = 320;
    options.render.settings.height = 180;
    options.output_dir = dir.path / "memory";
    PianoMovieReport memory = render_piano_movie(score, path, options);
    ASSERT_EQ(memory.batch.rendered, 6);
    EXPECT_GT(memory.triangles, 30000u);
    EXPECT_LT(memory.triangles, 60000u);

    options.export_obj_dir = dir.path / "frames";
    PianoMovieReport exported = render_piano_movie(score, path, options);
    ASSERT_EQ(exported.batch.rendered, 6);
    ASSERT_TRUE(fs::exists(dir.path / "frames/keys_000001.obj"));

    BatchOptions batch;
    batch.name = "keys";
    batch.first = 1;
    batch.last = 6;
    batch.input_dir = dir.path / "frames";
    batch.output_dir = dir.path / "batch";
    batch.render = options.render;
    BatchReport r = run_batch(batch);
    ASSERT_EQ(r.rendered, 6) << (r.failures.empty() ? "" : r.failures[0].message);
    for (int f = 1; f <= 6; ++f) {
        char name[32];
        std::snprintf(name, sizeof name, "keys_%06d.png", f);
        std::string a = bytes(dir.path / "memory" / name);
        ASSERT_FALSE(a.empty());
        EXPECT_EQ(a, bytes(dir.path / "batch" / name)) << name;
    }
    EXPECT_NE(bytes(dir.path / "memory/keys_000001.png"),
              bytes(dir.path / "memory/keys_000006.png"));
}

TEST(PianoMovie, JobsGiveIdenticalFrames) {
    TempDir dir("jobs");
    Score score = load_demo_score();
    CameraPath path = load_demo_camera_path();
    PianoMovieOptions options;
    options.start = 3.0;
    options.seconds = 4.0 / 24.0;
    options.render.settings.width = 160;
    options.render.settings.height = 90;
    for (int jobs : {1, 2}) {
        options.jobs = jobs;
        options.output_dir = dir.path / std::to_string(jobs);
        ASSERT_EQ(render_piano_movie(score, path, options).batch.rendered, 4);
    }
    for (int f = 1; f <= 4; ++f) {
        std::string name = "keys_00000" + std::to_string(f) + ".png";
        EXPECT_EQ(bytes(dir.path / "1" / name), bytes(dir.path / "2" / name)) << name;
    }
}

TEST(PianoMovie, InstancedKeysGiveTheSameFramesForAnyJobCountAndDifferFromFlatKeysSlightly) {
    // Keys moving (12 s into the piece): with the keys as instances, frames are posed by
    // moving 88 transforms, so a job reusing its scene must give what a fresh one gives, and
    // the pictures must stay those of the flat keys but for samples along edges.
    TempDir dir("instanced");
    Score score = load_demo_score();
    CameraPath path = load_demo_camera_path();
    PianoMovieOptions options;
    options.start = 12.0;
    options.seconds = 4.0 / 24.0;
    options.render.settings.width = 320;
    options.render.settings.height = 180;
    options.output_dir = dir.path / "flat";
    ASSERT_EQ(render_piano_movie(score, path, options).batch.rendered, 4);
    options.instanced_keys = true;
    for (int jobs : {1, 2}) {
        options.jobs = jobs;
        options.output_dir = dir.path / std::to_string(jobs);
        ASSERT_EQ(render_piano_movie(score, path, options).batch.rendered, 4);
    }
    for (int f = 1; f <= 4; ++f) {
        const std::string name = "keys_00000" + std::to_string(f) + ".png";
        EXPECT_EQ(bytes(dir.path / "1" / name), bytes(dir.path / "2" / name)) << name;
        const DecodedPng flat = read_png(dir.path / "flat" / name);
        const DecodedPng keyed = read_png(dir.path / "1" / name);
        ASSERT_EQ(flat.width, keyed.width);
        ASSERT_EQ(flat.height, keyed.height);
        int differ = 0;
        for (int y = 0; y < flat.height; ++y)
            for (int x = 0; x < flat.width; ++x) differ += flat.rgb(x, y) != keyed.rgb(x, y);
        EXPECT_LT(differ * 100, flat.width * flat.height) << name << ": " << differ;
    }
}

TEST(PianoMovie, BadOptionsAreErrors) {
    Score score = load_demo_score();
    CameraPath path = load_demo_camera_path();
    PianoMovieOptions options;
    options.output_dir = fs::temp_directory_path();
    auto error_of = [&] {
        try {
            render_piano_movie(score, path, options);
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("(no error)");
    };
    options.fps = 0;
    EXPECT_EQ(error_of(), "frame rate 0 fps: must be in (0, 1000]");
    options.fps = 24;
    options.start = -1;
    EXPECT_EQ(error_of(), "start time -1 s: must not be negative");
    options.start = 1e6;  // past the end of the music
    EXPECT_EQ(
        error_of(),
        "nothing to render: the length is zero (an empty score, or a start time past its end)");
    options.start = 0;
    options.name = "a/b";
    EXPECT_EQ(error_of(), "frame name 'a/b': must be a plain file name");
}

TEST(PianoMovie, EveryOnsetInTheFirstThirtySecondsShowsItsKeyDown) {
    // The sync check of the demo: for every note starting in the first 30 s of the demo score,
    // the first 24 fps frame at or after its onset shows its key down, and the pose given to the
    // mesh carries that depth (piano_pose_test checks that a key angle moves the key's vertices).
    Score score = load_demo_score();
    PianoPlayback play(score);
    const double fps = 24.0;
    int checked = 0;
    for (const Note& n : score.notes) {
        if (n.start >= 30.0) continue;
        int frame = static_cast<int>(std::ceil(n.start * fps - 1e-9)) + 1;  // frame 1 shows t = 0
        double t = (frame - 1) / fps;
        ASSERT_GE(t, n.start - 1e-9);
        ASSERT_LT(t, n.start + 1.0 / fps);
        EXPECT_TRUE(play.is_key_down(n.key, t))
            << "note " << n.key << " at " << n.start << " s, frame " << frame;
        PianoPose pose = play.pose_at(t);
        EXPECT_GE(pose.key_angle[static_cast<std::size_t>(n.key - 21)],
                  kKeyDownDepth * play.settings().key_dip_angle);
        ++checked;
    }
    EXPECT_GT(checked, 250);
    std::printf("checked %d onsets in the first 30 s\n", checked);
}
