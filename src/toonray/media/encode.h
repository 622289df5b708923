#pragma once
/// Video: a numbered PNG sequence (and optionally a soundtrack) compiled into an H.264 MP4 by
/// running ffmpeg, and ffprobe to check what came out. See docs/video.md.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace toonray {

/// A numbered image sequence: dir/PREFIX<number>SUFFIX for numbers first .. first + count - 1,
/// the number written as printf's "%0<digits>d" (digits 1 means plain "%d").
struct FrameSequence {
    std::filesystem::path dir;
    std::string prefix;
    std::string suffix = ".png";
    int digits = 1;
    int first = 0;
    int count = 0;
    int width = 0, height = 0;  ///< of every frame (all are checked to agree)

    /// The file name pattern, e.g. "frame_%05d.png".
    [[nodiscard]] std::string pattern() const;
    /// The file of frame `number`.
    [[nodiscard]] std::filesystem::path frame_path(int number) const;
};

/// Finds the one PNG sequence in `dir`: files named PREFIX + digits + ".png", the prefix and the
/// zero-padded width detected from the files present (other files are ignored). The sequence
/// starts at `start_number` when given, else at the lowest number present, and must be
/// contiguous up to the highest. Reads every frame's PNG header for its size.
/// Throws Error: the directory is missing; no frames; several sequences (named) or paddings
/// mixed; a gap (the first missing file named); a frame that is not a PNG or differs in size.
FrameSequence find_frame_sequence(const std::filesystem::path& dir,
                                  std::optional<int> start_number = {});

/// As find_frame_sequence, for an explicit pattern such as "out/frame_%04d.png" (one %d or
/// %0Nd; a literal '%' written "%%").
FrameSequence frame_sequence_from_pattern(const std::filesystem::path& pattern,
                                          std::optional<int> start_number = {});

struct EncodeOptions {
    std::filesystem::path frames_dir;  ///< directory holding one PNG sequence (detected), or
    std::string pattern;               ///< an explicit "dir/frame_%05d.png" (takes precedence)
    std::filesystem::path output;      ///< the .mp4 to write (always MP4, whatever the extension)
    double fps = 24.0;                 ///< frames per second, (0, 1000]
    std::filesystem::path audio;       ///< optional soundtrack (WAV or anything ffmpeg reads)
    std::optional<int> start_number;   ///< first frame number; default: the lowest present
    /// Cut the soundtrack at the end of the last frame (a longer track would leave the player
    /// showing a frozen last frame). Off: the MP4 lasts as long as the longer stream.
    bool cut_audio_to_video = true;
    int crf = 18;                    ///< x264 quality, 0 (lossless) .. 51; 18 looks lossless
    std::string preset = "medium";   ///< x264 speed/size trade-off
    std::string tune = "animation";  ///< x264 tuning for flat colours and hard edges; "" none
    int audio_bitrate_kbps = 192;    ///< AAC bit rate
    std::string ffmpeg = "ffmpeg";   ///< program name (searched on PATH) or path
    std::string ffprobe = "ffprobe";
};

struct EncodeResult {
    FrameSequence frames;
    std::vector<std::string> argv;  ///< the ffmpeg command that ran (output = temporary name)
    double duration = 0.0;          ///< frames.count / fps, seconds
    bool padded = false;            ///< an odd width or height was padded by one pixel
};

/// Encodes the sequence with libx264 (yuv420p, BT.709, +faststart) and the soundtrack, if any,
/// as AAC starting with frame 0. The MP4 is written under a temporary name in the output's
/// directory and renamed into place on success; on failure it is removed and `output` is left
/// as it was. Throws Error: ffmpeg not found; no frames or a gap (see find_frame_sequence);
/// audio missing, unreadable or without an audio stream; ffmpeg failed (with the tail of its
/// stderr).
EncodeResult encode_video(const EncodeOptions& options);

/// The ffmpeg arguments encode_video uses to write `output` (exposed for docs and tests).
std::vector<std::string> ffmpeg_arguments(const EncodeOptions& options, const FrameSequence& frames,
                                          const std::filesystem::path& output);

/// One stream as ffprobe reports it.
struct StreamInfo {
    int index = 0;
    std::string type;          ///< "video", "audio", ...
    std::string codec;         ///< "h264", "aac", ...
    std::int64_t frames = -1;  ///< frames decoded by ffprobe -count_frames (-1 when not counted)
    double duration = -1.0;    ///< seconds (-1 when unknown)
    double start_time = 0.0;   ///< presentation time of the first frame or sample, seconds
    int width = 0, height = 0;
    std::string pix_fmt;
    int sample_rate = 0, channels = 0;
};

struct MediaInfo {
    std::string format;      ///< container format names, e.g. "mov,mp4,m4a,3gp,3g2,mj2"
    double duration = -1.0;  ///< container duration, seconds (-1 when unknown)
    std::vector<StreamInfo> streams;

    /// The first stream of a type ("video", "audio"), or nullptr.
    [[nodiscard]] const StreamInfo* first(std::string_view type) const;
};

/// Runs ffprobe on a media file. `count_frames` decodes every frame to count them exactly (slow
/// for long videos). Throws Error when ffprobe is missing or cannot read the file.
MediaInfo probe_media(const std::filesystem::path& path, bool count_frames = true,
                      const std::string& ffprobe = "ffprobe");

}  // namespace toonray
