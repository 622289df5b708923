#include "toonray/scene/gltf_loader.h"

#include <gtest/gtest.h>

#include "scene/gltf_test_files.h"
#include "toonray/io/file.h"
#include "support/test_support.h"

namespace toonray {
namespace {

using gltf_test::data_uri;
using gltf_test::glb;
using gltf_test::triangle_bin;
using gltf_test::triangle_json;
using test_support::error_of;
using test_support::TempDir;

const std::string kSamples = std::string(TOONRAY_TEST_DATA_DIR) + "/gltf/";

GltfDocument load_text(const TempDir& dir, const std::string& name, const std::string& text,
                       Warnings& warnings, const GltfOptions& options = {}) {
    return load_gltf(dir.write(name, text), warnings, options);
}

std::string load_error(const std::string& name, const std::string& text) {
    TempDir dir("gltf");
    Warnings warnings;
    return error_of([&] { load_text(dir, name, text, warnings); });
}

TEST(GltfLoader, ReadsKhronosBox) {
    Warnings warnings;
    const GltfDocument doc = load_gltf(kSamples + "Box.gltf", warnings);
    EXPECT_TRUE(warnings.empty());
    ASSERT_EQ(doc.meshes.size(), 1u);
    ASSERT_EQ(doc.meshes[0].primitives.size(), 1u);
    const GltfPrimitive& prim = doc.meshes[0].primitives[0];
    EXPECT_EQ(prim.positions.size(), 24u);
    EXPECT_EQ(prim.normals.size(), 24u);
    EXPECT_EQ(prim.indices.size(), 36u);
    EXPECT_EQ(doc.triangles, 12u);
    ASSERT_EQ(doc.materials.size(), 2u);  // the default and the file's one
    EXPECT_FLOAT_EQ(doc.materials[1].kd.x, 0.8f);
    EXPECT_FLOAT_EQ(doc.materials[1].kd.y, 0.0f);
    EXPECT_EQ(prim.material, 1u);
    ASSERT_EQ(doc.roots, std::vector<int>{0});
    ASSERT_TRUE(doc.nodes[0].matrix.has_value());
    EXPECT_FLOAT_EQ((*doc.nodes[0].matrix)[6], -1.0f);  // Y up to Z up
    EXPECT_EQ(doc.nodes[1].parent, 0);
    EXPECT_FALSE(doc.deforms());
}

TEST(GltfLoader, ReadsEverySample) {
    for (const char* name : {"BoxAnimated", "RiggedSimple", "SimpleMorph", "SimpleSkin"}) {
        Warnings warnings;
        const GltfDocument doc = load_gltf(kSamples + name + ".gltf", warnings);
        EXPECT_GT(doc.triangles, 0u) << name;
        EXPECT_FALSE(doc.animations.empty()) << name;
    }
    Warnings warnings;
    EXPECT_TRUE(load_gltf(kSamples + "RiggedSimple.gltf", warnings).deforms());
    EXPECT_TRUE(load_gltf(kSamples + "SimpleMorph.gltf", warnings).deforms());
    EXPECT_FALSE(load_gltf(kSamples + "BoxAnimated.gltf", warnings).deforms());
}

TEST(GltfLoader, GlbAndEmbeddedGltfGiveTheSameTriangle) {
    TempDir dir("gltf");
    Warnings warnings;
    const auto from_glb = load_text(dir, "t.glb", glb(triangle_json(""), triangle_bin()), warnings);
    const auto from_gltf = load_text(
        dir, "t.gltf", triangle_json(R"(, "uri": ")" + data_uri(triangle_bin()) + "\""), warnings);
    for (const GltfDocument* doc : {&from_glb, &from_gltf}) {
        ASSERT_EQ(doc->meshes.size(), 1u);
        const auto& prim = doc->meshes[0].primitives[0];
        ASSERT_EQ(prim.positions.size(), 3u);
        EXPECT_EQ(prim.positions[1], Vec3f(1, 0, 0));
        EXPECT_EQ(prim.indices, (std::vector<std::uint32_t>{0, 1, 2}));
        EXPECT_EQ(doc->nodes[0].name, "tri");
    }
}

TEST(GltfLoader, ExternalBufferIsReadBesideTheFile) {
    TempDir dir("gltf");
    const auto bin = triangle_bin();
    dir.write("tri.bin", std::string(bin.begin(), bin.end()));
    Warnings warnings;
    const auto doc = load_text(dir, "t.gltf", triangle_json(R"(, "uri": "tri.bin")"), warnings);
    EXPECT_EQ(doc.triangles, 1u);
    EXPECT_NE(load_error("t.gltf", triangle_json(R"(, "uri": "missing.bin")")), "(no error)");
}

// Normalised integers, every index type, strips and fans, vertex colours, texture coordinates.
TEST(GltfLoader, ReadsIntegerComponentTypes) {
    std::vector<std::uint8_t> bin;
    // Positions 8 bytes apart (6 and 2 of padding), as byteStride must be a multiple of 4.
    gltf_test::put<std::int16_t>(bin,
                                 {0, 0, 0, 0, 32767, 0, 0, 0, 0, -32768, 0, 0, 32767, 32767, 0, 0});
    gltf_test::put<std::uint8_t>(bin, {0, 255, 255, 0, 0, 0, 255, 255});  // texcoords, 8 at 32
    gltf_test::put<std::uint16_t>(bin, {65535, 0, 0, 65535, 0, 65535, 0, 65535, 0, 0, 65535, 65535,
                                        65535, 65535, 65535, 65535});  // colours, 32 at 40
    gltf_test::put<std::uint8_t>(bin, {0, 1, 2, 3});                   // strip, 4 at 72
    gltf_test::put<std::uint32_t>(bin, {3, 2, 1});                     // 12 at 76
    const std::string json = R"({"asset": {"version": "2.0"}, "nodes": [{"mesh": 0}],
  "meshes": [{"primitives": [
    {"attributes": {"POSITION": 0, "TEXCOORD_0": 1, "COLOR_0": 2}, "indices": 3, "mode": 5},
    {"attributes": {"POSITION": 0}, "indices": 4},
    {"attributes": {"POSITION": 0}, "mode": 6},
    {"attributes": {"POSITION": 0}, "mode": 1}]}],
  "accessors": [
    {"bufferView": 0, "componentType": 5122, "normalized": true, "count": 4, "type": "VEC3",
     "byteOffset": 0},
    {"bufferView": 1, "componentType": 5121, "normalized": true, "count": 4, "type": "VEC2"},
    {"bufferView": 2, "componentType": 5123, "normalized": true, "count": 4, "type": "VEC4"},
    {"bufferView": 3, "componentType": 5121, "count": 4, "type": "SCALAR"},
    {"bufferView": 4, "componentType": 5125, "count": 3, "type": "SCALAR"}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 32, "byteStride": 8},
                  {"buffer": 0, "byteOffset": 32, "byteLength": 8},
                  {"buffer": 0, "byteOffset": 40, "byteLength": 32},
                  {"buffer": 0, "byteOffset": 72, "byteLength": 4},
                  {"buffer": 0, "byteOffset": 76, "byteLength": 12}],
  "buffers": [{"byteLength": 88}]})";
    TempDir dir("gltf");
    Warnings warnings;
    const auto doc = load_text(dir, "ints.glb", glb(json, bin), warnings);
    ASSERT_EQ(doc.meshes[0].primitives.size(), 3u);  // the line primitive is left out
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_NE(warnings[0].find("meshes[0].primitives[3].mode"), std::string::npos) << warnings[0];
    const auto& strip = doc.meshes[0].primitives[0];
    EXPECT_EQ(strip.positions[1], Vec3f(1, 0, 0));
    EXPECT_EQ(strip.positions[2], Vec3f(0, -1, 0));  // -32768 clamps to -1
    EXPECT_EQ(strip.positions[3], Vec3f(1, 1, 0));
    EXPECT_FLOAT_EQ(strip.texcoords[0].y, 0.0f);  // v = 1 in glTF is the bottom
    EXPECT_FLOAT_EQ(strip.texcoords[1].x, 1.0f);
    EXPECT_EQ(strip.colours[1], Vec3f(0, 1, 0));
    EXPECT_EQ(strip.indices, (std::vector<std::uint32_t>{0, 1, 2, 2, 1, 3}));
    EXPECT_EQ(doc.meshes[0].primitives[1].indices, (std::vector<std::uint32_t>{3, 2, 1}));
    EXPECT_EQ(doc.meshes[0].primitives[2].indices, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
}

