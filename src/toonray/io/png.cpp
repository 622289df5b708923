#include "toonray/io/png.h"

#include <algorithm>

#include <libdeflate.h>
#include <png.h>

#include <array>
#include <cstring>
#include <fmt/format.h>
#include <memory>

#include "toonray/core/error.h"
#include "toonray/core/limits.h"
#include "toonray/io/file.h"

namespace toonray {
namespace {

void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v) {
    out.push_back(static_cast<std::uint8_t>(v >> 24));
    out.push_back(static_cast<std::uint8_t>(v >> 16));
    out.push_back(static_cast<std::uint8_t>(v >> 8));
    out.push_back(static_cast<std::uint8_t>(v));
}

// Appends one chunk: length, type, data, CRC of type + data.
void put_chunk(std::vector<std::uint8_t>& out, const char type[4], const std::uint8_t* data,
               std::size_t size) {
    put_u32(out, static_cast<std::uint32_t>(size));
    std::size_t type_at = out.size();
    out.insert(out.end(), type, type + 4);
    if (size) out.insert(out.end(), data, data + size);
    std::uint32_t crc = libdeflate_crc32(0, out.data() + type_at, size + 4);
    put_u32(out, crc);
}

// A text chunk: tEXt (keyword, NUL, Latin-1 text) when the text is ASCII, else iTXt (keyword,
// NUL, uncompressed, no method, no language tag, no translated keyword, UTF-8 text).
void put_text_chunk(std::vector<std::uint8_t>& out, const std::string& keyword,
                    const std::string& text) {
    if (keyword.empty() || keyword.size() > 79 || keyword.find('\0') != std::string::npos)
        throw Error(fmt::format("PNG: text keyword '{}' is not 1 to 79 characters", keyword));
    const bool ascii =
        std::all_of(text.begin(), text.end(), [](char c) { return (c & 0x80) == 0 && c != 0; });
    std::vector<std::uint8_t> data(keyword.begin(), keyword.end());
    data.push_back(0);
    if (!ascii) data.insert(data.end(), {0, 0, 0, 0});  // flag, method, language, translated
    data.insert(data.end(), text.begin(), text.end());
    put_chunk(out, ascii ? "tEXt" : "iTXt", data.data(), data.size());
}

struct CompressorDeleter {
    void operator()(libdeflate_compressor* c) const { libdeflate_free_compressor(c); }
};

/// Toon frames mostly have a few dozen to a few hundred colours (flat bands, lines, background).
/// With at most 256, the image is written indexed (PNG colour type 3): one byte a pixel instead
/// of three, which deflate compresses in about half the time to about half the size
/// (docs/performance.md). Fills `rows` with each row's filter byte (0, None) and its pixels'
/// palette indices, and `palette` with the colours (RGB triplets) in order of first use.
/// Returns false as soon as a 257th colour appears.
bool index_colours(const std::uint8_t* pixels, int width, int height,
                   std::vector<std::uint8_t>& rows, std::vector<std::uint8_t>& palette) {
    // Open addressing over colour + 1 (0 marks a free slot); 1024 slots for 256 colours keep
    // probes short. Runs of one colour, the common case, skip the table (`previous`).
    constexpr std::uint32_t kSlotBits = 10;
    std::array<std::uint32_t, 1u << kSlotBits> keys{};
    std::array<std::uint8_t, 1u << kSlotBits> indices{};
    palette.clear();
    rows.resize((static_cast<std::size_t>(width) + 1) * static_cast<std::size_t>(height));
    std::uint8_t* out = rows.data();
    std::uint32_t previous = 0xFFFFFFFF;  // no colour
    std::uint8_t previous_index = 0;
    const std::uint8_t* p = pixels;
    for (int y = 0; y < height; ++y) {
        *out++ = 0;  // filter None: filters predict colours, not palette indices
        for (int x = 0; x < width; ++x, p += 3) {
            const std::uint32_t colour =
                std::uint32_t{p[0]} << 16 | std::uint32_t{p[1]} << 8 | p[2];
            if (colour != previous) {
                std::uint32_t slot =
                    (colour * 0x9E3779B1u) >> (32 - kSlotBits);  // Fibonacci hashing
                while (keys[slot] != colour + 1) {
                    if (keys[slot] == 0) {
                        if (palette.size() == 3 * 256) return false;
                        keys[slot] = colour + 1;
                        indices[slot] = static_cast<std::uint8_t>(palette.size() / 3);
                        palette.insert(palette.end(), p, p + 3);
                        break;
                    }
                    slot = (slot + 1) & ((1u << kSlotBits) - 1);
                }
                previous = colour;
                previous_index = indices[slot];
            }
            *out++ = previous_index;
        }
    }
    return true;
}

}  // namespace

