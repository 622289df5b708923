#pragma once
/// OpenEXR writing: one single-part, multi-layer scanline file (ZIP compression, lossless) from
/// whole float images. Layers are named by their channels' prefixes, as compositors read them
/// (`N.X`, `lines.silhouette`); the frame layer decides what goes in (frame/feature_exr.h).
/// Built with OpenEXR when TOONRAY_WITH_OPENEXR is on (the default); without it, writing throws.

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace toonray {

/// How a channel is stored: half (16-bit float: colours and coverages, 11 significant bits)
/// or float (32-bit: distances, normals, ids).
enum class ExrSample : std::uint8_t { Half, Float };

/// One channel: `values` holds width * height samples, row-major, top row first.
struct ExrChannel {
    std::string name;
    ExrSample sample = ExrSample::Half;
    std::span<const float> values;
};

/// True when this build can write EXR files.
[[nodiscard]] bool exr_available();

/// A string attribute of the file's header: its name and text.
using ExrAttribute = std::pair<std::string, std::string>;

/// The EXR file of the channels, in memory, with string attributes in its header. The channels
/// are stored sorted by name, as the format requires. Throws Error when a channel has the
/// wrong number of values, two channels share a name, or the build has no OpenEXR.
std::vector<std::uint8_t> encode_exr(int width, int height, std::span<const ExrChannel> channels,
                                     std::span<const ExrAttribute> attributes = {});

/// encode_exr, written atomically (io/file.h).
void write_exr(const std::filesystem::path& path, int width, int height,
               std::span<const ExrChannel> channels, std::span<const ExrAttribute> attributes = {});

}  // namespace toonray
