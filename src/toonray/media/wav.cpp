#include "toonray/media/wav.h"

#include <algorithm>
#include <cstring>
#include <fmt/format.h>
#include <string>

#include "toonray/core/error.h"
#include "toonray/io/file.h"

namespace toonray {

namespace {

void put_u16(std::vector<std::uint8_t>& out, std::uint32_t v) {
    out.push_back(static_cast<std::uint8_t>(v & 0xff));
    out.push_back(static_cast<std::uint8_t>((v >> 8) & 0xff));
}

void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v) {
    put_u16(out, v & 0xffff);
    put_u16(out, v >> 16);
}

void put_tag(std::vector<std::uint8_t>& out, const char* tag) {
    out.insert(out.end(), tag, tag + 4);
}

std::uint32_t get_u16(const std::string& s, std::size_t at) {
    return static_cast<std::uint8_t>(s[at]) | (static_cast<std::uint8_t>(s[at + 1]) << 8);
}

std::uint32_t get_u32(const std::string& s, std::size_t at) {
    return get_u16(s, at) | (get_u16(s, at + 2) << 16);
}

}  // namespace

std::vector<std::uint8_t> encode_wav(const WavAudio& audio) {
    if (audio.channels < 1 || audio.channels > 16)
        throw Error(fmt::format("WAV: unsupported channel count {}", audio.channels));
    if (audio.sample_rate < 1)
        throw Error(fmt::format("WAV: invalid sample rate {}", audio.sample_rate));
    if (audio.samples.size() % static_cast<std::size_t>(audio.channels) != 0)
        throw Error("WAV: sample count is not a multiple of the channel count");
    // RIFF sizes are 32-bit; 4 GB is about 6.7 hours of 44.1 kHz stereo, far beyond a demo.
    const std::uint64_t data_bytes = audio.samples.size() * 2;
    if (data_bytes > 0xffffffffull - 36) throw Error("WAV: audio too long for a RIFF file");

    std::vector<std::uint8_t> out;
    out.reserve(44 + data_bytes);
    const std::uint32_t block_align = static_cast<std::uint32_t>(audio.channels) * 2;
    put_tag(out, "RIFF");
    put_u32(out, static_cast<std::uint32_t>(36 + data_bytes));
    put_tag(out, "WAVE");
    put_tag(out, "fmt ");
    put_u32(out, 16);
    put_u16(out, 1);  // PCM
    put_u16(out, static_cast<std::uint32_t>(audio.channels));
    put_u32(out, static_cast<std::uint32_t>(audio.sample_rate));
    put_u32(out, static_cast<std::uint32_t>(audio.sample_rate) * block_align);
    put_u16(out, block_align);
    put_u16(out, 16);
    put_tag(out, "data");
    put_u32(out, static_cast<std::uint32_t>(data_bytes));
    for (std::int16_t s : audio.samples) put_u16(out, static_cast<std::uint16_t>(s));
    return out;
}

void write_wav(const std::filesystem::path& path, const WavAudio& audio) {
    std::vector<std::uint8_t> bytes = encode_wav(audio);
    write_file_atomic(path, bytes);
}

WavAudio read_wav(const std::filesystem::path& path) {
    const std::string data = read_file(path);
    auto fail = [&](const std::string& what) -> WavAudio {
        throw Error(fmt::format("{}: {}", path.string(), what));
    };
    if (data.size() < 12 || data.compare(0, 4, "RIFF") != 0 || data.compare(8, 4, "WAVE") != 0)
        return fail("not a WAV file (no RIFF/WAVE header)");

    WavAudio audio;
    bool have_fmt = false;
    std::size_t at = 12;
    while (at + 8 <= data.size()) {
        const std::string tag = data.substr(at, 4);
        const std::uint32_t size = get_u32(data, at + 4);
        const std::size_t body = at + 8;
        if (tag == "fmt ") {
            if (size < 16 || body + 16 > data.size()) return fail("truncated fmt chunk");
            const std::uint32_t format = get_u16(data, body);
            audio.channels = static_cast<int>(get_u16(data, body + 2));
            audio.sample_rate = static_cast<int>(get_u32(data, body + 4));
            const std::uint32_t bits = get_u16(data, body + 14);
            // 0xfffe is WAVE_FORMAT_EXTENSIBLE, which ffmpeg writes for some layouts.
            if ((format != 1 && format != 0xfffe) || bits != 16)
                return fail(
                    fmt::format("unsupported WAV encoding (format {}, {} bits); "
                                "16-bit PCM expected",
                                format, bits));
            if (audio.channels < 1) return fail("WAV with no channels");
            have_fmt = true;
        } else if (tag == "data") {
            if (!have_fmt) return fail("data chunk before fmt chunk");
            // Some writers leave the size at 0 or 0xffffffff when streaming; take what is there.
            std::size_t bytes = std::min<std::size_t>(size, data.size() - body);
            bytes -= bytes % (2 * static_cast<std::size_t>(audio.channels));
            audio.samples.resize(bytes / 2);
            for (std::size_t i = 0; i < audio.samples.size(); ++i)
                audio.samples[i] = static_cast<std::int16_t>(get_u16(data, body + 2 * i));
            return audio;
        }
        at = body + size + (size & 1);  // chunks are padded to even sizes
    }
    return fail("no data chunk");
}

}  // namespace toonray
