// Cross-check of our OBJ/MTL loader against tinyobjloader (Debian's 2.0.0rc10, target
// tinyobjloader::tinyobjloader, whose real_t is float: it parses numbers in double and rounds
// them to float). Both loaders read the same files; every triangle is compared by value, corner
// by corner: positions bit-equal as floats, normals and texcoords bit-equal where present (and
// absent in both where not), the material by name and Kd, the object by name.
// Comparing values rather than indices means an off-by-one in index resolution changes what is
// compared, so it fails (ComparisonCatchesAnOffByOne proves this on the teapot).
//
// Where tinyobjloader rc10 behaves differently by design, the test works around it and says so:
// - Triangulation. rc10 splits a quad along its shorter diagonal (0-2 or 1-3) and clips ears of
//   larger polygons with an orientation test that depends on where the polygon lies relative to
//   the origin; we fan from the first corner. Quads and polygons in the main files are chosen
//   so both agree (0-2 diagonal shorter; convex polygons whose fan rc10 also picks). Polygons
//   where they differ are compared face by face: same corners, same area (PolygonsWhere...).
// - Line continuation (`\` at the end of a line) is not read by rc10, so tinyobjloader is given
//   the text with each continuation already joined by a space, which is what it means.
// - rc10 has no default material: a face without one (or with an unknown one) has material id
//   -1, which is compared against our default material (index 0).

#include <gtest/gtest.h>
#include <tiny_obj_loader.h>

#include <fmt/format.h>
#include <unistd.h>
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/scene/obj_loader.h"

using namespace toonray;
namespace fs = std::filesystem;

