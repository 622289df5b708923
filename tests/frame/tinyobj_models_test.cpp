// tinyobjloader's own test models (tests/data/tinyobjloader, MIT, copied from
// github.com/tinyobjloader/tinyobjloader models/) as a real-world suite: OBJ files as other tools
// write and read them. Every one renders, except those that are truly broken (a vertex index
// out of range or zero), whose error names the file and the line.

#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <set>
#include <string>

#include "toonray/frame/frame_renderer.h"
#include "toonray/io/png.h"
#include "toonray/scene/obj_loader.h"
#include "support/test_scenes.h"
#include "support/test_support.h"

using namespace toonray;
namespace fs = std::filesystem;

namespace {

const fs::path kModels = fs::path(TOONRAY_TEST_DATA_DIR) / "tinyobjloader";

// The broken files and the start of their errors (after the path).
const std::map<std::string, std::string> kBroken = {
    {"invalid-relative-texture-index.obj",
     ":2: face vertex index 1 out of range (0 vertices defined so far)"},
    {"invalid-relative-vertex-index.obj",
     ":1: face vertex index -4 out of range (0 vertices defined so far)"},
    {"issue-140-zero-face-idx.obj", ":16: face vertex index 0 in '0/0/0'"},
};

}  // namespace

TEST(TinyobjModels, EveryModelRendersUnlessTrulyBroken) {
    test_support::TempDir dir("tinyobj_models");
    int rendered = 0, refused = 0;
    std::set<std::string> seen;
    for (const fs::directory_entry& entry : fs::directory_iterator(kModels)) {
        if (entry.path().extension() != ".obj") continue;
        const std::string name = entry.path().filename().string();
        seen.insert(name);
        SCOPED_TRACE(name);
        const fs::path output = dir.path / (entry.path().stem().string() + ".png");
        try {
            Scene scene;
            Warnings warnings;
            load_obj(entry.path(), scene, warnings);
            FrameOptions options;
            options.settings.width = 48;
            options.settings.height = 36;
            FrameRenderer renderer;
            renderer.render(test_support::scene_frame(scene, 48, 36), output, options, warnings);
            EXPECT_FALSE(kBroken.contains(name)) << "a broken file rendered";
            const DecodedPng png = read_png(output);
            EXPECT_EQ(png.width, 48);
            ++rendered;
        } catch (const Error& e) {
            ASSERT_TRUE(kBroken.contains(name)) << "refused: " << e.what();
            EXPECT_EQ(std::string(e.what()).rfind(entry.path().string() + kBroken.at(name), 0), 0u)
                << e.what();
            EXPECT_FALSE(fs::exists(output));
            ++refused;
        }
    }
    // The folder as copied: 47 models, of which 3 are broken.
    EXPECT_EQ(seen.size(), 47u);
    EXPECT_EQ(rendered, 44);
    EXPECT_EQ(refused, 3);
}

TEST(TinyobjModels, LenientCasesKeepWhatTheyCan) {
    auto load = [](const char* name, Warnings& warnings) {
        Scene scene;
        load_obj(kModels / name, scene, warnings);
        return scene;
    };
    Warnings w;
    // A `nan` coordinate: its faces dropped, the others kept.
    const Scene nan = load("test-nan.obj", w);
    EXPECT_GT(nan.triangle_count(), 0u);
    // Normal indices with no `vn`: geometric normals.
    const Scene torus = load("catmark_torus_creases0.obj", w);
    EXPECT_GT(torus.triangle_count(), 0u);
    for (const auto& n : torus.tri_normals) EXPECT_EQ(n[0], kNoIndex);
    // `l` elements are polylines; `p` elements are ignored.
    EXPECT_EQ(load("line-prim.obj", w).polylines.size(), 2u);
    EXPECT_EQ(load("points-prim.obj", w).triangle_count(), 0u);
    // Library names with escaped spaces (the first two libraries do not exist: warnings).
    Warnings ws;
    const Scene spaces = load("mtl filename with whitespace issue46.obj", ws);
    EXPECT_GT(spaces.materials.size(), 1u);
}
