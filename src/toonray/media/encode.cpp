#include "toonray/media/encode.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fmt/format.h>
#include <map>
#include <set>

#include "toonray/core/error.h"
#include "toonray/media/process.h"

namespace toonray {

namespace fs = std::filesystem;

namespace {

/// The number as the pattern writes it ("%0<digits>d").
std::string format_number(int number, int digits) { return fmt::format("{:0{}d}", number, digits); }

/// '%' is special in ffmpeg's image2 file names (anywhere in the path): write it as "%%".
std::string escape_percent(std::string_view text) {
    std::string out;
    for (char c : text) {
        out += c;
        if (c == '%') out += '%';
    }
    return out;
}

/// A path as an ffmpeg input or output URL: absolute (a name starting with '-' is not taken for
/// an option) and with the file: protocol, so a ':' in a name is not taken for a protocol.
std::string ffmpeg_url(const fs::path& path) { return "file:" + fs::absolute(path).string(); }

/// Width and height from a PNG's IHDR chunk, without decoding the image.
std::pair<int, int> png_size(const fs::path& path) {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f)
        throw Error(fmt::format("{}: cannot open frame: {}", path.string(), std::strerror(errno)));
    unsigned char h[24];
    const std::size_t n = std::fread(h, 1, sizeof h, f);
    std::fclose(f);
    static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    if (n != sizeof h || std::memcmp(h, kSignature, 8) != 0 || std::memcmp(h + 12, "IHDR", 4) != 0)
        throw Error(fmt::format("{}: frame is not a PNG file", path.string()));
    auto be32 = [&](int at) {
        return static_cast<std::uint32_t>(h[at]) << 24 |
               static_cast<std::uint32_t>(h[at + 1]) << 16 |
               static_cast<std::uint32_t>(h[at + 2]) << 8 | h[at + 3];
    };
    const std::uint32_t w = be32(16), ht = be32(20);
    if (w == 0 || ht == 0 || w > 65536 || ht > 65536)
        throw Error(fmt::format("{}: PNG has an invalid size {}x{}", path.string(), w, ht));
    return {static_cast<int>(w), static_cast<int>(ht)};
}

/// Checks `numbers` form one run from the start, and reads every frame's size.
FrameSequence make_sequence(FrameSequence seq, const std::set<int>& numbers,
                            std::optional<int> start_number) {
    const std::string where = (seq.dir / seq.pattern()).string();
    if (numbers.empty()) throw Error(fmt::format("{}: no frames found", where));
    seq.first = start_number ? *start_number : *numbers.begin();
    if (!numbers.contains(seq.first))
        throw Error(fmt::format(
            "{}: first frame not found (start number {}; frames present are "
            "numbered {} .. {})",
            seq.frame_path(seq.first).string(), seq.first, *numbers.begin(), *numbers.rbegin()));
    const int last = *numbers.rbegin();
    for (int n = seq.first; n <= last; ++n) {
        if (!numbers.contains(n))
            throw Error(
                fmt::format("{}: missing frame: the sequence {} has a gap (frames {} .. {} "
                            "present, {} missing)",
                            seq.frame_path(n).string(), seq.pattern(), seq.first, n - 1, n));
    }
    seq.count = last - seq.first + 1;
    for (int n = seq.first; n <= last; ++n) {
        const fs::path path = seq.frame_path(n);
        auto [w, h] = png_size(path);
        if (n == seq.first) {
            seq.width = w;
            seq.height = h;
        } else if (w != seq.width || h != seq.height) {
            throw Error(fmt::format(
                "{}: frame is {}x{} but the first frame {} is {}x{}", path.string(), w, h,
                seq.frame_path(seq.first).filename().string(), seq.width, seq.height));
        }
    }
    return seq;
}

void require_directory(const fs::path& dir) {
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
        throw Error(fmt::format("{}: frame directory not found", dir.string()));
}

/// The number, or `fallback` when the text is not one (ffprobe writes "N/A").
double parse_double(const std::string& text, double fallback) {
    double v = 0;
    auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    return ec == std::errc() && p == text.data() + text.size() ? v : fallback;
}

int parse_int(const std::string& text) {
    int v = 0;
    auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    return ec == std::errc() && p == text.data() + text.size() ? v : 0;
}

/// Removes a file when it goes out of scope, unless released.
class RemoveOnExit {
public:
    explicit RemoveOnExit(fs::path path) : path_(std::move(path)) {}
    ~RemoveOnExit() {
        if (!path_.empty()) ::unlink(path_.c_str());
    }
    RemoveOnExit(const RemoveOnExit&) = delete;
    RemoveOnExit& operator=(const RemoveOnExit&) = delete;
    void release() { path_.clear(); }

private:
    fs::path path_;
};

}  // namespace

