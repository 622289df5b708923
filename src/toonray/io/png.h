#pragma once
/// PNG encoding (libdeflate) and decoding (libpng).
///
/// Encoding is ours because libpng at its default level is 5-10 times slower on a 720p frame. Toon
/// frames usually have at most 256 colours: those are written indexed (palette, one byte a
/// pixel), others as RGB; rows unfiltered, compressed with libdeflate. At level 1 an indexed
/// 720p toon frame takes about half the time of the same frame as RGB, and files are 0.4-0.7
/// times libpng's default size (RGB: about 0.95). Figures in docs/performance.md.
/// Decoding uses libpng: it is only needed for validation and
/// tests, where speed does not matter and a second, independent implementation is the point.

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "toonray/core/image.h"

namespace toonray {

struct PngOptions {
    int level = 1;  ///< libdeflate level, 1 (fastest) to 12 (smallest)
    /// Text chunks written before the image data, keyword and text: tEXt when the text is
    /// ASCII, else iTXt (UTF-8). Keywords are 1 to 79 printable Latin-1 characters.
    std::vector<std::pair<std::string, std::string>> text;
};

/// Encodes 8-bit pixels (channels 1 = gray, 3 = RGB) as a complete PNG file in memory.
std::vector<std::uint8_t> encode_png(int width, int height, int channels,
                                     const std::uint8_t* pixels, const PngOptions& options = {});

/// Encodes and writes atomically. Throws Error on failure.
void write_png(const std::filesystem::path& path, const ImageRgb8& image,
               const PngOptions& options = {});
void write_png(const std::filesystem::path& path, const ImageGray8& image,
               const PngOptions& options = {});

/// A decoded PNG, converted to 8-bit RGB.
struct DecodedPng {
    int width = 0, height = 0;
    ImageRgb8 rgb;
};

/// Decodes a PNG file with libpng. Throws Error when the file is missing, truncated or corrupt,
/// or when its size exceeds limits().max_image_pixels (checked before any pixel is allocated).
DecodedPng read_png(const std::filesystem::path& path);

/// As read_png, from bytes in memory; `name` names them in messages.
DecodedPng decode_png(std::span<const std::uint8_t> bytes, std::string_view name);

/// True when `path` is a complete, decodable PNG (used by `batch --resume`).
bool is_valid_png(const std::filesystem::path& path);

}  // namespace toonray
