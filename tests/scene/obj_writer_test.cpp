#include "toonray/scene/obj_writer.h"

#include <gtest/gtest.h>
#include <tiny_obj_loader.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <unistd.h>

#include "toonray/core/error.h"
#include "toonray/io/file.h"
#include "toonray/scene/obj_loader.h"
#include "support/test_support.h"

namespace toonray {
namespace {

using toonray::test_support::TempDir;

namespace fs = std::filesystem;

bool same_bits(float a, float b) {
    return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b);
}
bool same_bits(const Vec3f& a, const Vec3f& b) {
    return same_bits(a.x, b.x) && same_bits(a.y, b.y) && same_bits(a.z, b.z);
}

/// A scene exercising everything the writer must keep: awkward floats, flat and smooth
/// triangles, texture coordinates, several materials and objects (one used out of order, one
/// unused), faces on the default material and object, and a camera.
Scene tricky_scene() {
    Scene s;
    const float values[] = {0.1f,
                            -0.0f,
                            0.0f,
                            1e-7f,
                            -3.4028235e38f,
                            1.17549435e-38f,
                            1.4e-45f /* denormal */,
                            123456.789f,
                            1.0f / 3.0f,
                            -2.5f,
                            16777217.0f,
                            0.3f};
    const int nv = static_cast<int>(std::size(values));
    for (int i = 0; i < nv; ++i)
        s.positions.push_back({values[i], values[(i + 3) % nv], values[(i + 7) % nv]});
    s.normals = {
        {0.0f, 0.0f, 1.0f}, {0.57735026f, 0.57735026f, -0.57735026f}, {-1e-9f, 1.0f, 0.0f}};
    s.texcoords = {{0.25f, 0.75f}, {1.0f / 7.0f, -0.5f}, {2.0f, 3.0f}};
    Material wood("wood");
    wood.kd = {0.56f, 0.28f, 0.14f};
    wood.ka = {0.01f, 0.02f, 0.03f};
    wood.ks = {0.5f, 0.5f, 0.5f};
    wood.ns = 12.5f;
    wood.d = 0.75f;
    wood.illum = 1;
    Material brass("polished brass");  // a name with a space
    brass.kd = {0.88f, 0.68f, 0.26f};
    s.materials.push_back(wood);
    s.materials.push_back(brass);
    s.objects.push_back("key w1");
    s.objects.push_back("lid");
    s.objects.push_back("unused");               // no triangles: still must keep its index
    s.add_triangle({0, 1, 2}, 1, 2);             // lid first: out of order
    s.add_triangle({3, 4, 5}, 2, 1, {0, 1, 2});  // smooth
    s.add_triangle({6, 7, 8}, 0, 1, {kNoIndex, 2, kNoIndex});  // default material, mixed corners
    s.add_triangle({9, 10, 11}, 1, 0, {0, 0, 0}, {0, 1, 2});   // default object, v/vt/vn
    s.add_triangle({0, 5, 9}, 2, 2, {kNoIndex, kNoIndex, kNoIndex}, {2, kNoIndex, 0});
    s.camera = CameraSpec{{1.5f, 2.25f, -3.0f}, {0.1f, 0.2f, 0.3f}, {0.0f, 1.0f, 0.0f}};
    return s;
}

void expect_round_trip(const Scene& in, const Scene& out) {
    // Positions: the scene's, then the camera block's eye and gaze.
    ASSERT_EQ(out.positions.size(), in.positions.size() + (in.camera ? 2u : 0u));
    for (std::size_t i = 0; i < in.positions.size(); ++i)
        EXPECT_TRUE(same_bits(in.positions[i], out.positions[i])) << "position " << i;
    ASSERT_EQ(out.normals.size(), in.normals.size() + (in.camera ? 1u : 0u));
    for (std::size_t i = 0; i < in.normals.size(); ++i)
        EXPECT_TRUE(same_bits(in.normals[i], out.normals[i])) << "normal " << i;
    ASSERT_EQ(out.texcoords.size(), in.texcoords.size());
    for (std::size_t i = 0; i < in.texcoords.size(); ++i) {
        EXPECT_TRUE(same_bits(in.texcoords[i].x, out.texcoords[i].x));
        EXPECT_TRUE(same_bits(in.texcoords[i].y, out.texcoords[i].y));
    }
    ASSERT_EQ(out.triangle_count(), in.triangle_count());
    EXPECT_EQ(out.tri_positions, in.tri_positions);
    EXPECT_EQ(out.tri_normals, in.tri_normals);
    EXPECT_EQ(out.tri_texcoords, in.tri_texcoords);
    EXPECT_EQ(out.tri_material, in.tri_material);
    EXPECT_EQ(out.tri_object, in.tri_object);
    EXPECT_EQ(out.objects, in.objects);
    ASSERT_EQ(out.materials.size(), in.materials.size());
    for (std::size_t i = 1; i < in.materials.size(); ++i) {
        const Material &a = in.materials[i], &b = out.materials[i];
        EXPECT_EQ(a.name, b.name);
        EXPECT_TRUE(same_bits(a.kd, b.kd)) << a.name;
        EXPECT_TRUE(same_bits(a.ka, b.ka)) << a.name;
        EXPECT_TRUE(same_bits(a.ks, b.ks)) << a.name;
        EXPECT_TRUE(same_bits(a.ns, b.ns)) << a.name;
        EXPECT_TRUE(same_bits(a.d, b.d)) << a.name;
        EXPECT_EQ(a.illum, b.illum) << a.name;
    }
    ASSERT_EQ(out.camera.has_value(), in.camera.has_value());
    if (in.camera) {
        EXPECT_TRUE(same_bits(out.camera->eye, in.camera->eye));
        EXPECT_TRUE(same_bits(out.camera->gaze, in.camera->gaze));
        EXPECT_TRUE(same_bits(out.camera->up, in.camera->up));
    }
}

TEST(ObjWriter, RoundTripsBitExactly) {
    TempDir dir;
    const Scene in = tricky_scene();
    write_obj(dir.path / "scene.obj", in);
    ASSERT_TRUE(fs::exists(dir.path / "scene.mtl"));
    Scene out;
    Warnings warnings;
    load_obj(dir.path / "scene.obj", out, warnings);
    EXPECT_TRUE(warnings.empty()) << warnings.front();
    expect_round_trip(in, out);
}

TEST(ObjWriter, WritesTheCameraBlockLast) {
    std::string text;
    format_obj(tricky_scene(), "scene.mtl", text);
    const auto block = text.find(
        "# Camera start\nv 1.5 2.25 -3\nv 0.1 0.2 0.3\nvn 0 1 0\nc -2 -1 -1\n# Camera end\n");
    ASSERT_NE(block, std::string::npos);
    EXPECT_EQ(text.find("\nf ", block), std::string::npos) << "faces after the camera block";
    EXPECT_NE(text.find("\nmtllib scene.mtl\n"), std::string::npos);
}

TEST(ObjWriter, RandomFloatsRoundTrip) {
    // Shortest round-trip formatting is exact for every finite float, whatever its exponent.
    std::mt19937 rng(7);
    Scene in;
    while (in.positions.size() < 30000) {
        Vec3f p;
        for (int k = 0; k < 3; ++k) {
            float f;
            do {
                f = std::bit_cast<float>(static_cast<std::uint32_t>(rng()));
            } while (!std::isfinite(f));
            (k == 0 ? p.x : k == 1 ? p.y : p.z) = f;
        }
        in.positions.push_back(p);
    }
    for (std::uint32_t i = 0; i + 2 < in.positions.size(); i += 3)
        in.add_triangle({i, i + 1, i + 2}, 0, 0);
    std::string text;
    format_obj(in, "", text);
    Scene out;
    Warnings warnings;
    parse_obj(text, "random.obj", out, warnings);
    expect_round_trip(in, out);
}

TEST(ObjWriter, CachedWriterMatchesFormatObj) {
    // The writer reuses text of unchanged values and faces; its output must be exactly
    // format_obj's whatever changes between calls.
    Scene s = tricky_scene();
    ObjWriter writer;
    std::string expected;
    auto check = [&](const char* what) {
        format_obj(s, "scene.mtl", expected);
        EXPECT_EQ(writer.format(s, "scene.mtl"), expected) << what;
    };
    check("first call");
    check("same scene");
    s.positions[4].y = 0.5f;
    s.normals[1] = {1.0f, 0.0f, 0.0f};
    check("moved vertex and normal");
    s.positions[2].x = -0.0f;  // 0 -> -0: equal as floats, different bits and text
    s.positions[1].x = 0.0f;
    check("signed zeros");
    s.tri_material[0] = 2;
    check("material change");
    s.objects[3] = "renamed";
    check("object rename");
    s.positions.push_back({1.0f, 2.0f, 3.0f});
    s.add_triangle({12, 0, 1}, 1, 3);
    check("grown scene");
    s.normals.clear();
    for (auto& n : s.tri_normals) n = {kNoIndex, kNoIndex, kNoIndex};
    check("normals dropped");
    s.camera.reset();
    check("camera removed");
}

TEST(ObjWriter, WritesOnlyCompleteFilesAndNoTemporaries) {
    TempDir dir;
    Scene s = tricky_scene();
    ObjWriter writer;
    for (int frame = 0; frame < 3; ++frame) {
        s.positions[0].x = static_cast<float>(frame);
        writer.write(dir.path / "frame.obj", s);
    }
    int files = 0;
    for (const auto& entry : fs::directory_iterator(dir.path)) {
        ++files;
        EXPECT_TRUE(entry.path().filename() == "frame.obj" ||
                    entry.path().filename() == "frame.mtl")
            << entry.path();
    }
    EXPECT_EQ(files, 2);
    Scene out;
    Warnings warnings;
    load_obj(dir.path / "frame.obj", out, warnings);
    EXPECT_EQ(out.positions[0].x, 2.0f);
}

TEST(ObjWriter, OptionsLeaveOutWhatIsNotWanted) {
    TempDir dir;
    Scene s = tricky_scene();
    ObjWriteOptions options;
    options.write_normals = false;
    options.write_texcoords = false;
    options.write_camera = false;
    options.write_mtl = false;
    ObjWriter().write(dir.path / "bare.obj", s, options);
    EXPECT_FALSE(fs::exists(dir.path / "bare.mtl"));
    const std::string text = read_file(dir.path / "bare.obj");
    EXPECT_EQ(text.find("vn "), std::string::npos);
    EXPECT_EQ(text.find("vt "), std::string::npos);
    EXPECT_EQ(text.find("Camera"), std::string::npos);
    EXPECT_EQ(text.find('/'), std::string::npos);
    // The OBJ still names its material library (written once for a frame sequence).
    EXPECT_NE(text.find("mtllib bare.mtl"), std::string::npos);
}

TEST(ObjWriter, RejectsWhatCannotRoundTrip) {
    std::string text;
    Scene s = tricky_scene();
    s.positions[3].y = std::numeric_limits<float>::quiet_NaN();
    EXPECT_THROW(format_obj(s, "", text), Error);
    s = tricky_scene();
    s.objects[1] = "bad#name";
    EXPECT_THROW(format_obj(s, "", text), Error);
    s = tricky_scene();
    s.materials[1].name = " padded";
    EXPECT_THROW(format_obj(s, "", text), Error);
    s = tricky_scene();
    s.tri_positions[1][2] = 999;
    EXPECT_THROW(format_obj(s, "", text), Error);
    s = tricky_scene();
    s.tri_normals[1][0] = 42;
    EXPECT_THROW(format_obj(s, "", text), Error);
}

TEST(ObjWriter, TextureMapPathsFollowTheMtl) {
    TempDir dir;
    fs::create_directories(dir.path / "in" / "tex");
    fs::create_directories(dir.path / "out");
    Scene s = tricky_scene();
    s.materials[1].map_kd = (dir.path / "in" / "tex" / "wood.png").string();
    write_obj(dir.path / "out" / "scene.obj", s);
    Scene back;
    Warnings warnings;
    load_obj(dir.path / "out" / "scene.obj", back, warnings);
    EXPECT_EQ(fs::weakly_canonical(back.materials[1].map_kd),
              fs::weakly_canonical(s.materials[1].map_kd));
}

TEST(ObjWriter, AnotherReaderAgrees) {
    // tinyobjloader, an independent reader, sees the same geometry and materials.
    TempDir dir;
    const Scene in = tricky_scene();
    ObjWriteOptions options;
    options.write_camera = false;  // `c` is toonray's own statement
    write_obj(dir.path / "scene.obj", in, options);
    tinyobj::ObjReader reader;
    tinyobj::ObjReaderConfig config;
    config.triangulate = false;
    ASSERT_TRUE(reader.ParseFromFile((dir.path / "scene.obj").string(), config)) << reader.Error();
    const auto& attrib = reader.GetAttrib();
    ASSERT_EQ(attrib.vertices.size(), 3 * in.positions.size());
    for (std::size_t i = 0; i < in.positions.size(); ++i) {
        EXPECT_EQ(attrib.vertices[3 * i + 0], in.positions[i].x);
        EXPECT_EQ(attrib.vertices[3 * i + 2], in.positions[i].z);
    }
    std::size_t faces = 0;
    for (const auto& shape : reader.GetShapes()) faces += shape.mesh.num_face_vertices.size();
    EXPECT_EQ(faces, in.triangle_count());
    ASSERT_EQ(reader.GetMaterials().size(), 2u);
    EXPECT_EQ(reader.GetMaterials()[0].name, "wood");
    EXPECT_EQ(reader.GetMaterials()[0].diffuse[0], 0.56f);
}

}  // namespace
}  // namespace toonray