// A bad file, and the error it gives: "/" + expected must be in the message.
struct BadFile {
    std::string name, text, expected;
};

void expect_errors(const std::vector<BadFile>& cases) {
    for (const BadFile& c : cases) {
        const std::string message = load_error(c.name, c.text);
        EXPECT_NE(message.find("/" + c.expected), std::string::npos) << c.name << ": " << message;
    }
}

const std::string kTriangleUri = R"(, "uri": ")" + data_uri(triangle_bin()) + "\"";

TEST(GltfLoader, BadFilesNameTheFileAndJsonPath) {
    const std::string& uri = kTriangleUri;
    std::string huge = triangle_json(uri, "", R"([{"mesh": 0}])", "4294967295");
    std::string view = triangle_json(uri);
    view.replace(view.find(R"("bufferView": 1)"), 15, R"("bufferView": 9)");
    std::string long_view = triangle_json(uri);
    long_view.replace(long_view.find(R"("byteLength": 6)"), 15, R"("byteLength": 99)");
    std::string garbage = triangle_json(R"(, "uri": "data:application/octet-stream;base64,@@@@")");
    std::string glb_text = glb(triangle_json(""), triangle_bin());
    expect_errors({
        {"huge.gltf", huge, "huge.gltf: accessors[0].count: 4294967295 exceeds the buffer view"},
        {"view.gltf", view, "view.gltf: accessor[1] invalid bufferView"},  // tinygltf's check
        {"long.gltf", long_view,
         "long.gltf: bufferViews[1].byteLength: 99 bytes from byte 36 exceed"},
        {"index.gltf", triangle_json(R"(, "uri": ")" + data_uri(triangle_bin(7)) + "\""),
         "index.gltf: meshes[0].primitives[0].indices: index 7 at element 2 is out of range (3 "
         "vertices)"},
        {"base64.gltf", garbage,
         "base64.gltf: buffers[0].uri: the data URI's payload is not base64"},
        {"cycle.gltf",
         triangle_json(uri, "", R"([{"mesh": 0}, {"children": [2]}, {"children": [1]}])"),
         "cycle.gltf: nodes[2].children: the node hierarchy has a cycle through nodes[1]"},
        {"two.gltf",
         triangle_json(uri, "", R"([{"mesh": 0, "children": [2]}, {"children": [2]}, {}])"),
         "two.gltf: nodes[1].children[0]: nodes[2] is already a child of nodes[0]"},
        {"self.gltf", triangle_json(uri, "", R"([{"mesh": 0, "children": [0]}])"),
         "self.gltf: nodes[0].children[0]: a node cannot be its own child"},
        {"trunc.glb", glb_text.substr(0, glb_text.size() - 10), "trunc.glb: byte 8: truncated GLB"},
        {"short.glb", glb_text.substr(0, 12), "short.glb: byte 12: truncated GLB"},
        {"json.gltf", "{\"asset\": {\"version\": \"2.0\"", "json.gltf: "},
        {"draco.gltf", triangle_json(uri, R"(, "extensionsUsed": ["KHR_draco_mesh_compression"],
                         "extensionsRequired": ["KHR_draco_mesh_compression"])"),
         "draco.gltf: extensionsRequired[0]: KHR_draco_mesh_compression is not supported"},
        {"mesh.gltf", triangle_json(uri, "", R"([{"mesh": 3}])"),
         "mesh.gltf: nodes[0].mesh: meshes 3 does not exist (1 meshes)"},
    });
}

