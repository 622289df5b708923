// Replays every fuzz target over its seed corpus (fuzz/corpus/TARGET) and the inputs that once
// crashed it (tests/robustness/data/fuzz/TARGET). The targets' own checks run as they do under
// libFuzzer: a FUZZ_CHECK failure aborts, and any exception but toonray::Error fails the test.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "robustness_util.h"
#include "toonray/core/limits.h"

extern "C" {
int toonray_fuzz_obj(const std::uint8_t*, std::size_t);
int toonray_fuzz_mtl(const std::uint8_t*, std::size_t);
int toonray_fuzz_camera(const std::uint8_t*, std::size_t);
int toonray_fuzz_note_script(const std::uint8_t*, std::size_t);
int toonray_fuzz_midi(const std::uint8_t*, std::size_t);
int toonray_fuzz_camera_path(const std::uint8_t*, std::size_t);
int toonray_fuzz_options(const std::uint8_t*, std::size_t);
int toonray_fuzz_png(const std::uint8_t*, std::size_t);
int toonray_fuzz_render(const std::uint8_t*, std::size_t);
int toonray_fuzz_shading(const std::uint8_t*, std::size_t);
int toonray_fuzz_gltf(const std::uint8_t*, std::size_t);
int toonray_fuzz_glb(const std::uint8_t*, std::size_t);
int toonray_fuzz_line_style(const std::uint8_t*, std::size_t);
int toonray_fuzz_settings(const std::uint8_t*, std::size_t);
int toonray_fuzz_tone(const std::uint8_t*, std::size_t);
int toonray_fuzz_init_png(int*, char***);
}

namespace {

namespace fs = std::filesystem;

struct Target {
    const char* name;
    int (*run)(const std::uint8_t*, std::size_t);
    int (*init)(int*, char***) = nullptr;
};

void PrintTo(const Target& t, std::ostream* os) { *os << t.name; }

class FuzzReplay : public ::testing::TestWithParam<Target> {};

std::vector<fs::path> inputs_of(const std::string& target) {
    std::vector<fs::path> files;
    for (const fs::path& dir : {fs::path(TOONRAY_FUZZ_DIR) / "corpus" / target,
                                fs::path(TOONRAY_ROBUSTNESS_DATA) / "fuzz" / target}) {
        std::error_code ec;
        if (!fs::is_directory(dir, ec)) continue;
        for (const auto& e : fs::directory_iterator(dir))
            if (e.is_regular_file()) files.push_back(e.path());
    }
    std::sort(files.begin(), files.end());
    return files;
}

}  // namespace

TEST_P(FuzzReplay, SeedsAndPastCrashesPass) {
    const Target& t = GetParam();
    const toonray::Limits saved = toonray::limits();
    if (t.init) t.init(nullptr, nullptr);
    std::vector<fs::path> files = inputs_of(t.name);
    ASSERT_FALSE(files.empty()) << "no seeds for " << t.name;
    for (const fs::path& f : files) {
        SCOPED_TRACE(f.string());
        std::string bytes = robustness::slurp(f);
        EXPECT_EQ(t.run(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()), 0);
    }
    toonray::set_limits(saved);
}

INSTANTIATE_TEST_SUITE_P(
    Targets, FuzzReplay,
    ::testing::Values(
        Target{"obj", toonray_fuzz_obj}, Target{"mtl", toonray_fuzz_mtl},
        Target{"camera", toonray_fuzz_camera}, Target{"note_script", toonray_fuzz_note_script},
        Target{"midi", toonray_fuzz_midi}, Target{"camera_path", toonray_fuzz_camera_path},
        Target{"options", toonray_fuzz_options},
        Target{"png", toonray_fuzz_png, toonray_fuzz_init_png},
        Target{"render", toonray_fuzz_render}, Target{"shading", toonray_fuzz_shading},
        Target{"gltf", toonray_fuzz_gltf}, Target{"glb", toonray_fuzz_glb},
        Target{"line_style", toonray_fuzz_line_style}, Target{"settings", toonray_fuzz_settings},
        Target{"tone", toonray_fuzz_tone}),
    [](const auto& info) { return std::string(info.param.name); });