// --- Frame sequences ---------------------------------------------------------------------------

std::string FrameSequence::pattern() const {
    return prefix + (digits > 1 ? fmt::format("%0{}d", digits) : std::string("%d")) + suffix;
}

fs::path FrameSequence::frame_path(int number) const {
    return dir / (prefix + format_number(number, digits) + suffix);
}

FrameSequence find_frame_sequence(const fs::path& dir, std::optional<int> start_number) {
    require_directory(dir);
    // prefix -> (digit string -> number)
    std::map<std::string, std::map<std::string, int>> groups;
    for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
        std::error_code ec;
        if (!entry.is_regular_file(ec)) continue;
        const std::string name = entry.path().filename().string();
        if (name.size() <= 4 || name.compare(name.size() - 4, 4, ".png") != 0) continue;
        const std::string stem = name.substr(0, name.size() - 4);
        std::size_t d = stem.size();
        while (d > 0 && stem[d - 1] >= '0' && stem[d - 1] <= '9') --d;
        if (d == stem.size()) continue;  // not numbered: a thumbnail, a poster, ...
        const std::string digits = stem.substr(d);
        int number = 0;
        auto [p, err] = std::from_chars(digits.data(), digits.data() + digits.size(), number);
        if (err != std::errc()) continue;  // beyond int: no frame number we could encode
        groups[stem.substr(0, d)][digits] = number;
    }
    if (groups.empty())
        throw Error(
            fmt::format("{}: no PNG frames (files named like frame_0001.png)", dir.string()));

    std::vector<FrameSequence> found;
    std::vector<std::set<int>> found_numbers;
    for (const auto& [prefix, files] : groups) {
        FrameSequence seq;
        seq.dir = dir;
        seq.prefix = prefix;
        std::size_t width = SIZE_MAX;
        for (const auto& [digits, number] : files) width = std::min(width, digits.size());
        seq.digits = static_cast<int>(width);
        // Every name must be what "%0<width>d" prints: "f1.png" next to "f001.png", or
        // "f001.png" next to "f0001.png", cannot be one sequence.
        std::set<int> numbers;
        std::vector<std::string> odd;
        for (const auto& [digits, number] : files) {
            if (digits == format_number(number, seq.digits)) {
                numbers.insert(number);
            } else {
                odd.push_back(prefix + digits + ".png");
            }
        }
        if (!odd.empty())
            throw Error(fmt::format(
                "{}: frames numbered with different zero padding: {} and {}{}", dir.string(),
                seq.frame_path(*numbers.begin()).filename().string(), odd.front(),
                odd.size() > 1 ? fmt::format(" ({} more)", odd.size() - 1) : ""));
        found.push_back(seq);
        found_numbers.push_back(numbers);
    }
    if (found.size() > 1) {
        std::string list;
        for (std::size_t i = 0; i < found.size(); ++i)
            list += fmt::format("{}{} ({} files)", i ? ", " : "", found[i].pattern(),
                                found_numbers[i].size());
        throw Error(
            fmt::format("{}: several image sequences in one directory: {}; give the one to "
                        "encode as a pattern",
                        dir.string(), list));
    }
    return make_sequence(found.front(), found_numbers.front(), start_number);
}

