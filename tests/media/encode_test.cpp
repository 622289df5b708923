#include "toonray/media/encode.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fmt/format.h>
#include <string>
#include <unistd.h>

#include "toonray/core/error.h"
#include "toonray/io/file.h"
#include "toonray/io/png.h"
#include "toonray/media/process.h"
#include "toonray/media/wav.h"
#include "support/test_support.h"

namespace toonray {
namespace {

using toonray::test_support::error_of;
using toonray::test_support::TempDir;

namespace fs = std::filesystem;

/// Writes frames first .. first + count - 1 as name_pattern (fmt, e.g. "frame_{:04d}.png"),
/// each a different colour so the encoder has something to do.
void write_frames(const fs::path& dir, const std::string& name_pattern, int first, int count,
                  int width = 64, int height = 48) {
    fs::create_directories(dir);
    for (int i = first; i < first + count; ++i) {
        ImageRgb8 img(width, height, Rgb8{static_cast<std::uint8_t>(20 * (i % 12)), 90, 200});
        for (int y = 0; y < height; ++y)  // a diagonal line, as an edge
            img(std::min(width - 1, (y + i) % width), y) = Rgb8{0, 0, 0};
        write_png(dir / fmt::vformat(name_pattern, fmt::make_format_args(i)), img);
    }
}

/// A 440 Hz stereo tone of `seconds`, silent before `onset`.
fs::path write_tone(const fs::path& path, double seconds, double onset = 0.0) {
    WavAudio a;
    a.sample_rate = 44100;
    a.channels = 2;
    const int n = static_cast<int>(std::lround(seconds * a.sample_rate));
    for (int i = 0; i < n; ++i) {
        const double t = static_cast<double>(i) / a.sample_rate;
        const auto v = static_cast<std::int16_t>(
            t < onset ? 0 : std::lround(12000 * std::sin(2 * M_PI * 440 * t)));
        a.samples.push_back(v);
        a.samples.push_back(v);
    }
    write_wav(path, a);
    return path;
}

std::size_t count_entries(const fs::path& dir) {
    return static_cast<std::size_t>(
        std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

constexpr double kFrame = 1.0 / 24.0;

TEST(Encode, VideoOnly) {
    TempDir tmp;
    write_frames(tmp.path / "frames", "frame_{:04d}.png", 1, 12);
    EncodeOptions o;
    o.frames_dir = tmp.path / "frames";
    o.output = tmp.path / "out.mp4";
    o.fps = 24;
    EncodeResult r = encode_video(o);
    EXPECT_EQ(r.frames.prefix, "frame_");
    EXPECT_EQ(r.frames.digits, 4);
    EXPECT_EQ(r.frames.first, 1);
    EXPECT_EQ(r.frames.count, 12);
    EXPECT_FALSE(r.padded);
    EXPECT_NEAR(r.duration, 0.5, 1e-9);

    MediaInfo info = probe_media(o.output);
    EXPECT_NE(info.format.find("mp4"), std::string::npos) << info.format;
    ASSERT_EQ(info.streams.size(), 1u);
    const StreamInfo& v = info.streams[0];
    EXPECT_EQ(v.type, "video");
    EXPECT_EQ(v.codec, "h264");
    EXPECT_EQ(v.frames, 12);
    EXPECT_EQ(v.width, 64);
    EXPECT_EQ(v.height, 48);
    EXPECT_EQ(v.pix_fmt, "yuv420p");
    EXPECT_NEAR(v.start_time, 0.0, 1e-6);
    EXPECT_NEAR(v.duration, 0.5, kFrame);
    EXPECT_NEAR(info.duration, 0.5, kFrame);
    // Only out.mp4 and the frames directory: no temporary left behind.
    EXPECT_EQ(count_entries(tmp.path), 2u);
}

TEST(Encode, WithAudioCutToTheVideo) {
    TempDir tmp;
    write_frames(tmp.path / "frames", "f{:03d}.png", 0, 12);
    EncodeOptions o;
    o.frames_dir = tmp.path / "frames";
    o.output = tmp.path / "av.mp4";
    o.audio = write_tone(tmp.path / "tone.wav", 1.0);
    encode_video(o);
    MediaInfo info = probe_media(o.output);
    ASSERT_EQ(info.streams.size(), 2u);
    const StreamInfo* v = info.first("video");
    const StreamInfo* a = info.first("audio");
    ASSERT_TRUE(v && a);
    EXPECT_EQ(v->codec, "h264");
    EXPECT_EQ(v->frames, 12);
    EXPECT_EQ(v->pix_fmt, "yuv420p");
    EXPECT_EQ(a->codec, "aac");
    EXPECT_EQ(a->sample_rate, 44100);
    EXPECT_EQ(a->channels, 2);
    EXPECT_NEAR(a->duration, 0.5, kFrame);
    EXPECT_NEAR(info.duration, 0.5, kFrame);

    // Without the cut the file runs as long as the soundtrack.
    o.cut_audio_to_video = false;
    o.output = tmp.path / "long.mp4";
    encode_video(o);
    EXPECT_NEAR(probe_media(o.output).duration, 1.0, kFrame);
}

TEST(Encode, AudioStartsWithFrameZero) {
    // A tone starting 0.25 s in: decoded back from the MP4 it must start 0.25 s in too (the AAC
    // encoder's priming samples must be hidden by the edit list, not shift the sound late).
    TempDir tmp;
    write_frames(tmp.path / "frames", "f{:03d}.png", 0, 12);
    EncodeOptions o;
    o.frames_dir = tmp.path / "frames";
    o.output = tmp.path / "av.mp4";
    o.audio = write_tone(tmp.path / "tone.wav", 0.5, 0.25);
    encode_video(o);
    MediaInfo info = probe_media(o.output);
    ASSERT_TRUE(info.first("video") && info.first("audio"));
    EXPECT_NEAR(info.first("video")->start_time, 0.0, 1e-6);
    EXPECT_NEAR(info.first("audio")->start_time, 0.0, 1e-3);

    const fs::path back = tmp.path / "back.wav";
    ProcessResult run = run_process({"ffmpeg", "-nostdin", "-loglevel", "error", "-i",
                                     o.output.string(), "-c:a", "pcm_s16le", back.string()});
    ASSERT_TRUE(run.ok()) << run.err;
    WavAudio decoded = read_wav(back);
    std::int64_t onset = -1;
    for (std::int64_t f = 0; f < decoded.frames() && onset < 0; ++f)
        if (std::abs(decoded.samples[f * decoded.channels]) > 2000) onset = f;
    ASSERT_GE(onset, 0);
    EXPECT_NEAR(static_cast<double>(onset) / decoded.sample_rate, 0.25, 0.010);
}

TEST(Encode, OddSizedFramesArePadded) {
    TempDir tmp;
    write_frames(tmp.path / "frames", "frame_{:04d}.png", 1, 12, 63, 47);
    EncodeOptions o;
    o.frames_dir = tmp.path / "frames";
    o.output = tmp.path / "odd.mp4";
    EncodeResult r = encode_video(o);
    EXPECT_TRUE(r.padded);
    MediaInfo info = probe_media(o.output);
    ASSERT_EQ(info.streams.size(), 1u);
    EXPECT_EQ(info.streams[0].width, 64);
    EXPECT_EQ(info.streams[0].height, 48);
    EXPECT_EQ(info.streams[0].frames, 12);
    EXPECT_EQ(info.streams[0].pix_fmt, "yuv420p");

    // The added column and row repeat the edge rather than being black.
    const fs::path png = tmp.path / "first.png";
    ProcessResult run = run_process({"ffmpeg", "-nostdin", "-loglevel", "error", "-i",
                                     o.output.string(), "-frames:v", "1", png.string()});
    ASSERT_TRUE(run.ok()) << run.err;
    DecodedPng d = read_png(png);
    ASSERT_EQ(d.width, 64);
    ASSERT_EQ(d.height, 48);
    const Rgb8 corner = d.rgb(63, 10), inside = d.rgb(61, 10), bottom = d.rgb(30, 47);
    EXPECT_GT(corner[2], 150) << "right column should be the frame's blue, not black";
    EXPECT_GT(bottom[2], 150) << "bottom row should be the frame's blue, not black";
    EXPECT_NEAR(corner[2], inside[2], 20);
}

TEST(Encode, GapNamesTheFirstMissingFrame) {
    TempDir tmp;
    write_frames(tmp.path / "frames", "frame_{:04d}.png", 1, 12);
    fs::remove(tmp.path / "frames" / "frame_0007.png");
    fs::remove(tmp.path / "frames" / "frame_0009.png");
    EncodeOptions o;
    o.frames_dir = tmp.path / "frames";
    o.output = tmp.path / "gap.mp4";
    const std::string e = error_of([&] { encode_video(o); });
    EXPECT_NE(e.find("frame_0007.png: missing frame"), std::string::npos) << e;
    EXPECT_FALSE(fs::exists(o.output));
    EXPECT_EQ(count_entries(tmp.path), 1u);
}

TEST(Encode, MissingOrBadAudioIsAnError) {
    TempDir tmp;
    write_frames(tmp.path / "frames", "frame_{:04d}.png", 1, 12);
    EncodeOptions o;
    o.frames_dir = tmp.path / "frames";
    o.output = tmp.path / "a.mp4";
    o.audio = tmp.path / "no such.wav";
    std::string e = error_of([&] { encode_video(o); });
    EXPECT_NE(e.find("no such.wav: cannot open audio file"), std::string::npos) << e;

    o.audio = tmp.path / "notes.txt";
    write_file_atomic(o.audio, {reinterpret_cast<const std::uint8_t*>("not audio"), 9});
    e = error_of([&] { encode_video(o); });
    EXPECT_NE(e.find("notes.txt: cannot read audio"), std::string::npos) << e;

    // A video with no audio stream is readable but is no soundtrack.
    o.audio.clear();
    encode_video(o);
    EncodeOptions o2 = o;
    o2.audio = o.output;
    o2.output = tmp.path / "b.mp4";
    e = error_of([&] { encode_video(o2); });
    EXPECT_NE(e.find("a.mp4: has no audio stream"), std::string::npos) << e;
    EXPECT_FALSE(fs::exists(o2.output));
}

TEST(Encode, MissingFfmpegSaysWhatToInstall) {
    TempDir tmp;
    write_frames(tmp.path / "frames", "frame_{:04d}.png", 1, 3);
    EncodeOptions o;
    o.frames_dir = tmp.path / "frames";
    o.output = tmp.path / "a.mp4";
    // PATH without ffmpeg: the default program name is looked up there.
    const std::string saved = std::getenv("PATH") ? std::getenv("PATH") : "";
    ::setenv("PATH", tmp.path.c_str(), 1);
    const std::string e = error_of([&] { encode_video(o); });
    ::setenv("PATH", saved.c_str(), 1);
    EXPECT_EQ(e, "ffmpeg not found on PATH; install the Debian package ffmpeg");
    o.ffmpeg = "toonray-no-such-ffmpeg";
    EXPECT_EQ(error_of([&] { encode_video(o); }),
              "toonray-no-such-ffmpeg not found on PATH; install the Debian package ffmpeg");
}

TEST(Encode, FfmpegFailureQuotesItsStderrAndKeepsTheOldOutput) {
    TempDir tmp;
    write_frames(tmp.path / "frames", "frame_{:04d}.png", 1, 3);
    EncodeOptions o;
    o.frames_dir = tmp.path / "frames";
    o.output = tmp.path / "a.mp4";
    write_file_atomic(o.output, {reinterpret_cast<const std::uint8_t*>("old"), 3});
    o.tune = "no-such-tune";
    const std::string e = error_of([&] { encode_video(o); });
    EXPECT_NE(e.find("a.mp4: ffmpeg failed (exit status"), std::string::npos) << e;
    EXPECT_NE(e.find("no-such-tune"), std::string::npos) << "stderr tail missing: " << e;
    EXPECT_EQ(read_file(o.output), "old");
    EXPECT_EQ(count_entries(tmp.path), 2u);  // frames/ and a.mp4: temporary removed
}

TEST(Encode, AwkwardPathsArePassedIntact) {
    // Spaces, quotes, '$', '%' and ':' must survive: no shell, '%' escaped, file: protocol.
    TempDir tmp;
    const fs::path dir = tmp.path / "my $frames 100% 'done'";
    write_frames(dir, "take:2 {:03d}.png", 1, 4);
    EncodeOptions o;
    o.frames_dir = dir;
    o.output = tmp.path / "-out: 50%.mp4";
    o.audio = write_tone(tmp.path / "tone $1.wav", 0.2);
    EncodeResult r = encode_video(o);
    EXPECT_EQ(r.frames.pattern(), "take:2 %03d.png");
    MediaInfo info = probe_media(o.output);
    ASSERT_EQ(info.streams.size(), 2u);
    EXPECT_EQ(info.first("video")->frames, 4);
}

TEST(Encode, ExplicitPatternAndStartNumber) {
    TempDir tmp;
    write_frames(tmp.path, "shot-{:03d}.png", 0, 12);
    write_frames(tmp.path, "other_{:02d}.png", 0, 2);  // a second sequence: fine with a pattern
    EncodeOptions o;
    o.pattern = (tmp.path / "shot-%03d.png").string();
    o.start_number = 3;
    o.output = tmp.path / "p.mp4";
    EncodeResult r = encode_video(o);
    EXPECT_EQ(r.frames.first, 3);
    EXPECT_EQ(r.frames.count, 9);
    EXPECT_EQ(probe_media(o.output).first("video")->frames, 9);

    o.start_number = 20;
    EXPECT_NE(error_of([&] { encode_video(o); }).find("shot-020.png: first frame not found"),
              std::string::npos);
    o.start_number.reset();
    o.pattern = (tmp.path / "shot-%03d-%d.png").string();
    EXPECT_NE(error_of([&] { encode_video(o); }).find("exactly one %d"), std::string::npos);
}

TEST(FrameSequence, DetectsPrefixAndPadding) {
    TempDir tmp;
    write_frames(tmp.path, "render.{:05d}.png", 7, 3);
    write_file_atomic(tmp.path / "poster.png", {reinterpret_cast<const std::uint8_t*>("x"), 1});
    write_file_atomic(tmp.path / "notes.txt", {reinterpret_cast<const std::uint8_t*>("x"), 1});
    FrameSequence s = find_frame_sequence(tmp.path);
    EXPECT_EQ(s.prefix, "render.");
    EXPECT_EQ(s.digits, 5);
    EXPECT_EQ(s.first, 7);
    EXPECT_EQ(s.count, 3);
    EXPECT_EQ(s.width, 64);
    EXPECT_EQ(s.pattern(), "render.%05d.png");
    EXPECT_EQ(s.frame_path(8), tmp.path / "render.00008.png");
}

TEST(FrameSequence, UnpaddedNumbersAndPaddingOverflow) {
    TempDir tmp;
    write_frames(tmp.path / "a", "f{}.png", 8, 5);  // f8 .. f12
    FrameSequence s = find_frame_sequence(tmp.path / "a");
    EXPECT_EQ(s.pattern(), "f%d.png");
    EXPECT_EQ(s.count, 5);
    write_frames(tmp.path / "b", "f{:03d}.png", 998, 4);  // f998, f999, f1000, f1001
    s = find_frame_sequence(tmp.path / "b");
    EXPECT_EQ(s.pattern(), "f%03d.png");
    EXPECT_EQ(s.count, 4);
}

TEST(FrameSequence, MixedSequencesAndPaddingsAreNamed) {
    TempDir tmp;
    write_frames(tmp.path / "a", "beauty_{:04d}.png", 1, 3);
    write_frames(tmp.path / "a", "depth_{:04d}.png", 1, 2);
    std::string e = error_of([&] { find_frame_sequence(tmp.path / "a"); });
    EXPECT_NE(e.find("several image sequences"), std::string::npos) << e;
    EXPECT_NE(e.find("beauty_%04d.png (3 files)"), std::string::npos) << e;
    EXPECT_NE(e.find("depth_%04d.png (2 files)"), std::string::npos) << e;

    write_frames(tmp.path / "b", "f{:03d}.png", 1, 3);
    write_frames(tmp.path / "b", "f{:04d}.png", 4, 1);
    e = error_of([&] { find_frame_sequence(tmp.path / "b"); });
    EXPECT_NE(e.find("different zero padding"), std::string::npos) << e;
    EXPECT_NE(e.find("f0004.png"), std::string::npos) << e;
}

TEST(FrameSequence, NoFramesMismatchedSizesAndNonPngs) {
    TempDir tmp;
    fs::create_directories(tmp.path / "empty");
    EXPECT_NE(error_of([&] { find_frame_sequence(tmp.path / "empty"); }).find("no PNG frames"),
              std::string::npos);
    EXPECT_NE(error_of([&] {
                  find_frame_sequence(tmp.path / "nowhere");
              }).find("frame directory not found"),
              std::string::npos);
    write_frames(tmp.path / "s", "f{:02d}.png", 1, 2, 64, 48);
    write_frames(tmp.path / "s", "f{:02d}.png", 3, 1, 32, 48);
    std::string e = error_of([&] { find_frame_sequence(tmp.path / "s"); });
    EXPECT_NE(e.find("f03.png: frame is 32x48 but the first frame f01.png is 64x48"),
              std::string::npos)
        << e;
    write_frames(tmp.path / "t", "f{:02d}.png", 1, 2);
    write_file_atomic(tmp.path / "t" / "f03.png",
                      {reinterpret_cast<const std::uint8_t*>("GIF89a"), 6});
    e = error_of([&] { find_frame_sequence(tmp.path / "t"); });
    EXPECT_NE(e.find("f03.png: frame is not a PNG"), std::string::npos) << e;
}

TEST(Process, ArgvIsPassedWithoutAShell) {
    ProcessResult r = run_process({"printf", "[%s]", "a b", "$HOME", "'q'", ";echo x"});
    EXPECT_EQ(r.exit_code, 0);
    EXPECT_EQ(r.out, "[a b][$HOME]['q'][;echo x]");
    r = run_process({"sh", "-c", "echo out; echo err >&2; exit 3"});
    EXPECT_EQ(r.exit_code, 3);
    EXPECT_EQ(r.out, "out\n");
    EXPECT_EQ(r.err, "err\n");
    EXPECT_THROW(run_process({"toonray-no-such-program"}), Error);
    EXPECT_EQ(tail_lines("a\nb\n\nc\nd\n", 2), "c\nd");
}

TEST(Probe, UnreadableFileIsAnError) {
    TempDir tmp;
    EXPECT_NE(error_of([&] {
                  probe_media(tmp.path / "missing.mp4");
              }).find("missing.mp4: ffprobe failed"),
              std::string::npos);
}

}  // namespace
}  // namespace toonray