std::vector<std::uint8_t> encode_png(int width, int height, int channels,
                                     const std::uint8_t* pixels, const PngOptions& options) {
    const std::size_t stride = static_cast<std::size_t>(width) * channels;
    std::vector<std::uint8_t> rows, palette;
    const bool indexed = channels == 3 && index_colours(pixels, width, height, rows, palette);
    if (!indexed) {
        // Every row with filter None. Measured on toon frames at libdeflate levels 1 to 6, None
        // gives smaller files than Up, Sub, Paeth or a per-row choice by the least sum of
        // absolute values (libpng's heuristic): a flat colour repeats at a distance of one
        // pixel, which deflate finds. It also saves the filtering pass (docs/performance.md).
        rows.resize((stride + 1) * static_cast<std::size_t>(height));
        for (int y = 0; y < height; ++y) {
            std::uint8_t* dst = rows.data() + (stride + 1) * y;
            dst[0] = 0;
            std::memcpy(dst + 1, pixels + stride * y, stride);
        }
    }
    std::unique_ptr<libdeflate_compressor, CompressorDeleter> compressor(
        libdeflate_alloc_compressor(options.level));
    if (!compressor) throw Error(fmt::format("PNG: invalid compression level {}", options.level));
    std::vector<std::uint8_t> idat(libdeflate_zlib_compress_bound(compressor.get(), rows.size()));
    std::size_t idat_size = libdeflate_zlib_compress(compressor.get(), rows.data(), rows.size(),
                                                     idat.data(), idat.size());
    if (idat_size == 0) throw Error("PNG: compression failed");

    std::vector<std::uint8_t> out;
    out.reserve(idat_size + palette.size() + 64);
    static const std::uint8_t signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    out.insert(out.end(), signature, signature + 8);
    std::uint8_t ihdr[13];
    auto be32 = [](std::uint8_t* p, std::uint32_t v) {
        p[0] = v >> 24;
        p[1] = v >> 16;
        p[2] = v >> 8;
        p[3] = v;
    };
    be32(ihdr, static_cast<std::uint32_t>(width));
    be32(ihdr + 4, static_cast<std::uint32_t>(height));
    ihdr[8] = 8;                                    // bit depth
    ihdr[9] = indexed ? 3 : channels == 3 ? 2 : 0;  // colour type: indexed, RGB or grayscale
    ihdr[10] = ihdr[11] = ihdr[12] = 0;             // deflate, adaptive filtering, no interlace
    put_chunk(out, "IHDR", ihdr, sizeof ihdr);
    if (indexed) put_chunk(out, "PLTE", palette.data(), palette.size());
    for (const auto& [keyword, text] : options.text) put_text_chunk(out, keyword, text);
    put_chunk(out, "IDAT", idat.data(), idat_size);
    put_chunk(out, "IEND", nullptr, 0);
    return out;
}

void write_png(const std::filesystem::path& path, const ImageRgb8& image,
               const PngOptions& options) {
    auto bytes = encode_png(image.width(), image.height(), 3,
                            reinterpret_cast<const std::uint8_t*>(image.data()), options);
    write_file_atomic(path, bytes);
}

void write_png(const std::filesystem::path& path, const ImageGray8& image,
               const PngOptions& options) {
    auto bytes = encode_png(image.width(), image.height(), 1, image.data(), options);
    write_file_atomic(path, bytes);
}

DecodedPng decode_png(std::span<const std::uint8_t> bytes, std::string_view name) {
    // libpng's reader stops after the image data, so a file cut just before its IEND chunk
    // would still decode: require the complete trailer.
    static const std::uint8_t iend[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xAE, 0x42, 0x60, 0x82};
    if (bytes.size() < 12 || std::memcmp(bytes.data() + bytes.size() - 12, iend, 12) != 0)
        throw Error(fmt::format("{}: truncated PNG (no IEND chunk at the end)", name));
    png_image img;
    std::memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&img, bytes.data(), bytes.size()))
        throw Error(fmt::format("{}: not a PNG file: {}", name, img.message));
    struct Freer {
        png_image* img;
        ~Freer() { png_image_free(img); }
    } freer{&img};
    // The header may announce any size up to 2^31 - 1 squared: check before allocating.
    const std::uint64_t pixels = std::uint64_t{img.width} * img.height;
    if (img.width > 0x7FFFFFFFu || img.height > 0x7FFFFFFFu || pixels > limits().max_image_pixels)
        throw LimitError(Limit::ImagePixels,
                         fmt::format("{}: a {}x{} PNG has more pixels than the limit of {}", name,
                                     img.width, img.height, limits().max_image_pixels));
    img.format = PNG_FORMAT_RGB;
    DecodedPng result;
    result.width = static_cast<int>(img.width);
    result.height = static_cast<int>(img.height);
    result.rgb.resize(result.width, result.height);
    if (!png_image_finish_read(&img, nullptr, result.rgb.data(), 0, nullptr))
        throw Error(fmt::format("{}: corrupt PNG: {}", name, img.message));
    return result;
}

DecodedPng read_png(const std::filesystem::path& path) {
    std::string data = read_file(path);
    return decode_png(std::span(reinterpret_cast<const std::uint8_t*>(data.data()), data.size()),
                      path.string());
}

bool is_valid_png(const std::filesystem::path& path) {
    try {
        read_png(path);
        return true;
    } catch (const std::exception&) {
        return false;
    }
}

}  // namespace toonray
