#include "toonray/frame/textures.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "toonray/io/png.h"
#include "support/test_support.h"

using namespace toonray;
namespace fs = std::filesystem;

namespace {

Scene with_textures(const std::vector<std::string>& paths) {
    Scene s;
    for (std::size_t i = 0; i < paths.size(); ++i) {
        Material m("m" + std::to_string(i));
        m.map_kd = paths[i];
        s.materials.push_back(m);
    }
    return s;
}

}  // namespace

TEST(TextureCache, DecodesEachFileOnceAndIndexesByMaterial) {
    test_support::TempDir dir("textures");
    ImageRgb8 tex(4, 2);
    tex(3, 1) = Rgb8{10, 20, 30};
    write_png(dir.path / "tex.png", tex);
    const std::string path = (dir.path / "tex.png").string();
    TextureCache cache;
    Warnings w;
    // Materials 1 and 3 share the file; the default material 0 and material 2 have none.
    const TextureSet& set = cache.load(with_textures({path, "", path}), w);
    EXPECT_TRUE(w.empty());
    ASSERT_EQ(set.size(), 4u);
    EXPECT_EQ(texture_of(set, 0), nullptr);
    ASSERT_NE(texture_of(set, 1), nullptr);
    EXPECT_EQ(texture_of(set, 2), nullptr);
    EXPECT_EQ(texture_of(set, 1), texture_of(set, 3));
    EXPECT_EQ((*texture_of(set, 1))(3, 1), (Rgb8{10, 20, 30}));
    EXPECT_EQ(texture_of(set, 99), nullptr);
    // The next frame reuses the decoded image even when the file is gone.
    const ImageRgb8* first = texture_of(set, 1);
    fs::remove(dir.path / "tex.png");
    const TextureSet& again = cache.load(with_textures({path}), w);
    EXPECT_TRUE(w.empty());
    EXPECT_EQ(texture_of(again, 1), first);
}

TEST(TextureCache, MissingAndBrokenFilesWarnOnceAndAreLeftOut) {
    test_support::TempDir dir("textures_bad");
    std::ofstream(dir.path / "fake.png") << "not a png";
    for (const char* name : {"missing.png", "fake.png"}) {
        TextureCache cache;
        Warnings w;
        const Scene scene = with_textures({(dir.path / name).string()});
        const TextureSet& set = cache.load(scene, w);
        ASSERT_EQ(w.size(), 1u) << name;
        EXPECT_NE(w[0].find(name), std::string::npos) << w[0];
        EXPECT_NE(w[0].find("material 'm0'"), std::string::npos) << w[0];
        EXPECT_EQ(texture_of(set, 1), nullptr);
        cache.load(scene, w);
        EXPECT_EQ(w.size(), 1u) << "warned again for " << name;
    }
}