namespace {

const fs::path kData = TOONRAY_TEST_DATA_DIR;

std::string read_text(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error("cannot read " + path.string());
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

/// `\` + newline (LF or CRLF) becomes one space, as our loader joins continued lines.
std::string join_continuations(std::string_view text) {
    std::string out;
    out.reserve(text.size());
    for (std::size_t i = 0; i < text.size(); ++i) {
        if (text[i] == '\\') {
            if (i + 1 < text.size() && text[i + 1] == '\n') {
                out.push_back(' ');
                ++i;
                continue;
            }
            if (i + 2 < text.size() && text[i + 1] == '\r' && text[i + 2] == '\n') {
                out.push_back(' ');
                i += 2;
                continue;
            }
        }
        out.push_back(text[i]);
    }
    return out;
}

struct TinyObj {
    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    std::string warn, err;
};

/// Loads OBJ text with tinyobjloader, triangulating, with MTL files looked up in `dir`.
/// `join` applies line continuations first (rc10 does not read them).
TinyObj load_tinyobj(std::string_view text, const fs::path& dir, bool join = true) {
    TinyObj t;
    std::istringstream in{join ? join_continuations(text) : std::string(text)};
    std::string base = dir.string();
    if (!base.empty() && base.back() != '/') base += '/';
    tinyobj::MaterialFileReader mtl(base);
    bool ok = tinyobj::LoadObj(&t.attrib, &t.shapes, &t.materials, &t.warn, &t.err, &in, &mtl,
                               /*triangulate=*/true, /*default_vcols_fallback=*/false);
    if (!ok) throw std::runtime_error("tinyobjloader failed: " + t.err);
    return t;
}

Scene load_ours(std::string_view text, const fs::path& path) {
    Scene scene;
    Warnings warnings;
    parse_obj(text, path, scene, warnings);
    return scene;
}

/// One triangle as values, independent of how a loader indexes its arrays.
struct FlatTri {
    std::array<Vec3f, 3> p;
    std::array<std::optional<Vec3f>, 3> n;
    std::array<std::optional<Vec2f>, 3> t;
    std::string material;  ///< "(default)" for none or unknown
    Vec3f kd;
    std::string object;  ///< "(default)" before any o/g
};

std::vector<FlatTri> flatten(const Scene& s) {
    std::vector<FlatTri> out(s.triangle_count());
    for (std::size_t i = 0; i < out.size(); ++i) {
        FlatTri& f = out[i];
        for (int k = 0; k < 3; ++k) {
            f.p[k] = s.positions.at(s.tri_positions[i][k]);
            if (std::uint32_t n = s.tri_normals[i][k]; n != kNoIndex) f.n[k] = s.normals.at(n);
            if (std::uint32_t t = s.tri_texcoords[i][k]; t != kNoIndex) f.t[k] = s.texcoords.at(t);
        }
        const Material& m = s.materials.at(s.tri_material[i]);
        f.material = m.name;
        f.kd = m.kd;
        f.object = s.objects.at(s.tri_object[i]);
    }
    return out;
}

Vec3f vec3_at(const std::vector<tinyobj::real_t>& v, int index) {
    std::size_t i = static_cast<std::size_t>(index) * 3;
    return {static_cast<float>(v.at(i)), static_cast<float>(v.at(i + 1)),
            static_cast<float>(v.at(i + 2))};
}

std::vector<FlatTri> flatten(const TinyObj& t) {
    std::vector<FlatTri> out;
    const Material default_material{"(default)"};
    for (const tinyobj::shape_t& shape : t.shapes) {
        const auto& mesh = shape.mesh;
        std::size_t corner = 0;
        for (std::size_t face = 0; face < mesh.num_face_vertices.size(); ++face) {
            if (mesh.num_face_vertices[face] != 3)
                throw std::runtime_error("tinyobjloader left a face untriangulated");
            FlatTri f;
            for (int k = 0; k < 3; ++k, ++corner) {
                const tinyobj::index_t& idx = mesh.indices.at(corner);
                f.p[k] = vec3_at(t.attrib.vertices, idx.vertex_index);
                if (idx.normal_index >= 0) f.n[k] = vec3_at(t.attrib.normals, idx.normal_index);
                if (idx.texcoord_index >= 0) {
                    std::size_t i = static_cast<std::size_t>(idx.texcoord_index) * 2;
                    f.t[k] = Vec2f{static_cast<float>(t.attrib.texcoords.at(i)),
                                   static_cast<float>(t.attrib.texcoords.at(i + 1))};
                }
            }
            int m = mesh.material_ids.at(face);
            if (m < 0) {
                f.material = default_material.name;
                f.kd = default_material.kd;
            } else {
                const tinyobj::material_t& mat = t.materials.at(static_cast<std::size_t>(m));
                f.material = mat.name;
                f.kd = {static_cast<float>(mat.diffuse[0]), static_cast<float>(mat.diffuse[1]),
                        static_cast<float>(mat.diffuse[2])};
            }
            f.object = shape.name.empty() ? "(default)" : shape.name;
            out.push_back(std::move(f));
        }
    }
    return out;
}

bool bit_equal(float a, float b) {
    return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b);
}
bool bit_equal(const Vec3f& a, const Vec3f& b) {
    return bit_equal(a.x, b.x) && bit_equal(a.y, b.y) && bit_equal(a.z, b.z);
}
bool bit_equal(const Vec2f& a, const Vec2f& b) {
    return bit_equal(a.x, b.x) && bit_equal(a.y, b.y);
}

std::string str(const Vec3f& v) { return fmt::format("({:.9g} {:.9g} {:.9g})", v.x, v.y, v.z); }
std::string str(const Vec2f& v) { return fmt::format("({:.9g} {:.9g})", v.x, v.y); }
template <typename T>
std::string str(const std::optional<T>& v) {
    return v ? str(*v) : std::string("none");
}

template <typename T>
bool same(const std::optional<T>& a, const std::optional<T>& b) {
    return a.has_value() == b.has_value() && (!a || bit_equal(*a, *b));
}

/// Describes how the two triangle lists differ (empty when they agree), at most `max` lines.
std::vector<std::string> differences(const std::vector<FlatTri>& ours,
                                     const std::vector<FlatTri>& theirs, std::size_t max = 8) {
    std::vector<std::string> out;
    if (ours.size() != theirs.size())
        out.push_back(
            fmt::format("triangle count: ours {}, tinyobjloader {}", ours.size(), theirs.size()));
    std::size_t n = std::min(ours.size(), theirs.size());
    for (std::size_t i = 0; i < n && out.size() < max; ++i) {
        const FlatTri& a = ours[i];
        const FlatTri& b = theirs[i];
        for (int k = 0; k < 3; ++k) {
            if (!bit_equal(a.p[k], b.p[k]))
                out.push_back(
                    fmt::format("triangle {} corner {}: position ours {} tinyobjloader {}", i, k,
                                str(a.p[k]), str(b.p[k])));
            if (!same(a.n[k], b.n[k]))
                out.push_back(fmt::format("triangle {} corner {}: normal ours {} tinyobjloader {}",
                                          i, k, str(a.n[k]), str(b.n[k])));
            if (!same(a.t[k], b.t[k]))
                out.push_back(
                    fmt::format("triangle {} corner {}: texcoord ours {} tinyobjloader {}", i, k,
                                str(a.t[k]), str(b.t[k])));
        }
        if (a.material != b.material || !bit_equal(a.kd, b.kd))
            out.push_back(
                fmt::format("triangle {}: material ours '{}' Kd {}, tinyobjloader '{}' Kd {}", i,
                            a.material, str(a.kd), b.material, str(b.kd)));
        if (a.object != b.object)
            out.push_back(fmt::format("triangle {}: object ours '{}', tinyobjloader '{}'", i,
                                      a.object, b.object));
    }
    if (out.size() > max) out.resize(max);
    return out;
}

std::string joined(const std::vector<std::string>& lines) {
    std::string s;
    for (const auto& l : lines) s += l + "\n";
    return s;
}

/// Loads `path` with both loaders (ours straight from disk, as the renderer does) and compares.
struct Both {
    std::vector<FlatTri> ours, theirs;
};
Both load_both(const fs::path& path) {
    Scene scene;
    Warnings warnings;
    load_obj(path, scene, warnings);
    return {flatten(scene), flatten(load_tinyobj(read_text(path), path.parent_path()))};
}

fs::path temp_dir(const std::string& name) {
    fs::path dir =
        fs::temp_directory_path() / fmt::format("toonray_tinyobj_{}_{}", name, ::getpid());
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

void write_text(const fs::path& path, std::string_view text) {
    std::ofstream(path, std::ios::binary) << text;
}

double area(const FlatTri& t) {
    auto d = [](const Vec3f& a, const Vec3f& b) {
        return std::array<double, 3>{double(b.x) - a.x, double(b.y) - a.y, double(b.z) - a.z};
    };
    auto e1 = d(t.p[0], t.p[1]), e2 = d(t.p[0], t.p[2]);
    double cx = e1[1] * e2[2] - e1[2] * e2[1], cy = e1[2] * e2[0] - e1[0] * e2[2],
           cz = e1[0] * e2[1] - e1[1] * e2[0];
    return 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
}

}  // namespace

TEST(ObjTinyobjCrossCheck, Teapot) {
    Both b = load_both(kData / "teapot.obj");
    ASSERT_EQ(b.ours.size(), 6320u);
    EXPECT_EQ(joined(differences(b.ours, b.theirs)), "");
    EXPECT_FALSE(b.ours[0].n[0].has_value());  // teapot.obj has no normals
}

TEST(ObjTinyobjCrossCheck, Spot) {
    Both b = load_both(kData / "spot.obj");
    ASSERT_EQ(b.ours.size(), 5856u);
    EXPECT_EQ(joined(differences(b.ours, b.theirs)), "");
    EXPECT_TRUE(b.ours[0].t[0].has_value());  // f v/vt
}

// Every feature at once: CRLF, two mtllib files (one CRLF), o/g, all four index forms, negative
// indices in each form, a quad, a pentagon over continued lines, vertex colours, 1-value vt,
// faces before any usemtl and with an unknown material.
TEST(ObjTinyobjCrossCheck, MixedFeaturesFile) {
    const fs::path path = kData / "scene" / "mixed.obj";
    ASSERT_NE(read_text(path).find("\r\n"), std::string::npos)
        << "mixed.obj must keep CRLF endings";
    Both b = load_both(path);
    EXPECT_EQ(joined(differences(b.ours, b.theirs)), "");

    // Not vacuous: the features really are there in what was compared.
    ASSERT_EQ(b.ours.size(), 16u);
    auto count = [&](auto pred) { return std::count_if(b.ours.begin(), b.ours.end(), pred); };
    EXPECT_EQ(count([](const FlatTri& t) { return t.material == "(default)"; }), 2);
    EXPECT_EQ(count([](const FlatTri& t) { return t.material == "red"; }), 4);
    EXPECT_EQ(count([](const FlatTri& t) { return t.material == "green"; }), 4);
    EXPECT_EQ(count([](const FlatTri& t) { return t.material == "blue"; }), 5);  // quad + pentagon
    EXPECT_EQ(count([](const FlatTri& t) { return t.material == "red_again"; }), 1);  // 2nd mtllib
    EXPECT_EQ(count([](const FlatTri& t) { return t.n[0].has_value(); }), 9);
    EXPECT_EQ(count([](const FlatTri& t) { return t.t[0].has_value(); }), 6);
    EXPECT_EQ(count([](const FlatTri& t) { return t.object == "second"; }), 9);
    EXPECT_EQ(b.ours[15].object, "third");
}

// The same content with LF endings and no continuations, parsed from memory.
TEST(ObjTinyobjCrossCheck, MixedFeaturesLfInMemory) {
    const fs::path path = kData / "scene" / "mixed.obj";
    std::string text = join_continuations(read_text(path));
    text.erase(std::remove(text.begin(), text.end(), '\r'), text.end());
    std::vector<FlatTri> ours = flatten(load_ours(text, path));
    std::vector<FlatTri> theirs = flatten(load_tinyobj(text, path.parent_path()));
    ASSERT_EQ(ours.size(), 16u);
    EXPECT_EQ(joined(differences(ours, theirs)), "");
}

// rc10 triangulates these differently from our fan (quad: its 1-3 diagonal is the shorter one;
// hexagon: rc10's ear test rejects the first ear because of where the hexagon lies relative to
// the origin). Both are valid triangulations of the same convex polygons, so compare per face:
// the same corners (with their normals) and the same area.
TEST(ObjTinyobjCrossCheck, PolygonsWhereTriangulationsDiffer) {
    const std::string text =
        "vn 0 0 1\n"
        "v 0 0 0\nv 2 0 0\nv 2.2 1 0\nv 0.1 1 0\n"  // quad: |v2-v0| > |v3-v1|
        "f 1//1 2//1 3//1 4//1\n"
        "v 4 0 1\nv 5 -1 1\nv 6 0 1\nv 6 1 1\nv 5 2 1\nv 4 1 1\n"
        "f 5 6 7 8 9 10\n";
    std::vector<FlatTri> ours = flatten(load_ours(text, "poly.obj"));
    std::vector<FlatTri> theirs = flatten(load_tinyobj(text, "."));
    ASSERT_EQ(ours.size(), 6u);
    ASSERT_EQ(theirs.size(), 6u);
    struct Face {
        std::size_t first, count;
    };
    for (Face face : {Face{0, 2}, Face{2, 4}}) {
        auto corners = [&](const std::vector<FlatTri>& tris) {
            std::vector<std::array<float, 3>> c;
            for (std::size_t i = face.first; i < face.first + face.count; ++i)
                for (int k = 0; k < 3; ++k) {
                    c.push_back({tris[i].p[k].x, tris[i].p[k].y, tris[i].p[k].z});
                    EXPECT_TRUE(same(tris[i].n[k], ours[face.first].n[0]));
                }
            std::sort(c.begin(), c.end());
            c.erase(std::unique(c.begin(), c.end()), c.end());
            return c;
        };
        EXPECT_EQ(corners(ours), corners(theirs));
        double area_ours = 0, area_theirs = 0;
        for (std::size_t i = face.first; i < face.first + face.count; ++i) {
            area_ours += area(ours[i]);
            area_theirs += area(theirs[i]);
        }
        EXPECT_NEAR(area_ours, area_theirs, 1e-6 * area_ours);
    }
}

// The comparison is not vacuous: small loader mistakes are caught.
TEST(ObjTinyobjCrossCheck, ComparisonCatchesAnOffByOne) {
    const fs::path path = kData / "teapot.obj";
    Scene scene;
    Warnings warnings;
    load_obj(path, scene, warnings);
    std::vector<FlatTri> theirs = flatten(load_tinyobj(read_text(path), path.parent_path()));
    ASSERT_TRUE(differences(flatten(scene), theirs).empty());

    Scene shifted = scene;  // a face index resolved one too low, for one corner
    shifted.tri_positions[100][1] -= 1;
    EXPECT_FALSE(differences(flatten(shifted), theirs).empty());

    Scene dropped = scene;  // one face lost
    dropped.tri_positions.pop_back();
    dropped.tri_normals.pop_back();
    dropped.tri_texcoords.pop_back();
    dropped.tri_material.pop_back();
    dropped.tri_object.pop_back();
    EXPECT_FALSE(differences(flatten(dropped), theirs).empty());

    Scene recoloured = scene;  // the wrong material
    recoloured.materials.push_back(Material{"other"});
    recoloured.tri_material[7] = 1;
    EXPECT_FALSE(differences(flatten(recoloured), theirs).empty());

    Scene rounded = scene;  // a position one ulp off (as a sloppy number parser would give)
    rounded.positions[scene.tri_positions[5][2]].y =
        std::nextafter(rounded.positions[scene.tri_positions[5][2]].y, 1e9f);
    EXPECT_FALSE(differences(flatten(rounded), theirs).empty());
}

namespace {

/// xorshift64*: the same sequence on every platform (std distributions are not portable).
struct Rng {
    std::uint64_t s;
    std::uint64_t next() {
        s ^= s >> 12;
        s ^= s << 25;
        s ^= s >> 27;
        return s * 0x2545F4914F6CDD1Dull;
    }
    int below(int n) { return static_cast<int>(next() % static_cast<std::uint64_t>(n)); }
    double uniform(double lo, double hi) { return lo + (hi - lo) * (next() >> 11) * 0x1.0p-53; }
};

/// A number in one of the spellings exporters write.
std::string spell(Rng& rng, double v) {
    switch (rng.below(5)) {
        case 0: return fmt::format("{:.6f}", v);
        case 1: return fmt::format("{}", static_cast<float>(v));  // shortest round trip
        case 2: return fmt::format("{:e}", v);
        case 3: return fmt::format("{:.3E}", v);
        default: return fmt::format("{:.9g}", v);
    }
}

/// A random OBJ using every statement both loaders read, with only quads whose 0-2 diagonal is
/// clearly the shorter one (so both triangulate the same way).
std::string random_obj(Rng& rng, int material_count) {
    std::string o;
    const char* eol = rng.below(2) ? "\r\n" : "\n";
    o += fmt::format("# random cross-check scene{}mtllib rand_a.mtl{}mtllib rand_b.mtl{}", eol, eol,
                     eol);
    std::vector<std::array<double, 3>> v;
    int nt = 0, nn = 0;
    auto index = [&](int i, int count) {  // 0-based -> positive or negative OBJ index
        return rng.below(3) == 0 ? fmt::format("{}", i - count) : fmt::format("{}", i + 1);
    };
    for (int statement = 0; statement < 120; ++statement) {
        int kind = rng.below(12);
        if (kind <= 3 || v.size() < 4) {
            // Keep the value as written (some spellings round), so quad diagonals are judged on
            // what the loaders read.
            std::array<double, 3> p;
            o += "v";
            for (double& c : p) {
                std::string s = spell(rng, rng.uniform(-5, 5));
                c = std::strtod(s.c_str(), nullptr);
                o += " " + s;
            }
            v.push_back(p);
            if (rng.below(6) == 0) o += " 0.5 0.25 1";  // vertex colour
            o += eol;
        } else if (kind == 4) {
            o += fmt::format("vt {} {}{}", spell(rng, rng.uniform(0, 1)),
                             spell(rng, rng.uniform(0, 1)), eol);
            ++nt;
        } else if (kind == 5) {
            o += fmt::format("vn {} {} {}{}", spell(rng, rng.uniform(-1, 1)),
                             spell(rng, rng.uniform(-1, 1)), spell(rng, rng.uniform(-1, 1)), eol);
            ++nn;
        } else if (kind == 6) {
            int m = rng.below(material_count + 1);
            o += m == material_count ? fmt::format("usemtl missing{}", eol)
                                     : fmt::format("usemtl m{}{}", m, eol);
        } else if (kind == 7) {
            o += fmt::format("{} part{}{}", rng.below(2) ? "o" : "g", rng.below(4), eol);
        } else if (kind == 8) {
            o += rng.below(2) ? fmt::format("  # a comment{}", eol) : std::string(eol);
        } else {
            int form = rng.below(4);  // v, v/vt, v//vn, v/vt/vn
            if ((form & 1) && nt == 0) form &= ~1;
            if ((form & 2) && nn == 0) form &= ~2;
            int corners = rng.below(3) == 0 ? 4 : 3;
            std::vector<int> vi(static_cast<std::size_t>(corners));
            for (int& i : vi) i = rng.below(static_cast<int>(v.size()));
            if (corners == 4) {
                auto d2 = [&](int a, int b) {
                    double s = 0;
                    for (int k = 0; k < 3; ++k)
                        s += (v[vi[a]][k] - v[vi[b]][k]) * (v[vi[a]][k] - v[vi[b]][k]);
                    return s;
                };
                if (d2(0, 2) > d2(1, 3)) std::rotate(vi.begin(), vi.begin() + 1, vi.end());
                if (!(d2(0, 2) < 0.99 * d2(1, 3))) vi.pop_back();  // too close to call: a triangle
            }
            o += "f";
            for (std::size_t c = 0; c < vi.size(); ++c) {
                if (c == 2 && rng.below(8) == 0) o += fmt::format(" \\{}", eol);  // continued line
                o += " " + index(vi[c], static_cast<int>(v.size()));
                if (form == 1) o += "/" + index(rng.below(nt), nt);
                if (form == 2) o += "//" + index(rng.below(nn), nn);
                if (form == 3) o += "/" + index(rng.below(nt), nt) + "/" + index(rng.below(nn), nn);
            }
            o += eol;
        }
    }
    return o;
}

}  // namespace

// Many small random files, every feature mixed in every order, CRLF and LF, materials over two
// libraries: both loaders must read the same triangles.
TEST(ObjTinyobjCrossCheck, RandomFilesAgree) {
    fs::path dir = temp_dir("random");
    Rng rng{0x9E3779B97F4A7C15ull};
    const int materials = 5;
    std::string a, b;
    for (int m = 0; m < materials; ++m) {
        std::string def =
            fmt::format("newmtl m{}\nKd {} {} {}\nNs 10\n", m, spell(rng, rng.uniform(0, 1)),
                        spell(rng, rng.uniform(0, 1)), spell(rng, rng.uniform(0, 1)));
        (m < 3 ? a : b) += def;
    }
    write_text(dir / "rand_a.mtl", a);
    write_text(dir / "rand_b.mtl", b);
    std::size_t triangles = 0;
    for (int file = 0; file < 200; ++file) {
        std::string text = random_obj(rng, materials);
        const fs::path path = dir / fmt::format("rand{}.obj", file);
        std::vector<FlatTri> ours = flatten(load_ours(text, path));
        std::vector<FlatTri> theirs = flatten(load_tinyobj(text, dir));
        triangles += ours.size();
        std::vector<std::string> diff = differences(ours, theirs);
        if (!diff.empty()) {
            write_text(path, text);
            ADD_FAILURE() << "file " << path << " differs:\n" << joined(diff);
            break;
        }
    }
    EXPECT_GT(triangles, 5000u);
    fs::remove_all(dir);
}

// Disagreements the cross-check found where our loader was the one that was wrong (fixed in
// 6607bc7); kept so they stay fixed.

// A comment that ends in a backslash (a Windows path, say) is not a continued line: `\` joins
// statements, and a comment ends at its line. Ours used to join it with the next line, losing
// that line: here the first vertex of the triangle, so -3 resolved to (9, 9, 9) instead.
TEST(ObjTinyobjCrossCheck, CommentEndingInBackslashDoesNotSwallowTheNextLine) {
    const std::string text =
        "v 9 9 9\n"
        "# exported from C:\\models\\\n"
        "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
        "f -3 -2 -1\n";
    std::vector<FlatTri> theirs = flatten(load_tinyobj(text, ".", /*join=*/false));
    ASSERT_EQ(theirs.size(), 1u);
    EXPECT_EQ(theirs[0].p[0].x, 0.0f);
    EXPECT_EQ(joined(differences(flatten(load_ours(text, "comment.obj")), theirs)), "");
}

// A number too small for a float is zero (or a denormal), as strtof and tinyobjloader read it;
// ours used to reject the file with "number '1e-50' out of range" (from_chars reports underflow
// as result_out_of_range). Exporters writing doubles produce such values near zero.
TEST(ObjTinyobjCrossCheck, UnderflowingNumbersReadAsZero) {
    const std::string text = "v 1e-50 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n";
    std::vector<FlatTri> theirs = flatten(load_tinyobj(text, "."));
    std::vector<FlatTri> ours;
    ASSERT_NO_THROW(ours = flatten(load_ours(text, "tiny.obj")));
    EXPECT_EQ(joined(differences(ours, theirs)), "");
}

// Three cases where ours used to disagree with rc10, now read as rc10 reads them:
// - A material defined again (in a later mtllib, or in the same file) keeps its first
//   definition; ours used to let the later one recolour the faces already given it.
// - Lines ended by a lone CR (old Mac files); ours used to read such a file as one line.
// - '#' inside a material name is part of it ("Mat#2"); ours used to cut it as a comment and
//   so merge "Mat#1" and "Mat#2". (A '#' that begins a word still starts a comment for us, as
//   in "usemtl red # note", where rc10 keeps "red" too.)
TEST(ObjTinyobjCrossCheck, RedefinedMaterialsCrOnlyLinesAndHashInNames) {
    const fs::path dir = temp_dir("fixed");
    write_text(dir / "a.mtl",
               "newmtl A\nKd 1 0 0\nnewmtl A\nKd 0 0 0.5\nnewmtl Mat#1\nKd 0.2 0.2 0.2\n");
    write_text(dir / "b.mtl",
               "newmtl A\nKd 0 0 1\nnewmtl B\nKd 0 1 0\nnewmtl Mat#2\nKd 0.7 0.7 0.7\n");
    const std::string body =
        "mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl A\nf 1 2 3\n"
        "mtllib b.mtl\nusemtl A\nf 1 2 3\nusemtl B\nf 1 2 3\n"
        "usemtl Mat#2\nf 1 2 3\nusemtl Mat#1\nf 1 2 3\nusemtl B # comment\nf 1 2 3\n";
    std::string cr_only = body;
    std::replace(cr_only.begin(), cr_only.end(), '\n', '\r');
    for (const std::string& text : {body, cr_only}) {
        std::vector<FlatTri> ours = flatten(load_ours(text, dir / "scene.obj"));
        std::vector<FlatTri> theirs = flatten(load_tinyobj(text, dir, /*join=*/false));
        ASSERT_EQ(theirs.size(), 6u);
        // Not vacuous: the first A (red) on both A faces, and the two '#' names apart.
        EXPECT_EQ(theirs[1].kd, Vec3f(1, 0, 0));
        EXPECT_EQ(theirs[3].material, "Mat#2");
        EXPECT_EQ(theirs[4].material, "Mat#1");
        EXPECT_EQ(joined(differences(ours, theirs)), "");
    }
    fs::remove_all(dir);
}
