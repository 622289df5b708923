#include "toonray/scene/obj_loader.h"

#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstring>
#include <fmt/format.h>
#include <random>

#include <filesystem>
#include <fstream>

#include "toonray/core/error.h"
#include "toonray/scene/mtl_loader.h"
#include "toonray/scene/obj_fast_path.h"
#include "support/same_bits.h"

using namespace toonray;
namespace fs = std::filesystem;

namespace {

using test_support::same_bits;
bool same_scene(const Scene& a, const Scene& b) {
    std::vector<std::string> names_a = a.objects, names_b = b.objects;
    for (const Material& m : a.materials) names_a.push_back(m.name + "/" + m.map_kd);
    for (const Material& m : b.materials) names_b.push_back(m.name + "/" + m.map_kd);
    const bool same_camera =
        a.camera.has_value() == b.camera.has_value() &&
        (!a.camera || std::memcmp(&*a.camera, &*b.camera, sizeof(CameraSpec)) == 0);
    return same_bits(a.positions, b.positions) && same_bits(a.normals, b.normals) &&
           same_bits(a.texcoords, b.texcoords) && same_bits(a.tri_positions, b.tri_positions) &&
           same_bits(a.tri_normals, b.tri_normals) && same_bits(a.tri_texcoords, b.tri_texcoords) &&
           same_bits(a.tri_material, b.tri_material) && same_bits(a.tri_object, b.tri_object) &&
           same_bits(a.polylines, b.polylines) && same_bits(a.polyline_points, b.polyline_points) &&
           names_a == names_b && same_camera;
}

// What parse_obj makes of a text: the scene and its warnings, or the error.
struct Parsed {
    Scene scene;
    Warnings warnings;
    std::string error;
};

template <typename Read>
Parsed parsed_by(const Read& read) {
    Parsed out;
    try {
        read(out.scene, out.warnings);
    } catch (const Error& e) {
        out.error = e.what();
    }
    return out;
}

void expect_same(const Parsed& a, const Parsed& b, std::string_view text, std::string_view how) {
    EXPECT_EQ(a.error, b.error) << how << ": " << text;
    EXPECT_EQ(a.warnings, b.warnings) << how << ": " << text;
    EXPECT_TRUE(same_scene(a.scene, b.scene)) << how << ": " << text;
}

// Every text is read in every way: as it is, where a short text is left to the general path;
// followed by a padding comment, which puts all of it in the fast path's padded zone
// (obj_fast_path.h); and that in chunks of a line or a few, read ahead on this thread or by
// others and merged. All must read it the same. An empty line comes first in the padding: a
// last line continued with `\` is then joined with nothing, as at the end of the text.
Parsed parse_every_way(std::string_view text, const fs::path& path) {
    Parsed plain = parsed_by(
        [&](Scene& scene, Warnings& warnings) { parse_obj(text, path, scene, warnings); });
    const std::string padded = std::string(text) + "\n\n#" + std::string(80, ' ') + "\n";
    expect_same(plain, parsed_by([&](Scene& scene, Warnings& warnings) {
                    parse_obj(padded, path, scene, warnings);
                }),
                text, "padded");
    for (const std::pair<std::size_t, int>& way :
         {std::pair<std::size_t, int>{1, 0}, {13, 0}, {1, 3}, {40, 2}})
        expect_same(plain, parsed_by([&](Scene& scene, Warnings& warnings) {
                        wavefront::parse_obj_in_chunks(padded, path, scene, warnings, {}, way.first,
                                                       way.second);
                    }),
                    text, fmt::format("chunks of {} bytes, {} threads", way.first, way.second));
    return plain;
}

Scene parse(std::string_view text, Warnings* warnings_out = nullptr,
            const fs::path& path = "test.obj") {
    Parsed parsed = parse_every_way(text, path);
    if (!parsed.error.empty()) throw Error(parsed.error);
    if (warnings_out) *warnings_out = parsed.warnings;
    return std::move(parsed.scene);
}

std::string error_of(std::string_view text, const fs::path& path = "test.obj") {
    const Parsed parsed = parse_every_way(text, path);
    return parsed.error.empty() ? "(no error)" : parsed.error;
}

fs::path temp_dir(const std::string& name) {
    fs::path dir =
        fs::temp_directory_path() / ("toonray_obj_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

void write(const fs::path& p, std::string_view text) { std::ofstream(p, std::ios::binary) << text; }

const char* kQuad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

}  // namespace

TEST(ObjLoader, ReadsAllFourIndexForms) {
    Scene s = parse(std::string(kQuad) +
                    "vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\nvn 0 0 -1\n"
                    "f 1 2 3\nf 1/1 2/2 3/3\nf 1//1 2//1 3//2\nf 1/1/1 2/2/1 3/3/1\n");
    ASSERT_EQ(s.triangle_count(), 4u);
    for (std::size_t i = 0; i < 4; ++i)
        EXPECT_EQ(s.tri_positions[i], (std::array<std::uint32_t, 3>{0, 1, 2}));
    EXPECT_EQ(s.tri_normals[0][0], kNoIndex);
    EXPECT_EQ(s.tri_texcoords[1], (std::array<std::uint32_t, 3>{0, 1, 2}));
    EXPECT_EQ(s.tri_normals[1][2], kNoIndex);
    EXPECT_EQ(s.tri_normals[2], (std::array<std::uint32_t, 3>{0, 0, 1}));
    EXPECT_EQ(s.tri_texcoords[2][0], kNoIndex);
    EXPECT_EQ(s.tri_normals[3], (std::array<std::uint32_t, 3>{0, 0, 0}));
    EXPECT_EQ(s.tri_texcoords[3], (std::array<std::uint32_t, 3>{0, 1, 2}));
}

TEST(ObjLoader, NegativeIndicesAreRelativeToVerticesSoFar) {
    Scene s = parse("v 0 0 0\nv 1 0 0\nv 1 1 0\nf -3 -2 -1\nv 5 5 5\nf -4 -1 -2\n");
    ASSERT_EQ(s.triangle_count(), 2u);
    EXPECT_EQ(s.tri_positions[0], (std::array<std::uint32_t, 3>{0, 1, 2}));
    EXPECT_EQ(s.tri_positions[1], (std::array<std::uint32_t, 3>{0, 3, 2}));
}

TEST(ObjLoader, PolygonsAreFanTriangulated) {
    Scene s = parse("v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\nf 1 2 3 4 5\n");
    ASSERT_EQ(s.triangle_count(), 3u);
    EXPECT_EQ(s.tri_positions[0], (std::array<std::uint32_t, 3>{0, 1, 2}));
    EXPECT_EQ(s.tri_positions[1], (std::array<std::uint32_t, 3>{0, 2, 3}));
    EXPECT_EQ(s.tri_positions[2], (std::array<std::uint32_t, 3>{0, 3, 4}));
}

TEST(ObjLoader, AcceptsWComponentCommentsSmoothingCrlfBomAndContinuations) {
    Scene s = parse(
        "\xEF\xBB\xBF# comment\r\nv 0 0 0 1\r\nv 1 0 0 1.0 # trailing\r\n"
        "v 1 1 \\\r\n 0\r\ns 1\r\ns off\r\nf 1 \\\n 2 3\r\n");
    ASSERT_EQ(s.positions.size(), 3u);
    EXPECT_EQ(s.positions[2], Vec3f(1, 1, 0));
    ASSERT_EQ(s.triangle_count(), 1u);
}

TEST(ObjLoader, ErrorsNameThePhysicalLineAfterContinuations) {
    std::string e = error_of("v 0 0 \\\n0\nv 1 0 0\nv 0 1 0\nf 1 2 \\\n 3\nf 1 2 x\n");
    EXPECT_NE(e.find("test.obj:7:"), std::string::npos) << e;
}

TEST(ObjLoader, ObjectsAndGroupsGetIds) {
    Scene s = parse(std::string(kQuad) + "o first\nf 1 2 3\ng second\nf 1 3 4\no first\nf 2 3 4\n");
    ASSERT_EQ(s.triangle_count(), 3u);
    EXPECT_EQ(s.objects[s.tri_object[0]], "first");
    EXPECT_EQ(s.objects[s.tri_object[1]], "second");
    EXPECT_EQ(s.tri_object[2], s.tri_object[0]);
}

TEST(ObjLoader, MaterialsFromSeveralLibrariesRelativeToTheObj) {
    fs::path dir = temp_dir("mtl");
    fs::create_directories(dir / "sub");
    write(
        dir / "sub" / "a.mtl",
        "newmtl red\nKd 1 0 0\nKa 0.1 0.1 0.1\nKs 0.5 0.5 0.5\nNs 20\nd 0.5\nillum 2\nmap_Kd -s 1 1 1 tex.png\n");
    write(dir / "b.mtl", "# b\nnewmtl blue\r\nKd 0 0 1\r\nunknown_statement 1 2 3\r\n");
    write(dir / "scene.obj",
          std::string("mtllib sub/a.mtl b.mtl\n") + kQuad +
              "f 1 2 3\nusemtl red\nf 1 2 3\nusemtl blue\nf 1 3 4\nusemtl\nf 2 3 4\n");
    Scene s;
    Warnings w;
    load_obj(dir / "scene.obj", s, w);
    EXPECT_TRUE(w.empty()) << w.front();
    ASSERT_EQ(s.triangle_count(), 4u);
    EXPECT_EQ(s.tri_material[0], 0u);
    EXPECT_EQ(s.materials[0].kd, Vec3f(0.8f));
    const Material& red = s.materials[s.tri_material[1]];
    EXPECT_EQ(red.name, "red");
    EXPECT_EQ(red.kd, Vec3f(1, 0, 0));
    EXPECT_EQ(red.ka, Vec3f(0.1f));
    EXPECT_EQ(red.ks, Vec3f(0.5f));
    EXPECT_EQ(red.ns, 20.0f);
    EXPECT_EQ(red.d, 0.5f);
    EXPECT_EQ(red.illum, 2);
    EXPECT_EQ(fs::path(red.map_kd), dir / "sub" / "tex.png");
    EXPECT_EQ(s.materials[s.tri_material[2]].name, "blue");
    EXPECT_EQ(s.materials[s.tri_material[2]].kd, Vec3f(0, 0, 1));
    EXPECT_EQ(s.tri_material[3], 0u);
    fs::remove_all(dir);
}

TEST(ObjLoader, MissingLibraryAndUnknownMaterialWarnAndUseTheDefault) {
    fs::path dir = temp_dir("missing");
    write(dir / "scene.obj",
          std::string("mtllib nothere.mtl\n") + kQuad + "usemtl ghost\nf 1 2 3\n");
    Scene s;
    Warnings w;
    load_obj(dir / "scene.obj", s, w);
    ASSERT_EQ(w.size(), 2u);
    EXPECT_NE(w[0].find("scene.obj:1:"), std::string::npos) << w[0];
    EXPECT_NE(w[0].find("nothere.mtl"), std::string::npos) << w[0];
    EXPECT_NE(w[1].find("scene.obj:6:"), std::string::npos) << w[1];
    EXPECT_NE(w[1].find("ghost"), std::string::npos) << w[1];
    EXPECT_EQ(s.tri_material[0], 0u);
    fs::remove_all(dir);
}

TEST(ObjLoader, BadInputIsAnErrorWithFileAndLine) {
    struct Case {
        std::string text;
        std::string expect;
    };
    const std::string q = kQuad;  // lines 1-4
    const Case cases[] = {
        {q + "f 1 2 0\n", "test.obj:5: face vertex index 0"},
        {q + "f 1 2 5\n", "test.obj:5: face vertex index 5 out of range (4 vertices"},
        {q + "f 1 2 -5\n", "test.obj:5: face vertex index -5 out of range"},
        {q + "f 1 2 3000000000\n", "test.obj:5: face vertex index 3000000000 out of range"},
        {q + "l 1\n", "test.obj:5: line element needs at least 2 points, has 1"},
        {q + "l 1 0\n", "test.obj:5: line vertex index 0"},
        {q + "l 1 9\n", "test.obj:5: line vertex index 9 out of range (4 vertices"},
        {q + "l 1 2//3\n", "test.obj:5: malformed line point '2//3'"},
        {q + "f 1/2/3/4 2 3\n", "test.obj:5: malformed face corner '1/2/3/4'"},
        {q + "f a b c\n", "test.obj:5: malformed face corner 'a'"},
        {"v 1 2\n", "test.obj:1: missing number in 'v' statement"},
        {"v 1 2 abc\n", "test.obj:1: malformed number 'abc' in 'v' statement"},
        {"v 1 2 3.0.0\n", "test.obj:1: malformed number '3.0.0'"},
        {"vn 1 2\n", "test.obj:1: missing number in 'vn' statement"},
        {"v 1 nan\n", "test.obj:1: missing number in 'v' statement"},
        {"v 1 nanx 3\n", "test.obj:1: malformed number 'nanx'"},
        {"p 1\nv 1 2 3 inf\n", "test.obj:2: non-finite number 'inf'"},  // w stays strict
        {std::string("v 0 0 0\n\0\0\0 binary\n", 19), "test.obj:2: binary data"},
    };
    for (const Case& c : cases) {
        std::string e = error_of(c.text);
        EXPECT_NE(e.find(c.expect), std::string::npos) << "input:\n" << c.text << "\ngot: " << e;
    }
}

TEST(ObjLoader, UnderflowReadsAsZeroOverflowIsNonFinite) {
    Scene s = parse("v 1e-50 -1e-400 2.5e-39\n");
    EXPECT_EQ(s.positions[0].x, 0.0f);
    EXPECT_EQ(s.positions[0].y, 0.0f);
    EXPECT_GT(s.positions[0].z, 0.0f);  // a denormal, kept
    Warnings w;
    Scene big = parse("v 1 1e400 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", &w);
    EXPECT_EQ(big.triangle_count(), 0u);
    ASSERT_EQ(w.size(), 2u);
    EXPECT_NE(w[0].find("test.obj:1: non-finite coordinate in 'v'"), std::string::npos) << w[0];
}

TEST(ObjLoader, NonFiniteCoordinatesDropTheFacesThatUseThem) {
    Warnings w;
    // Vertex 2 is not finite (general path); the other lines take the fast path.
    Scene s = parse(
        "v 0 0 0\nv 1 -1.#IND 0\nv 1 1 0\nv 0 1 0\nv 0 0 inf\nvn 0 0 1\n"
        "vn -nan 0 1\nvt 0 0\nvt inf 1\n"
        "f 1 2 3\nf 1 3 4\nf 1/1/1 3/1/1 4/1/2\nf 1/2 3/1 4/1\nf 1 4 5\n",
        &w);
    ASSERT_EQ(s.triangle_count(), 3u);  // faces on lines 10 and 14 are dropped
    EXPECT_EQ(s.positions.size(), 5u);  // indices stay right
    EXPECT_EQ(s.tri_positions[0], (std::array<std::uint32_t, 3>{0, 2, 3}));
    // A non-finite normal or texture coordinate takes them from the face, not the face.
    EXPECT_EQ(s.tri_normals[1], (std::array<std::uint32_t, 3>{kNoIndex, kNoIndex, kNoIndex}));
    EXPECT_EQ(s.tri_texcoords[1], (std::array<std::uint32_t, 3>{0, 0, 0}));
    EXPECT_EQ(s.tri_texcoords[2], (std::array<std::uint32_t, 3>{kNoIndex, kNoIndex, kNoIndex}));
    std::string all;
    for (const std::string& m : w) all += m + "\n";
    EXPECT_NE(all.find("test.obj:2: non-finite coordinate in 'v'"), std::string::npos) << all;
    EXPECT_NE(all.find("test.obj:7: non-finite coordinate in 'vn'"), std::string::npos) << all;
    EXPECT_NE(all.find("test.obj:9: non-finite coordinate in 'vt'"), std::string::npos) << all;
    EXPECT_NE(all.find("test.obj:10: face uses a vertex with a non-finite"), std::string::npos)
        << all;
    EXPECT_NE(all.find("test.obj:14: face uses a vertex with a non-finite"), std::string::npos)
        << all;
}

TEST(ObjLoader, TextureAndNormalIndicesPastTheDefinedOnesAreWarnings) {
    Warnings w;
    Scene s = parse(std::string(kQuad) +
                        "vt 0 0\nvn 0 0 1\nf 1/9/1 2/1/1 3/1/1\nf 1//9 2//1 3//1\n"
                        "f 1/0 2/1 3/1\nf 1/1/1 2/1/1 3/1/1\n",
                    &w);
    ASSERT_EQ(s.triangle_count(), 4u);
    EXPECT_EQ(s.tri_texcoords[0], (std::array<std::uint32_t, 3>{kNoIndex, kNoIndex, kNoIndex}));
    EXPECT_EQ(s.tri_normals[0], (std::array<std::uint32_t, 3>{0, 0, 0}));
    EXPECT_EQ(s.tri_normals[1], (std::array<std::uint32_t, 3>{kNoIndex, kNoIndex, kNoIndex}));
    EXPECT_EQ(s.tri_texcoords[2], (std::array<std::uint32_t, 3>{kNoIndex, kNoIndex, kNoIndex}));
    EXPECT_EQ(s.tri_texcoords[3], (std::array<std::uint32_t, 3>{0, 0, 0}));
    ASSERT_EQ(w.size(), 3u);
    EXPECT_NE(w[0].find("test.obj:7: face texture index 9 out of range (1 defined so far)"),
              std::string::npos)
        << w[0];
    EXPECT_NE(w[1].find("test.obj:8: face normal index 9 out of range"), std::string::npos) << w[1];
    EXPECT_NE(w[2].find("test.obj:9: face texture index 0"), std::string::npos) << w[2];
}

TEST(ObjLoader, LineElementsAreKeptWithObjectAndMaterial) {
    Warnings w;
    Scene s = parse(std::string(kQuad) +
                        "v nan 0 0\ng wire\nl 1 2 -3\nl 1/1 2/2\nl 1 5\n"
                        "f 1 2\nf 1 2 3\n",
                    &w);
    ASSERT_EQ(s.polylines.size(), 2u);
    EXPECT_EQ(s.polylines[0].first, 0u);
    EXPECT_EQ(s.polylines[0].count, 3u);
    EXPECT_EQ(s.polyline_points[2], 2u);  // -3 of 5 vertices
    EXPECT_EQ(s.polylines[1].first, 3u);
    EXPECT_EQ(s.objects[s.polylines[1].object], "wire");
    EXPECT_EQ(s.polyline_points.size(), 5u);  // the line through the nan vertex is dropped
    EXPECT_EQ(s.triangle_count(), 1u);        // and so is the two-corner face
    std::string all;
    for (const std::string& m : w) all += m + "\n";
    EXPECT_NE(all.find("test.obj:9: line uses a vertex with a non-finite"), std::string::npos)
        << all;
    EXPECT_NE(all.find("test.obj:10: face needs at least 3 corners, has 2; dropped"),
              std::string::npos)
        << all;
    s.clear();
    EXPECT_TRUE(s.polylines.empty());
    EXPECT_TRUE(s.polyline_points.empty());
}

TEST(ObjLoader, PointElementsAreIgnoredWithOneWarning) {
    Warnings w;
    Scene s = parse(std::string(kQuad) + "p 1\np 2 3\nf 1 2 3\n", &w);
    ASSERT_EQ(w.size(), 1u);
    EXPECT_NE(w[0].find("test.obj:5: point elements ('p')"), std::string::npos) << w[0];
    EXPECT_EQ(s.triangle_count(), 1u);
}

TEST(ObjLoader, MtllibNamesMayEscapeSpaces) {
    const fs::path dir = temp_dir("escaped");
    write(dir / "my file.mtl", "newmtl red\nKd 1 0 0\n");
    write(dir / "b.mtl", "newmtl blue\nKd 0 0 1\n");
    write(dir / "scene.obj", std::string("mtllib my\\ file.mtl b.mtl\n") + kQuad +
                                 "usemtl red\nf 1 2 3\nusemtl blue\nf 1 3 4\n");
    Scene s;
    Warnings w;
    load_obj(dir / "scene.obj", s, w);
    EXPECT_TRUE(w.empty()) << w.front();
    ASSERT_EQ(s.triangle_count(), 2u);
    EXPECT_EQ(s.materials[s.tri_material[0]].kd, Vec3f(1, 0, 0));
    EXPECT_EQ(s.materials[s.tri_material[1]].kd, Vec3f(0, 0, 1));
    fs::remove_all(dir);
}

TEST(ObjLoader, CommentsAreNotContinued) {
    Scene s = parse("# C:\\models\\\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    EXPECT_EQ(s.positions.size(), 3u);
    EXPECT_EQ(s.triangle_count(), 1u);
}

TEST(ObjLoader, MissingFileIsAnError) {
    Scene s;
    Warnings w;
    EXPECT_THROW(load_obj("/nonexistent/scene.obj", s, w), Error);
}

TEST(ObjLoader, UnknownStatementsWarnOnce) {
    Warnings w;
    Scene s = parse(std::string(kQuad) + "foo 1\nfoo 2\nl 1 2\nf 1 2 3\n", &w);
    ASSERT_EQ(w.size(), 1u);
    EXPECT_NE(w[0].find("unknown statement 'foo'"), std::string::npos);
    EXPECT_EQ(s.triangle_count(), 1u);
}

TEST(ObjLoader, MtlErrorsNameTheMtlFileAndLine) {
    std::vector<Material> materials;
    Warnings w;
    try {
        parse_mtl("newmtl a\nKd 1 x 0\n", "lib.mtl", materials, w);
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("lib.mtl:2: malformed number 'x'"), std::string::npos)
            << e.what();
    }
    EXPECT_THROW(parse_mtl("Kd 1 1 1\n", "lib.mtl", materials, w), Error);  // before newmtl
}

TEST(ObjLoader, MtlSingleValueKdIsGrey) {
    std::vector<Material> materials;
    Warnings w;
    parse_mtl("newmtl g\nKd 0.25\n", "lib.mtl", materials, w);
    ASSERT_EQ(materials.size(), 1u);
    EXPECT_EQ(materials[0].kd, Vec3f(0.25f));
}

TEST(CameraBlock, ReadsTheSeedsBlock) {
    Scene s = parse(
        "# Camera start\n"
        "v 16.270052 26.948549 25.997269\n"
        "v 15.863070 26.491430 25.206442\n"
        "vn -0.419904 0.862497 -0.282451\n"
        "c 1 2 1\n"
        "# Camera end\n" +
        std::string(kQuad) + "f 3 4 5\n");
    ASSERT_TRUE(s.camera);
    EXPECT_EQ(s.camera->eye, Vec3f(16.270052f, 26.948549f, 25.997269f));
    EXPECT_EQ(s.camera->gaze, Vec3f(15.863070f, 26.491430f, 25.206442f));
    EXPECT_EQ(s.camera->up, Vec3f(-0.419904f, 0.862497f, -0.282451f));
    // Camera vertices are ordinary vertices but do not count towards the scene bounds.
    EXPECT_EQ(s.bounds().hi, Vec3f(1, 1, 0));
}

TEST(CameraBlock, RelativeIndices) {
    Scene s = parse(std::string(kQuad) + "v 0 0 5\nv 0 0 4\nvn 0 1 0\nc -2 -1 -1\n");
    ASSERT_TRUE(s.camera);
    EXPECT_EQ(s.camera->eye, Vec3f(0, 0, 5));
    EXPECT_EQ(s.camera->gaze, Vec3f(0, 0, 4));
}

TEST(CameraBlock, InvalidBlocksAreErrors) {
    EXPECT_NE(error_of("v 0 0 5\nv 0 0 4\nvn 0 1 0\nc 1 2 2\n")
                  .find("test.obj:4: camera up index 2 out of range"),
              std::string::npos);
    EXPECT_NE(
        error_of("v 0 0 5\nv 0 0 4\nvn 0 1 0\nc 0 2 1\n").find("test.obj:4: camera eye index 0"),
        std::string::npos);
    EXPECT_NE(error_of("v 0 0 5\nv 0 0 5\nvn 0 1 0\nc 1 2 1\n")
                  .find("test.obj:4: invalid camera: eye and gaze"),
              std::string::npos);
    EXPECT_NE(error_of("v 0 0 5\nv 0 0 4\nvn 0 0 1\nc 1 2 1\n")
                  .find("test.obj:4: invalid camera: up vector"),
              std::string::npos);
    EXPECT_NE(error_of("v 0 0 5\nv 0 0 4\nvn 0 1 0\nc 1 2\n")
                  .find("test.obj:4: camera statement needs three"),
              std::string::npos);
}

TEST(ObjLoader, FastNumberPathEqualsFromCharsBitForBit) {
    // The loader parses short decimals without from_chars (see short_decimal); every number
    // must still read back exactly as from_chars<float> reads it.
    std::mt19937_64 rng(7);
    int checked = 0;
    for (int i = 0; i < 100000; ++i) {
        std::string texts[2];
        float f;
        std::uint32_t bits = static_cast<std::uint32_t>(rng());
        std::memcpy(&f, &bits, 4);
        char buf[64];
        if (std::isfinite(f) && std::abs(f) < 1e6f && std::abs(f) > 1e-6f) {
            auto r = std::to_chars(buf, buf + 64, f, std::chars_format::fixed);
            texts[0].assign(buf, r.ptr);
        }
        int digits = 1 + static_cast<int>(rng() % 16),
            decimals = static_cast<int>(rng() % (digits + 1));
        for (int k = 0; k < digits; ++k) texts[1] += static_cast<char>('0' + rng() % 10);
        if (decimals) texts[1].insert(texts[1].size() - decimals, ".");
        if (rng() & 1) texts[1] = "-" + texts[1];
        for (const std::string& t : texts) {
            if (t.empty()) continue;
            float expect;
            if (std::from_chars(t.data(), t.data() + t.size(), expect).ec != std::errc()) continue;
            Scene s = parse("v " + t + " 0 0\n");
            ASSERT_EQ(0, std::memcmp(&expect, &s.positions[0].x, 4)) << t;
            ++checked;
        }
    }
    EXPECT_GT(checked, 100000);
}

TEST(ObjLoader, PlusSignedFaceIndices) {
    Scene s = parse(std::string(kQuad) + "f +1 +2 +3\n");
    ASSERT_EQ(s.triangle_count(), 1u);
    EXPECT_EQ(s.tri_positions[0], (std::array<std::uint32_t, 3>{0, 1, 2}));
}

TEST(ObjLoader, CrOnlyLineEndingsAreRead) {
    // Old Mac files end lines with a lone CR; tinyobjloader reads them, and so do we. Mixed
    // endings too: each of LF, CRLF and CR ends one line (line 5 is the error's).
    Scene s = parse("v 0 0 0\rv 1 0 0\r\nv 0 1 0\nf 1 2 3\r");
    EXPECT_EQ(s.positions.size(), 3u);
    EXPECT_EQ(s.triangle_count(), 1u);
    EXPECT_NE(error_of("v 0 0 0\rv 1 0 0\r\nv 0 1 0\n\rf 1 2 4\r")
                  .find("test.obj:5: face vertex index 4"),
              std::string::npos);
}

TEST(ObjLoader, HashInsideANameIsPartOfTheName) {
    // '#' starts a comment only at the start of a word: "Mat#1" and "Mat#2" are two materials.
    fs::path dir = temp_dir("hash");
    write(dir / "m.mtl", "newmtl Mat#1\nKd 1 0 0\nnewmtl Mat#2 # green\nKd 0 1 0\n");
    write(dir / "scene.obj", std::string("mtllib m.mtl\n") + kQuad +
                                 "usemtl Mat#2\nf 1 2 3\nusemtl Mat#1 # the red one\nf 1 3 4\n");
    Scene s;
    Warnings w;
    load_obj(dir / "scene.obj", s, w);
    EXPECT_TRUE(w.empty()) << w.front();
    ASSERT_EQ(s.triangle_count(), 2u);
    EXPECT_EQ(s.materials[s.tri_material[0]].name, "Mat#2");
    EXPECT_EQ(s.materials[s.tri_material[0]].kd, Vec3f(0, 1, 0));
    EXPECT_EQ(s.materials[s.tri_material[1]].name, "Mat#1");
    EXPECT_EQ(s.materials[s.tri_material[1]].kd, Vec3f(1, 0, 0));
    fs::remove_all(dir);
}

TEST(ObjLoader, MaterialDefinedAgainKeepsItsFirstDefinition) {
    // A later library (or a later newmtl in the same one) must not recolour faces already
    // given the material: the first definition wins, as in tinyobjloader, with a warning.
    fs::path dir = temp_dir("redefined");
    write(dir / "a.mtl", "newmtl A\nKd 1 0 0\nnewmtl A\nKd 0 0 0.5\n");
    write(dir / "b.mtl", "newmtl A\nKd 0 0 1\nnewmtl B\nKd 0 1 0\n");
    write(dir / "scene.obj",
          std::string("mtllib a.mtl\n") + kQuad +
              "usemtl A\nf 1 2 3\nmtllib b.mtl\nusemtl A\nf 1 2 3\nusemtl B\nf 1 2 3\n");
    Scene s;
    Warnings w;
    load_obj(dir / "scene.obj", s, w);
    ASSERT_EQ(s.triangle_count(), 3u);
    EXPECT_EQ(s.tri_material[0], s.tri_material[1]);
    EXPECT_EQ(s.materials[s.tri_material[0]].kd, Vec3f(1, 0, 0));
    EXPECT_EQ(s.materials[s.tri_material[2]].kd, Vec3f(0, 1, 0));
    ASSERT_EQ(w.size(), 2u);
    EXPECT_NE(w[0].find("a.mtl:3: material 'A' defined again"), std::string::npos) << w[0];
    EXPECT_NE(w[1].find("b.mtl:1: material 'A' defined again"), std::string::npos) << w[1];
    fs::remove_all(dir);
}

TEST(ObjLoader, LongAndShortNumbersReadTheSameInEveryPosition) {
    // The fast paths (plain v and f lines) read numbers in one pass without tokens: indices and
    // numbers of every length, at the end of the text and not, must read as the general path
    // (from_chars) reads them, including past the fast paths' 15- and 18-digit limits.
    for (const char* tail : {"", "\n", " \n", "\r\n"}) {
        for (int digits = 1; digits <= 20; ++digits) {
            std::string index =
                std::string(static_cast<std::size_t>(digits - 1), '0') + "1";  // vertex 1
            std::string text = std::string(kQuad) + "f " + index + " 2 " + index + tail;
            // Past 18 digits the general path reads it (from_chars), still as 1.
            Scene s = parse(text);
            ASSERT_EQ(s.triangle_count(), 1u) << text;
            EXPECT_EQ(s.tri_positions[0], (std::array<std::uint32_t, 3>{0, 1, 0})) << text;
            std::string number =
                "0." + std::string(static_cast<std::size_t>(digits - 1), '3') + "7";
            float expect;
            std::from_chars(number.data(), number.data() + number.size(), expect);
            Scene v = parse("v " + number + " -" + number + " " + number + tail);
            ASSERT_EQ(v.positions.size(), 1u);
            EXPECT_EQ(v.positions[0], Vec3f(expect, -expect, expect)) << number;
        }
    }
    EXPECT_NE(error_of(std::string(kQuad) + "f 1 2 12345678x\n")
                  .find("malformed face corner '12345678x'"),
              std::string::npos);
    EXPECT_NE(error_of("v 1 2 12345678.9x\n").find("malformed number '12345678.9x'"),
              std::string::npos);
}