// A node's weights stand for its mesh's default weights: one per morph target, and only on a
// node with a mesh.
TEST(GltfLoader, NodeWeightsMustMatchTheMeshsMorphTargets) {
    const std::string morph = read_file(kSamples + "SimpleMorph.gltf", 1 << 20);
    auto with_node = [&](const std::string& members) {
        std::string text = morph;
        text.replace(text.find(R"("mesh":0)"), 8, R"("mesh":0, )" + members);
        return text;
    };
    expect_errors({
        {"three.gltf", with_node(R"("weights": [0.1, 0.2, 0.3])"),
         "three.gltf: nodes[0].weights: 3 weights for the 2 morph targets of meshes[0]"},
        {"one.gltf", with_node(R"("weights": [1])"),
         "one.gltf: nodes[0].weights: 1 weights for the 2 morph targets of meshes[0]"},
        {"none.gltf", triangle_json(kTriangleUri, "", R"([{"mesh": 0, "weights": [0.5]}])"),
         "none.gltf: nodes[0].weights: 1 weights for the 0 morph targets of meshes[0]"},
        {"meshless.gltf",
         triangle_json(kTriangleUri, "", R"([{"mesh": 0}, {"weights": [0.5, 0.5]}])"),
         "meshless.gltf: nodes[1].weights: 2 weights on a node without a mesh"},
    });
    TempDir dir("gltf");
    Warnings warnings;
    const GltfDocument doc =
        load_text(dir, "two.gltf", with_node(R"("weights": [0.25, 0.75])"), warnings);
    EXPECT_EQ(doc.nodes[0].weights, (std::vector<float>{0.25f, 0.75f}));
}

