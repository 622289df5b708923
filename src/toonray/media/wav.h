#pragma once
/// 16-bit PCM WAV files: what the audio synthesis writes and the video encoder muxes.

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

namespace toonray {

/// Interleaved 16-bit PCM samples.
struct WavAudio {
    int sample_rate = 44100;
    int channels = 2;
    std::vector<std::int16_t> samples;  ///< interleaved, frames() * channels values

    [[nodiscard]] std::int64_t frames() const {
        return channels > 0 ? static_cast<std::int64_t>(samples.size()) / channels : 0;
    }
    [[nodiscard]] double duration() const {
        return sample_rate > 0 ? static_cast<double>(frames()) / sample_rate : 0.0;
    }
};

/// The complete WAV file (RIFF header, `fmt `, `data`) as bytes, little-endian.
std::vector<std::uint8_t> encode_wav(const WavAudio& audio);

/// Writes a WAV file atomically (write_file_atomic). Throws Error on failure.
void write_wav(const std::filesystem::path& path, const WavAudio& audio);

/// Reads a 16-bit PCM WAV file (unknown chunks are skipped). Throws Error naming the file when
/// it is missing, not a WAV, or not 16-bit PCM.
WavAudio read_wav(const std::filesystem::path& path);

}  // namespace toonray