FrameSequence frame_sequence_from_pattern(const fs::path& pattern,
                                          std::optional<int> start_number) {
    const std::string name = pattern.filename().string();
    FrameSequence seq;
    seq.dir = pattern.parent_path().empty() ? fs::path(".") : pattern.parent_path();
    // Split the name at its one number field; "%%" is a literal '%'.
    std::string literal;
    bool have_field = false;
    for (std::size_t i = 0; i < name.size(); ++i) {
        if (name[i] != '%') {
            literal += name[i];
            continue;
        }
        if (i + 1 < name.size() && name[i + 1] == '%') {
            literal += '%';
            ++i;
            continue;
        }
        std::size_t j = i + 1;
        int width = 0;
        while (j < name.size() && name[j] >= '0' && name[j] <= '9' && width < 100)
            width = width * 10 + (name[j++] - '0');
        if (j >= name.size() || name[j] != 'd' || have_field)
            throw Error(
                fmt::format("{}: frame pattern needs exactly one %d or %0Nd number field "
                            "(write a literal % as %%)",
                            pattern.string()));
        if (width > 10)
            throw Error(
                fmt::format("{}: frame number width {} is too wide", pattern.string(), width));
        have_field = true;
        seq.prefix = literal;
        literal.clear();
        seq.digits = std::max(1, width);
        i = j;
    }
    if (!have_field)
        throw Error(
            fmt::format("{}: frame pattern has no %d or %0Nd number field", pattern.string()));
    seq.suffix = literal;
    require_directory(seq.dir);

    std::set<int> numbers;
    for (const fs::directory_entry& entry : fs::directory_iterator(seq.dir)) {
        std::error_code ec;
        if (!entry.is_regular_file(ec)) continue;
        const std::string file = entry.path().filename().string();
        if (file.size() <= seq.prefix.size() + seq.suffix.size() || !file.starts_with(seq.prefix) ||
            !file.ends_with(seq.suffix))
            continue;
        const std::string digits =
            file.substr(seq.prefix.size(), file.size() - seq.prefix.size() - seq.suffix.size());
        int number = 0;
        auto [p, err] = std::from_chars(digits.data(), digits.data() + digits.size(), number);
        if (err != std::errc() || p != digits.data() + digits.size() || number < 0) continue;
        if (digits == format_number(number, seq.digits)) numbers.insert(number);
    }
    return make_sequence(seq, numbers, start_number);
}

// --- Encoding ----------------------------------------------------------------------------------

std::vector<std::string> ffmpeg_arguments(const EncodeOptions& o, const FrameSequence& frames,
                                          const fs::path& output) {
    std::vector<std::string> a = {o.ffmpeg,    "-hide_banner", "-nostdin", "-nostats",
                                  "-loglevel", "error",        "-y"};
    // Input 0: the frames, read as an exact image sequence (no globbing). '%' in the names is
    // doubled, the number field kept.
    const std::string field = frames.digits > 1 ? fmt::format("%0{}d", frames.digits) : "%d";
    const std::string input = escape_percent(ffmpeg_url(frames.dir / frames.prefix)) + field +
                              escape_percent(frames.suffix);
    a.insert(a.end(),
             {"-framerate", fmt::format("{}", o.fps), "-start_number", std::to_string(frames.first),
              "-f", "image2", "-pattern_type", "sequence", "-i", input});

    const bool audio = !o.audio.empty();
    if (audio) a.insert(a.end(), {"-i", ffmpeg_url(o.audio)});
    a.insert(a.end(), {"-map", "0:v:0"});
    if (audio) a.insert(a.end(), {"-map", "1:a:0"});

    // yuv420p needs even dimensions. Pad (rather than scale, which would blur every line of a
    // toon image) by one pixel, filled by repeating the edge so no dark border appears.
    // Frames are RGB or, with few colours, indexed PNGs (io/png.cpp); ffmpeg converts a palette
    // to YUV slightly differently from the same pixels as RGB (1 in 900 samples off by one), so
    // every frame is made RGB first and the video depends only on the pixels.
    std::string filters = "format=rgb24,";
    const int pad_w = frames.width % 2, pad_h = frames.height % 2;
    if (pad_w || pad_h)
        filters += fmt::format("pad={}:{}:0:0,fillborders=right={}:bottom={}:mode=smear,",
                               frames.width + pad_w, frames.height + pad_h, pad_w, pad_h);
    // BT.709 matrix, limited range, and tagged so: players assume BT.709 for video this size,
    // and ffmpeg's default conversion would use BT.601 untagged, shifting the toon colours.
    filters +=
        "scale=out_color_matrix=bt709:out_range=tv:flags=bicubic+accurate_rnd+full_chroma_int,"
        "format=yuv420p";
    a.insert(a.end(), {"-vf", filters, "-c:v", "libx264", "-preset", o.preset});
    if (!o.tune.empty()) a.insert(a.end(), {"-tune", o.tune});
    a.insert(a.end(),
             {"-crf", std::to_string(o.crf), "-pix_fmt", "yuv420p", "-color_primaries", "bt709",
              "-color_trc", "bt709", "-colorspace", "bt709", "-color_range", "tv"});
    if (audio) a.insert(a.end(), {"-c:a", "aac", "-b:a", fmt::format("{}k", o.audio_bitrate_kbps)});
    // The length of the frames, which also stops the sequence at its last checked frame. (Not
    // -frames:v: in ffmpeg 5 reaching it closes every stream of the output, audio included.)
    if (!audio || o.cut_audio_to_video)
        a.insert(a.end(), {"-t", fmt::format("{:.6f}", frames.count / o.fps)});
    a.insert(a.end(), {"-movflags", "+faststart", "-f", "mp4", ffmpeg_url(output)});
    return a;
}

