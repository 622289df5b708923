// The limits (core/limits.h) and the readers that enforce them, at the library level.

#include <gtest/gtest.h>

#include <sys/stat.h>

#include <cmath>
#include <fmt/format.h>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <string>

#include "robustness_util.h"
#include "toonray/anim/batch.h"
#include "toonray/anim/camera_path.h"
#include "toonray/anim/piano_movie.h"
#include "toonray/core/error.h"
#include "toonray/core/limits.h"
#include "toonray/core/parallel.h"
#include "toonray/io/file.h"
#include "toonray/io/png.h"
#include "toonray/scene/obj_loader.h"
#include "toonray/score/midi.h"
#include "toonray/score/note_script.h"

using namespace toonray;
using robustness::data;

namespace {

/// The limit a LimitError names, or nullopt when `f` throws something else or nothing.
std::optional<Limit> limit_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const LimitError& e) {
        return e.limit();
    } catch (const Error&) {
    }
    return std::nullopt;
}

std::string error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

/// Sets process-wide limits for one test and restores them after.
struct ScopedLimits {
    Limits saved = limits();
    explicit ScopedLimits(const std::function<void(Limits&)>& change) {
        Limits l = saved;
        change(l);
        set_limits(l);
    }
    ~ScopedLimits() { set_limits(saved); }
};

ObjOptions obj_options(const std::function<void(Limits&)>& change) {
    ObjOptions o;
    o.load_materials = false;
    change(o.limits);
    return o;
}

Scene parse_with(std::string_view text, const ObjOptions& o) {
    Scene scene;
    Warnings w;
    parse_obj(text, "limits.obj", scene, w, o);
    return scene;
}

}  // namespace