// What tinygltf refuses without a reason, or leaves out without a word, is named by its JSON
// path, with the glTF 1.0 spelling pointed out where a file uses it.
TEST(GltfLoader, RefusedStructureIsNamedByJsonPath) {
    const std::string& uri = kTriangleUri;
    const std::string skin_1_0 =
        R"(, "skins": [{"jointNames": ["hip"], "bindShapeMatrix": [1, 0, 0, 0, 0, 1, 0, 0,
           0, 0, 1, 0, 0, 0, 0, 1]}])";
    const std::string triangle = triangle_json(uri);
    auto with_asset = [&](const std::string& asset) {
        std::string text = triangle;
        text.replace(text.find(R"("asset": {"version": "2.0"})"), 27, asset);
        return text;
    };
    auto replaced = [&](const std::string& from, const std::string& to) {
        std::string text = triangle;
        text.replace(text.find(from), from.size(), to);
        return text;
    };
    expect_errors({
        {"skin.gltf", triangle_json(uri, skin_1_0),
         "skin.gltf: skins[0]: missing \"joints\" (jointNames and bindShapeMatrix are glTF 1.0;"},
        {"skin.glb", glb(triangle_json("", skin_1_0), triangle_bin()),
         "skin.glb: skins[0]: missing \"joints\" (jointNames and bindShapeMatrix are glTF 1.0;"},
        {"joints.gltf", triangle_json(uri, R"(, "skins": [{"joints": ["hip"]}])"),
         "joints.gltf: skins[0].joints[0]: \"hip\" is not an index"},
        {"noasset.gltf", with_asset(R"("generator": "hand")"),
         "noasset.gltf: asset: missing (a glTF 2.0 file has \"asset\": {\"version\": \"2.0\"})"},
        {"assetarray.gltf", with_asset(R"("asset": ["2.0"])"),
         "assetarray.gltf: asset: an array is not an object"},
        {"noversion.gltf", with_asset(R"("asset": {"generator": "hand"})"),
         "noversion.gltf: asset: missing \"version\""},
        {"number.gltf", with_asset(R"("asset": {"version": 2.0})"),
         "number.gltf: asset.version: 2.0 is not a string (\"2.0\" for glTF 2.0)"},
        {"one.gltf", with_asset(R"("asset": {"version": "1.0"})"),
         "one.gltf: asset.version: \"1.0\": only glTF 2.0 is read"},
        {"three.gltf", with_asset(R"("asset": {"version": "3.0"})"),
         "three.gltf: asset.version: \"3.0\": only glTF 2.0 is read"},
        {"words.gltf", with_asset(R"("asset": {"version": "two"})"),
         "words.gltf: asset.version: \"two\" is not a version (major.minor, \"2.0\")"},
        {"min.gltf", with_asset(R"("asset": {"version": "2.0", "minVersion": "2.1"})"),
         "min.gltf: asset.minVersion: \"2.1\": only glTF 2.0 is read"},
        {"dict.gltf",
         replaced(R"("nodes": [{"mesh": 0, "name": "tri"}])",
                  R"("nodes": {"tri": {"meshes": ["m"]}})"),
         "dict.gltf: nodes: an object where an array is expected (glTF 1.0 names its objects; "
         "glTF 2.0 lists them)"},
        {"attributes.gltf",
         replaced(R"({"attributes": {"POSITION": 0}, "indices": 1})", R"({"indices": 1})"),
         "attributes.gltf: meshes[0].primitives[0]: missing \"attributes\""},
        {"mesh.gltf", replaced(R"({"mesh": 0, "name": "tri"})", R"({"mesh": "0"})"),
         "mesh.gltf: nodes[0].mesh: \"0\" is not an index"},
        {"camera.gltf", triangle_json(uri, R"(, "cameras": [{"perspective": {"yfov": 1}}])"),
         "camera.gltf: cameras[0]: missing \"type\""},
        {"yfov.gltf",
         triangle_json(uri, R"(, "cameras": [{"type": "perspective", "perspective": {}}])"),
         "yfov.gltf: cameras[0].perspective: missing \"yfov\""},
        {"target.gltf", triangle_json(uri, R"(, "animations": [{"channels": [{"sampler": 0}],
             "samplers": [{"input": 0, "output": 0}]}])"),
         "target.gltf: animations[0].channels[0]: missing \"target\""},
    });
    // A later minor version reads as 2.0 (glTF 2.x stays compatible).
    TempDir dir("gltf");
    Warnings warnings;
    EXPECT_EQ(load_text(dir, "minor.gltf", with_asset(R"("asset": {"version": "2.1"})"), warnings)
                  .meshes.size(),
              1u);
}