EncodeResult encode_video(const EncodeOptions& o) {
    if (!std::isfinite(o.fps) || o.fps <= 0 || o.fps > 1000)
        throw Error(fmt::format("encode: frame rate {} outside (0, 1000]", o.fps));
    if (o.crf < 0 || o.crf > 51) throw Error(fmt::format("encode: crf {} outside 0..51", o.crf));
    if (o.audio_bitrate_kbps < 8 || o.audio_bitrate_kbps > 1024)
        throw Error(
            fmt::format("encode: audio bit rate {}k outside 8..1024", o.audio_bitrate_kbps));
    if (o.output.empty()) throw Error("encode: no output file given");
    if (find_program(o.ffmpeg).empty())
        throw Error(
            fmt::format("{} not found on PATH; install the Debian package ffmpeg", o.ffmpeg));

    EncodeResult result;
    if (!o.pattern.empty()) {
        result.frames = frame_sequence_from_pattern(o.pattern, o.start_number);
    } else if (!o.frames_dir.empty()) {
        result.frames = find_frame_sequence(o.frames_dir, o.start_number);
    } else {
        throw Error("encode: no frames given (a frame directory or a pattern)");
    }
    result.duration = result.frames.count / o.fps;
    result.padded = result.frames.width % 2 || result.frames.height % 2;

    if (!o.audio.empty()) {
        // Checked here so the message names the file, instead of ffmpeg's stderr saying it.
        std::FILE* f = std::fopen(o.audio.c_str(), "rb");
        if (!f)
            throw Error(fmt::format("{}: cannot open audio file: {}", o.audio.string(),
                                    std::strerror(errno)));
        std::fclose(f);
        std::error_code ec;
        if (!fs::is_regular_file(o.audio, ec))
            throw Error(fmt::format("{}: audio is not a regular file", o.audio.string()));
        MediaInfo info;
        try {
            info = probe_media(o.audio, false, o.ffprobe);
        } catch (const Error& e) {
            throw Error(fmt::format("{}: cannot read audio: {}", o.audio.string(), e.what()));
        }
        if (!info.first("audio"))
            throw Error(fmt::format("{}: has no audio stream", o.audio.string()));
    }

    const fs::path out_dir =
        o.output.parent_path().empty() ? fs::path(".") : o.output.parent_path();
    std::error_code ec;
    if (!fs::is_directory(out_dir, ec))
        throw Error(
            fmt::format("{}: output directory {} not found", o.output.string(), out_dir.string()));
    std::string tmp = (out_dir / ("." + o.output.filename().string() + ".tmp.XXXXXX")).string();
    const int fd = ::mkstemp(tmp.data());
    if (fd < 0)
        throw Error(
            fmt::format("{}: cannot create a file: {}", o.output.string(), std::strerror(errno)));
    ::close(fd);
    RemoveOnExit remove_tmp(tmp);

    result.argv = ffmpeg_arguments(o, result.frames, tmp);
    const ProcessResult run = run_process(result.argv);
    if (!run.ok()) {
        const std::string why = run.signal ? fmt::format("killed by signal {}", run.signal)
                                           : fmt::format("exit status {}", run.exit_code);
        throw Error(fmt::format("{}: ffmpeg failed ({}):\n{}", o.output.string(), why,
                                tail_lines(run.err)));
    }
    struct stat st {};
    if (::stat(tmp.c_str(), &st) != 0 || st.st_size == 0)
        throw Error(
            fmt::format("{}: ffmpeg reported success but wrote nothing", o.output.string()));
    // mkstemp made the file 0600; give it the permissions any new file would have.
    const mode_t mask = ::umask(0);
    ::umask(mask);
    ::chmod(tmp.c_str(), 0666 & ~mask);
    if (::rename(tmp.c_str(), o.output.c_str()) != 0)
        throw Error(fmt::format("{}: cannot rename into place: {}", o.output.string(),
                                std::strerror(errno)));
    remove_tmp.release();
    return result;
}