TEST(LimitValues, CountsAndSizesParseWithSuffixes) {
    EXPECT_EQ(parse_count("50000000"), 50'000'000u);
    EXPECT_EQ(parse_count("50M"), 50'000'000u);
    EXPECT_EQ(parse_count("2.5k"), 2500u);
    EXPECT_EQ(parse_count("1G"), 1'000'000'000u);
    EXPECT_EQ(parse_bytes("512M"), 512 * kMiB);
    EXPECT_EQ(parse_bytes("8GiB"), 8 * kGiB);
    EXPECT_EQ(parse_bytes("64KB"), 64 * kKiB);
    EXPECT_EQ(parse_bytes("100"), 100u);
    EXPECT_EQ(parse_bytes("1e30"), UINT64_MAX);
    for (const char* bad : {"", "0", "-5", "nan", "inf", "5X", "5MM", "M", "0.1", "1 M"}) {
        EXPECT_THROW((void)parse_count(bad), Error) << bad;
        EXPECT_THROW((void)parse_bytes(bad), Error) << bad;
    }
    EXPECT_EQ(error_of([] { (void)parse_bytes("lots"); }),
              "expected a positive size such as 512M or 8G, got 'lots'");
}

TEST(LimitValues, DefaultsAreDocumented) {
    const Limits d;
    EXPECT_EQ(d.max_input_bytes, 2 * kGiB);
    EXPECT_EQ(d.max_line_bytes, 16 * kMiB);
    EXPECT_EQ(d.max_vertices, 100'000'000u);
    EXPECT_EQ(d.max_triangles, 50'000'000u);
    EXPECT_EQ(d.max_image_pixels, 8192u * 8192u);
    EXPECT_EQ(d.max_frames, 10'000'000u);
    EXPECT_GT(d.max_memory, 0u);
    EXPECT_EQ(format_bytes(1536 * kMiB), "1.5 GiB");
    EXPECT_EQ(format_bytes(100), "100 bytes");
}

TEST(LimitValues, MemoryEstimatesSaturateInsteadOfOverflowing) {
    RenderSettings huge;
    huge.width = huge.height = 2147483647;
    huge.lines.mode = LineMode::Ink;
    huge.layers = true;
    EXPECT_EQ(frame_buffer_bytes(huge), UINT64_MAX);
    EXPECT_EQ(scene_bytes(UINT64_MAX, UINT64_MAX), UINT64_MAX);
    // Measured with feature images: 37 bytes a pixel above the program's own 14 MB.
    FrameOptions hd;
    hd.settings.width = 1280;
    hd.settings.height = 720;
    hd.aov_dir = "aov";
    EXPECT_GT(frame_bytes(hd), 1280u * 720u * 37u);
}

TEST(LimitValues, MemoryOverTheLimitSaysWhatAndHowMuch) {
    ScopedLimits l([](Limits& x) { x.max_memory = 64 * kMiB; });
    check_memory(64 * kMiB, "the scene");
    EXPECT_EQ(error_of([] { check_memory(3 * kGiB, "the scene"); }),
              "the scene needs about 3.0 GiB of memory, more than the limit of 64 MiB");
    EXPECT_EQ(limit_of([] { check_memory(64 * kMiB + 1, "the scene"); }), Limit::Memory);
}

// --- read_file ---------------------------------------------------------------------------

TEST(ReadFile, RefusesFilesOverTheLimitBeforeReading) {
    TempDir dir("limits_read");
    dir.write("big.obj", std::string(1000, 'x'));
    const auto p = (dir / "big.obj").string();
    EXPECT_EQ(read_file(dir / "big.obj", 1000).size(), 1000u);
    EXPECT_EQ(error_of([&] { read_file(dir / "big.obj", 999); }),
              p + ": 1000 bytes, more than the input size limit of 999 bytes");
    EXPECT_EQ(limit_of([&] { read_file(dir / "big.obj", 999); }), Limit::InputBytes);
}

TEST(ReadFile, RefusesDirectoriesDevicesAndFifosWithoutBlocking) {
    TempDir dir("limits_special");
    EXPECT_EQ(error_of([&] { read_file(dir.path); }),
              dir.path.string() + ": is a directory, not a file");
    EXPECT_EQ(
        error_of([] { read_file("/dev/zero"); }),
        "/dev/zero: not a regular file (a device, FIFO or socket); toonray reads inputs from regular files only");
    // A FIFO with no writer: opening it for reading would block forever.
    ASSERT_EQ(::mkfifo((dir / "fifo").c_str(), 0600), 0);
    EXPECT_EQ(
        error_of([&] { read_file(dir / "fifo"); }),
        (dir / "fifo").string() +
            ": not a regular file (a device, FIFO or socket); toonray reads inputs from regular files only");
}

TEST(ReadFile, ReadsProcFilesThatReportSizeZero) {
    std::string status = read_file("/proc/self/status");
    EXPECT_NE(status.find("Name:"), std::string::npos);
    EXPECT_EQ(limit_of([] { read_file("/proc/self/status", 16); }), Limit::InputBytes);
}

// --- OBJ ---------------------------------------------------------------------------------

TEST(ObjLimits, LineLength) {
    const ObjOptions o = obj_options([](Limits& l) { l.max_line_bytes = 64; });
    EXPECT_EQ(parse_with("v 0 0 0\n# " + std::string(62, 'x') + "\n", o).positions.size(), 1u);
    EXPECT_EQ(error_of([&] { parse_with("v 0 0 0\n# " + std::string(63, 'x') + "\n", o); }),
              "limits.obj:2: line longer than the limit of 64 bytes");
    EXPECT_EQ(limit_of([&] { parse_with("v 0 0 0\n# " + std::string(63, 'x') + "\n", o); }),
              Limit::LineBytes);
    // Continuations count as one line.
    EXPECT_EQ(error_of([&] {
                  parse_with(
                      "v 0 0 0\nf 1 \\\n" + std::string(30, ' ') + "\\\n" + std::string(40, ' '),
                      o);
              }),
              "limits.obj:2: line (with its continuations) longer than the limit of 64 bytes");
}

TEST(ObjLimits, VertexAndTriangleCounts) {
    const ObjOptions o = obj_options([](Limits& l) {
        l.max_vertices = 4;
        l.max_triangles = 2;
    });
    const std::string quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";
    EXPECT_EQ(parse_with(quad + "f 1 2 3 4\n", o).triangle_count(), 2u);
    EXPECT_EQ(error_of([&] { parse_with(quad + "v 2 2 2\n", o); }),
              "limits.obj:5: more than 4 vertices ('v') (the limit)");
    EXPECT_EQ(limit_of([&] { parse_with(quad + "v 2 2 2\n", o); }), Limit::Vertices);
    EXPECT_EQ(error_of([&] {
                  parse_with(quad + "vn 0 0 1\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\n", o);
              }),
              "limits.obj:9: more than 4 normals ('vn') (the limit)");
    EXPECT_EQ(limit_of([&] {
                  parse_with(quad + "vn 0 0 1\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\n", o);
              }),
              Limit::Vertices);
    EXPECT_EQ(error_of([&] { parse_with(quad + "f 1 2 3 4\nf 1 2 3\n", o); }),
              "limits.obj:6: more than 2 triangles (the limit)");
    EXPECT_EQ(limit_of([&] { parse_with(quad + "f 1 2 3 4\nf 1 2 3\n", o); }), Limit::Triangles);
    // A limit can never be raised past what 32-bit indices address.
    ObjOptions big = obj_options([](Limits& l) { l.max_triangles = UINT64_MAX; });
    EXPECT_EQ(parse_with(quad + "f 1 2 3\n", big).triangle_count(), 1u);
}

TEST(ObjLimits, MemoryEstimateIsCheckedAsTheSceneGrows) {
    const ObjOptions o = obj_options([](Limits& l) { l.max_memory = 2 * kMiB; });
    std::string text;
    for (int i = 0; i < 100'000; ++i) text += "v 0 0 0\n";
    const std::string e = error_of([&] { parse_with(text, o); });
    EXPECT_EQ(
        e.rfind("limits.obj:65536: the scene so far (65535 vertices, 0 triangles) needs about ", 0),
        0u)
        << e;
    EXPECT_TRUE(e.ends_with("more than the limit of 2.0 MiB")) << e;
    EXPECT_EQ(limit_of([&] { parse_with(text, o); }), Limit::Memory);
    // Memory reserved for frame buffers counts too.
    const ObjOptions reserved = obj_options([](Limits& l) {
        l.max_memory = 64 * kMiB;
        l.reserved_memory = 64 * kMiB;
    });
    EXPECT_NE(
        error_of([&] { parse_with("v 0 0 0\n", reserved); }).find("limits.obj: the scene so far"),
        std::string::npos);
}

TEST(ObjLimits, ManyWarningsAreCappedWithACount) {
    std::string text;
    for (int i = 0; i < 500; ++i) text += "bogus" + std::to_string(i) + " 1\n";
    for (int i = 0; i < 500; ++i) text += "usemtl m" + std::to_string(i) + "\n";
    Scene scene;
    Warnings w;
    parse_obj(text, "warn.obj", scene, w);
    ASSERT_EQ(w.size(), 101u);
    EXPECT_EQ(w.front(), "warn.obj:1: unknown statement 'bogus0' ignored");
    EXPECT_EQ(w.back(), "warn.obj: 900 more warnings not shown");
}

TEST(ObjLimits, ManyMaterialLookupsStayLinear) {
    // 20000 materials and 20000 usemtl lines: linear search made this 4e8 string compares.
    TempDir dir("limits_materials");
    std::string mtl, obj = "mtllib many.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n";
    for (int i = 0; i < 20'000; ++i) {
        mtl += "newmtl m" + std::to_string(i) + "\nKd 1 0 0\n";
        obj += "usemtl m" + std::to_string(i) + "\nf 1 2 3\n";
    }
    dir.write("many.mtl", mtl);
    dir.write("many.obj", obj);
    Scene scene;
    Warnings w;
    load_obj(dir / "many.obj", scene, w);
    EXPECT_TRUE(w.empty());
    ASSERT_EQ(scene.triangle_count(), 20'000u);
    EXPECT_EQ(scene.materials[scene.tri_material.back()].name, "m19999");
}

TEST(ObjLimits, RepeatedMaterialLibrariesAreReadOnce) {
    TempDir dir("limits_mtllib");
    dir.write("a.mtl", "newmtl red\nKd 1 0 0\n");
    std::string obj = "mtllib";
    for (int i = 0; i < 10'000; ++i) obj += " a.mtl ./a.mtl";
    obj += "\nmtllib a.mtl\nusemtl red\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    dir.write("a.obj", obj);
    Scene scene;
    Warnings w;
    load_obj(dir / "a.obj", scene, w);
    EXPECT_EQ(scene.materials.size(), 2u);
    EXPECT_EQ(scene.tri_material[0], 1u);
}

TEST(ObjLimits, IndicesPastTwoToTheThirtyOneAreOutOfRange) {
    for (const char* index :
         {"2147483648", "4294967296", "4294967297", "-4294967296", "9223372036854775807"}) {
        const std::string e = error_of([&] {
            parse_with(std::string("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 ") + index + "\n",
                       ObjOptions{});
        });
        EXPECT_EQ(e, std::string("limits.obj:4: face vertex index ") + index +
                         " out of range (3 vertices defined so far)");
    }
}

TEST(ObjLimits, AMillionVertexFaceLoads) {
    // One polygon with 10^6 corners: a fan of 999,998 triangles. Its line is ~7 MB, within the
    // 16 MiB line limit.
    constexpr int n = 1'000'000;
    std::string text;
    text.reserve(40 * static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
        const double a = 6.283185307179586 * i / n;
        text += fmt::format("v {:.6f} {:.6f} 0\n", std::cos(a), std::sin(a));
    }
    text += "f";
    for (int i = 1; i <= n; ++i) text += fmt::format(" {}", i);
    text += "\n";
    Scene scene;
    Warnings w;
    parse_obj(text, "million.obj", scene, w);
    EXPECT_EQ(scene.triangle_count(), static_cast<std::size_t>(n - 2));
    ObjOptions small;
    small.limits.max_triangles = 1000;
    EXPECT_EQ(error_of([&] { parse_obj(text, "million.obj", scene, w, small); }),
              "million.obj:1000001: more than 1000 triangles (the limit)");
}

// --- PNG, frames, scores ------------------------------------------------------------------

TEST(PngLimits, HeaderAnnouncingAHugeImageIsRefusedBeforeAllocating) {
    // A valid 1x1 PNG whose IHDR claims 100000 x 100000 (CRC fixed up): libpng would accept the
    // header, and decoding would allocate 30 GB.
    std::string png =
        robustness::slurp(std::filesystem::path(TOONRAY_FUZZ_DIR) / "corpus" / "png" / "rgb.png");
    auto be32 = [&](std::size_t at, std::uint32_t v) {
        for (int i = 0; i < 4; ++i) png[at + i] = static_cast<char>(v >> (24 - 8 * i));
    };
    be32(16, 100000);
    be32(20, 100000);
    // CRC over "IHDR" + 13 bytes of data, at offset 29.
    std::uint32_t crc = 0xFFFFFFFFu;
    for (std::size_t i = 12; i < 29; ++i) {
        crc ^= static_cast<std::uint8_t>(png[i]);
        for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
    be32(29, ~crc);
    const std::span bytes(reinterpret_cast<const std::uint8_t*>(png.data()), png.size());
    EXPECT_EQ(error_of([&] { decode_png(bytes, "huge.png"); }),
              "huge.png: a 100000x100000 PNG has more pixels than the limit of 67108864");
    EXPECT_EQ(limit_of([&] { decode_png(bytes, "huge.png"); }), Limit::ImagePixels);
}

TEST(FrameLimits, PlanChecksPixelsAndMemoryAndFitsJobsToMemory) {
    FrameOptions o;
    RenderSettings& s = o.settings;
    s.width = 1920;
    s.height = 1080;
    {
        ScopedLimits l([](Limits& x) { x.max_memory = 8 * kGiB; });
        FramePlan p = plan_frame_jobs(o, 3, 100);
        EXPECT_EQ(p.jobs, 3);
        EXPECT_EQ(plan_frame_jobs(o, 8, 2).jobs, 2);  // never more jobs than frames
    }
    {
        // Room for two frames: an automatic job count takes two, an explicit 4 is an error.
        const std::uint64_t frame = frame_bytes(o);
        ScopedLimits l([&](Limits& x) { x.max_memory = 2 * frame + frame / 2; });
        EXPECT_EQ(plan_frame_jobs(o, 0, 100).jobs, std::min(2, hardware_threads()));
        EXPECT_EQ(error_of([&] {
                      plan_frame_jobs(o, 4, 100);
                  }).rfind("4 frames at once (a 1920x1080 frame each) needs about ", 0),
                  0u);
        EXPECT_EQ(limit_of([&] { plan_frame_jobs(o, 4, 100); }), Limit::Memory);
    }
    s.width = 10000;
    s.height = 10000;
    EXPECT_EQ(error_of([&] { plan_frame_jobs(o, 1, 1); }),
              "image size 10000x10000: 100000000 pixels, more than the limit of 67108864");
    try {
        plan_frame_jobs(o, 1, 1);
        FAIL();
    } catch (const LimitError& e) {
        EXPECT_EQ(e.limit(), Limit::ImagePixels);
    }
}

// Where one frame fits but the frames in flight need more than 2^64 bytes, the total must
// saturate and be refused, not wrap around to a small number that fits.
TEST(FrameLimits, FramesWhoseTotalPassesTwoToTheSixtyFourAreRefused) {
    FrameOptions o;
    o.settings.width = 1 << 23;
    o.settings.height = 1 << 23;
    const std::uint64_t frame = frame_bytes(o);
    const std::uint64_t jobs = std::numeric_limits<std::uint64_t>::max() / frame + 1;
    ASSERT_GT(jobs, 1u);
    ASSERT_LE(jobs, 1u << 16);  // plan_frame_jobs takes up to 65536 frames at once
    ScopedLimits l([&](Limits& x) {
        x.max_image_pixels = std::numeric_limits<std::uint64_t>::max();
        x.max_memory = frame;
    });
    EXPECT_EQ(plan_frame_jobs(o, 1, 1 << 16).jobs, 1);
    const int requested = static_cast<int>(jobs);
    EXPECT_EQ(limit_of([&] { plan_frame_jobs(o, requested, 1 << 16); }), Limit::Memory);
    EXPECT_EQ(error_of([&] { plan_frame_jobs(o, requested, 1 << 16); })
                  .rfind(fmt::format("{} frames at once (a 8388608x8388608 frame each) needs about "
                                     "16 EiB of memory",
                                     jobs),
                         0),
              0u);
}

TEST(FrameLimits, FrameRangesAreCheckedBeforeAllocating) {
    EXPECT_EQ(error_of([] {
                  shard_frames(0, 2147483647, {1, 1});
              }),
              "frame range 0 2147483647: 2147483648 frames is more than the limit of 10000000");
    EXPECT_EQ(shard_frames(0, 2147483647, {1, 1000}).size(),
              2147484u);  // within the limit once sharded
    EXPECT_EQ(error_of([] {
                  shard_frames(5, 4, {1, 1});
              }),
              "frame range 5 4: the first frame is after the last");
}

TEST(FrameLimits, FrameCountSaturatesInsteadOfOverflowing) {
    EXPECT_EQ(frame_count(30.0, 24.0), 720);
    EXPECT_EQ(frame_count(1e300, 1000.0), 2147483647);
    EXPECT_EQ(frame_count(-5.0, 24.0), 0);
    EXPECT_EQ(frame_count(std::numeric_limits<double>::quiet_NaN(), 24.0), 0);
}

TEST(ScoreLimits, NoteScriptNoteCount) {
    ScopedLimits l([](Limits& x) { x.max_notes = 5; });
    EXPECT_EQ(parse_note_script("E:w1,w2,w3\nE:w4,w5\n", "n.notes").notes.size(), 5u);
    EXPECT_EQ(error_of([] { (void)parse_note_script("E:w1,w2,w3\nE:w4,w5,w6\n", "n.notes"); }),
              "n.notes:2: more than 5 notes (the limit)");
}

TEST(ScoreLimits, MidiEventAndTrackCounts) {
    const std::string good = robustness::slurp(data("good.mid"));
    const std::span bytes(reinterpret_cast<const std::uint8_t*>(good.data()), good.size());
    MidiLimits few;
    few.max_events = 2;
    EXPECT_EQ(error_of([&] { (void)read_midi(bytes, "good.mid", nullptr, few); }),
              "good.mid: byte 30: more than 2 events (the limit)");
    MidiLimits one_track;
    one_track.max_tracks = 0;
    EXPECT_EQ(error_of([&] { (void)read_midi(bytes, "good.mid", nullptr, one_track); }),
              "good.mid: byte 10: 1 tracks exceed the limit of 0");
}

TEST(CameraPathLimits, KeyCount) {
    ScopedLimits l([](Limits& x) { x.max_camera_keys = 2; });
    const std::string two = "key 0 eye 0 1 5 target 0 0 0\nkey 1 eye 5 1 0 target 0 0 0\n";
    EXPECT_EQ(parse_camera_path(two, "p.campath").keys().size(), 2u);
    EXPECT_EQ(error_of([&] {
                  (void)parse_camera_path(two + "key 2 eye 0 1 -5 target 0 0 0\n", "p.campath");
              }),
              "p.campath:3: more than 2 camera keys (the limit)");
}