TEST(GltfLoader, HugeCountsHitTheLimitsNotTheMemory) {
    // No buffer view: the values would be zeros, four billion of them.
    std::string text = triangle_json(R"(, "uri": ")" + data_uri(triangle_bin()) + "\"");
    text.replace(text.find(R"({"bufferView": 0, )"), 18, "{");
    text.replace(text.find(R"("count": 3, "type": "VEC3")"), 11, R"("count": 4000000000,)");
    TempDir dir("gltf");
    Warnings warnings;
    try {
        load_text(dir, "zeros.gltf", text, warnings);
        FAIL() << "no error";
    } catch (const LimitError& e) {
        EXPECT_EQ(e.limit(), Limit::Vertices);
        EXPECT_NE(std::string(e.what()).find("zeros.gltf: accessors[0].count"), std::string::npos)
            << e.what();
    }
    GltfOptions options;
    options.limits.max_triangles = 0;
    try {
        load_text(dir, "tri.glb", glb(triangle_json(""), triangle_bin()), warnings, options);
        FAIL() << "no error";
    } catch (const LimitError& e) {
        EXPECT_EQ(e.limit(), Limit::Triangles);
    }
    options = {};
    options.limits.max_input_bytes = 100;
    EXPECT_NE(
        error_of([&] { load_gltf(kSamples + "Box.gltf", warnings, options); }).find("Box.gltf"),
        std::string::npos);
}

TEST(GltfLoader, MissingOrBadTextureIsAWarning) {
    const std::string materials = R"(, "materials": [{"name": "skin", "pbrMetallicRoughness":
        {"baseColorFactor": [0.5, 0.5, 0.5, 1], "baseColorTexture": {"index": 0}}}],
      "textures": [{"source": 0}], "images": [{"uri": "missing.png"}])";
    std::string text = triangle_json(R"(, "uri": ")" + data_uri(triangle_bin()) + "\"", materials);
    text.replace(text.find(R"("indices": 1)"), 12, R"("indices": 1, "material": 0)");
    TempDir dir("gltf");
    Warnings warnings;
    const auto doc = load_text(dir, "tex.gltf", text, warnings);
    ASSERT_EQ(doc.materials.size(), 2u);
    EXPECT_EQ(doc.materials[1].name, "skin");
    EXPECT_FALSE(doc.materials[1].kd_image);
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_NE(warnings[0].find("missing.png"), std::string::npos) << warnings[0];
    EXPECT_NE(warnings[0].find("'skin'"), std::string::npos) << warnings[0];

    dir.write("missing.png", "not a png");
    warnings.clear();
    load_text(dir, "tex.gltf", text, warnings);
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_NE(warnings[0].find("not a PNG or JPEG"), std::string::npos) << warnings[0];
}

TEST(GltfLoader, RecognisesGltfPaths) {
    EXPECT_TRUE(is_gltf_path("a/scene.GLB"));
    EXPECT_TRUE(is_gltf_path("scene.gltf"));
    EXPECT_FALSE(is_gltf_path("scene.obj"));
}

}  // namespace
}  // namespace toonray
