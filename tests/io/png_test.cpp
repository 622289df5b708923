#include "toonray/io/png.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "toonray/core/error.h"
#include "toonray/io/file.h"

using namespace toonray;
namespace fs = std::filesystem;

namespace {

fs::path temp_dir(const std::string& name) {
    fs::path dir = fs::temp_directory_path() / ("toonray_io_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
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
        write_png(dir / "a.png", image, {level});
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
    for (std::size_t cut : {std::size_t{0}, std::size_t{8}, std::size_t{30}, bytes.size() / 2, bytes.size() - 12}) {
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
