#include "toonray/io/png.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <utility>

#include "toonray/core/error.h"
#include "toonray/io/file.h"

using namespace toonray;
namespace fs = std::filesystem;

namespace {

PngOptions at_level(int level) {
    PngOptions options;
    options.level = level;
    return options;
}

fs::path temp_dir(const std::string& name) {
    fs::path dir =
        fs::temp_directory_path() / ("toonray_io_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

/// Colour type from the IHDR chunk (byte 25 of the file): 2 RGB, 3 indexed, 0 gray.
int colour_type(const std::vector<std::uint8_t>& png) { return png.at(25); }

/// An image with `colours` distinct colours (at most 2^24), in runs and rows like a toon frame,
/// plus single pixels so that every colour appears.
ImageRgb8 image_with_colours(int width, int height, int colours, std::uint32_t seed) {
    ImageRgb8 image(width, height);
    std::mt19937 rng(seed);
    auto colour_of = [](std::uint32_t i) {
        i *= 2654435761u;  // spread the colours over the cube
        return Rgb8{static_cast<std::uint8_t>(i >> 24), static_cast<std::uint8_t>(i >> 16),
                    static_cast<std::uint8_t>(i >> 8)};
    };
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            image(x, y) =
                colour_of(((x / 7) + (y / 5) * 3 + static_cast<int>(rng() % 2)) % colours);
    for (int i = 0; i < colours && i < width * height; ++i)
        image(i % width, i / width) = colour_of(i);
    return image;
}

void expect_round_trip(const ImageRgb8& image, const PngOptions& options, int expect_colour_type) {
    const auto bytes = encode_png(image.width(), image.height(), 3,
                                  reinterpret_cast<const std::uint8_t*>(image.data()), options);
    EXPECT_EQ(colour_type(bytes), expect_colour_type);
    DecodedPng decoded = decode_png(bytes, "memory");
    ASSERT_EQ(decoded.width, image.width());
    ASSERT_EQ(decoded.height, image.height());
    for (int y = 0; y < image.height(); ++y)
        for (int x = 0; x < image.width(); ++x)
            ASSERT_EQ(decoded.rgb(x, y), image(x, y))
                << x << "," << y << " of " << image.width() << "x" << image.height();
}

}  // namespace

TEST(Png, RgbRoundTripsThroughLibpng) {
    ImageRgb8 image(37, 23);  // odd sizes exercise row filtering
    std::mt19937 rng(7);
    for (int y = 0; y < image.height(); ++y)
        for (int x = 0; x < image.width(); ++x)
            image(x, y) = {static_cast<std::uint8_t>(rng()), static_cast<std::uint8_t>(x * 7),
                           static_cast<std::uint8_t>(y * 11)};
    fs::path dir = temp_dir("rgb");
    for (int level : {1, 6, 12}) {
        write_png(dir / "a.png", image, at_level(level));
        DecodedPng decoded = read_png(dir / "a.png");
        ASSERT_EQ(decoded.width, 37);
        ASSERT_EQ(decoded.height, 23);
        for (int y = 0; y < image.height(); ++y)
            for (int x = 0; x < image.width(); ++x) ASSERT_EQ(decoded.rgb(x, y), image(x, y));
    }
    fs::remove_all(dir);
}

TEST(Png, GrayRoundTripsThroughLibpng) {
    ImageGray8 image(16, 9);
    for (int y = 0; y < 9; ++y)
        for (int x = 0; x < 16; ++x) image(x, y) = static_cast<std::uint8_t>(x * 16 + y);
    fs::path dir = temp_dir("gray");
    write_png(dir / "g.png", image);
    DecodedPng decoded = read_png(dir / "g.png");
    for (int y = 0; y < 9; ++y)
        for (int x = 0; x < 16; ++x) {
            Rgb8 expect = {image(x, y), image(x, y), image(x, y)};
            ASSERT_EQ(decoded.rgb(x, y), expect);
        }
    fs::remove_all(dir);
}

TEST(Png, TruncatedOrCorruptFilesAreInvalid) {
    ImageRgb8 image(64, 64, Rgb8{10, 200, 30});
    auto bytes = encode_png(64, 64, 3, reinterpret_cast<const std::uint8_t*>(image.data()));
    fs::path dir = temp_dir("trunc");
    write_file_atomic(dir / "ok.png", bytes);
    EXPECT_TRUE(is_valid_png(dir / "ok.png"));
    for (std::size_t cut :
         {std::size_t{0}, std::size_t{8}, std::size_t{30}, bytes.size() / 2, bytes.size() - 12}) {
        write_file_atomic(dir / "cut.png", std::span(bytes.data(), cut));
        EXPECT_FALSE(is_valid_png(dir / "cut.png")) << "cut at " << cut;
    }
    EXPECT_FALSE(is_valid_png(dir / "missing.png"));
    fs::remove_all(dir);
}

TEST(AtomicWrite, ReplacesTheTargetAndLeavesNoTemporary) {
    fs::path dir = temp_dir("atomic");
    std::vector<std::uint8_t> a(1000, 1), b(10, 2);
    write_file_atomic(dir / "f.bin", a);
    write_file_atomic(dir / "f.bin", b);
    EXPECT_EQ(fs::file_size(dir / "f.bin"), 10u);
    int entries = 0;
    for (auto& e : fs::directory_iterator(dir)) {
        (void)e;
        ++entries;
    }
    EXPECT_EQ(entries, 1);
    fs::remove_all(dir);
}

TEST(AtomicWrite, FailsCleanlyInAMissingDirectory) {
    fs::path dir = temp_dir("nodir");
    std::vector<std::uint8_t> a(10, 1);
    EXPECT_THROW(write_file_atomic(dir / "no" / "such" / "f.bin", a), Error);
    fs::remove_all(dir);
}

TEST(ReadFile, MissingFileNamesThePath) {
    try {
        read_file("/nonexistent/toonray.obj");
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("/nonexistent/toonray.obj"), std::string::npos);
    }
}

TEST(Png, FewColoursAreIndexedAndRoundTrip) {
    // Up to 256 colours are written with a palette; from 257 on as RGB. Both decode to exactly
    // the pixels given, at every size (1x1, odd widths, a row, a column) and level.
    for (auto [w, h] : {std::pair{1, 1}, {1, 40}, {33, 1}, {37, 23}, {640, 3}}) {
        for (int colours : {1, 2, 255, 256, 257, 1000}) {
            SCOPED_TRACE(testing::Message() << w << "x" << h << ", " << colours << " colours");
            ImageRgb8 image = image_with_colours(w, h, colours, 11);
            std::set<std::uint32_t> used;
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x)
                    used.insert(image(x, y)[0] << 16 | image(x, y)[1] << 8 | image(x, y)[2]);
            for (int level : {1, 12})
                expect_round_trip(image, at_level(level), used.size() <= 256 ? 3 : 2);
        }
    }
}

TEST(Png, NoiseAndLargeFramesRoundTrip) {
    ImageRgb8 noise(641, 359);
    std::mt19937 rng(3);
    for (int y = 0; y < noise.height(); ++y)
        for (int x = 0; x < noise.width(); ++x)
            noise(x, y) = {static_cast<std::uint8_t>(rng()), static_cast<std::uint8_t>(rng()),
                           static_cast<std::uint8_t>(rng())};
    expect_round_trip(noise, {}, 2);
    // A 4K frame of toon-like bands, indexed; and with one pixel more than 256 colours, RGB.
    ImageRgb8 frame = image_with_colours(3840, 2160, 200, 5);
    expect_round_trip(frame, {}, 3);
    frame(3839, 2159) = {1, 2, 3};
    for (int i = 0; i < 60; ++i) frame(i, 2159) = {static_cast<std::uint8_t>(i), 7, 9};
    expect_round_trip(frame, {}, 2);
}