// --- Probing -----------------------------------------------------------------------------------

const StreamInfo* MediaInfo::first(std::string_view type) const {
    for (const StreamInfo& s : streams)
        if (s.type == type) return &s;
    return nullptr;
}

MediaInfo probe_media(const fs::path& path, bool count_frames, const std::string& ffprobe) {
    if (find_program(ffprobe).empty())
        throw Error(
            fmt::format("{} not found on PATH; install the Debian package ffmpeg", ffprobe));
    std::vector<std::string> argv = {ffprobe, "-v", "error"};
    if (count_frames) argv.push_back("-count_frames");
    argv.insert(argv.end(),
                {"-show_entries",
                 "format=format_name,duration:stream=index,codec_type,codec_name,width,height,"
                 "pix_fmt,nb_frames,nb_read_frames,duration,start_time,sample_rate,channels",
                 "-of", "flat", ffmpeg_url(path)});
    const ProcessResult run = run_process(argv);
    if (!run.ok())
        throw Error(fmt::format("{}: ffprobe failed: {}", path.string(), tail_lines(run.err, 6)));

    // Lines like: streams.stream.0.codec_name="h264"  format.duration="0.500000"
    MediaInfo info;
    std::map<int, std::map<std::string, std::string>> streams;
    std::size_t pos = 0;
    const std::string& out = run.out;
    while (pos < out.size()) {
        std::size_t nl = out.find('\n', pos);
        if (nl == std::string::npos) nl = out.size();
        const std::string line = out.substr(pos, nl - pos);
        pos = nl + 1;
        const std::size_t eq = line.find('=');
        if (eq == std::string::npos) continue;
        const std::string key = line.substr(0, eq);
        std::string value = line.substr(eq + 1);
        if (value.size() >= 2 && value.front() == '"' && value.back() == '"')
            value = value.substr(1, value.size() - 2);
        if (key == "format.format_name") {
            info.format = value;
        } else if (key == "format.duration") {
            info.duration = parse_double(value, -1.0);
        } else if (key.starts_with("streams.stream.")) {
            const std::string rest = key.substr(15);
            const std::size_t dot = rest.find('.');
            if (dot == std::string::npos) continue;
            streams[parse_int(rest.substr(0, dot))][rest.substr(dot + 1)] = value;
        }
    }
    for (auto& [index, fields] : streams) {
        StreamInfo s;
        s.index = index;
        s.type = fields["codec_type"];
        s.codec = fields["codec_name"];
        s.width = parse_int(fields["width"]);
        s.height = parse_int(fields["height"]);
        s.pix_fmt = fields["pix_fmt"];
        s.sample_rate = parse_int(fields["sample_rate"]);
        s.channels = parse_int(fields["channels"]);
        s.duration = parse_double(fields["duration"], -1.0);
        s.start_time = parse_double(fields["start_time"], 0.0);
        const std::string& frames = count_frames ? fields["nb_read_frames"] : fields["nb_frames"];
        s.frames = frames.empty() || frames == "N/A" ? -1 : parse_int(frames);
        if (s.pix_fmt == "unknown") s.pix_fmt.clear();
        info.streams.push_back(s);
    }
    return info;
}

}  // namespace toonray
