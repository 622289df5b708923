#include "bench_scene.h"

#include <fmt/format.h>
#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/io/file.h"
#include "toonray/scene/obj_loader.h"

namespace toonray::bench {
namespace {

using Tri = std::array<std::uint32_t, 3>;

/// Accumulates OBJ text; indices in faces are 1-based and absolute.
struct ObjText {
    std::string text;
    std::size_t vertices = 0, normals = 0, texcoords = 0;

    void v(const Vec3f& p) {
        text += fmt::format("v {:.6f} {:.6f} {:.6f}\n", p.x, p.y, p.z);
        ++vertices;
    }
    void vn(const Vec3f& n) {
        text += fmt::format("vn {:.6f} {:.6f} {:.6f}\n", n.x, n.y, n.z);
        ++normals;
    }
    void vt(const Vec2f& t) {
        text += fmt::format("vt {:.6f} {:.6f}\n", t.x, t.y);
        ++texcoords;
    }
};

/// Subdivided icosahedron on the unit sphere.
void icosphere(int levels, std::vector<Vec3f>& verts, std::vector<Tri>& tris) {
    // (0, +-1, +-phi) and its cyclic permutations; phi = (1 + sqrt 5) / 2 written out.
    const float t = 1.6180339887f;
    verts = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
             {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
    tris = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
            {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
            {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    for (Vec3f& v : verts) v = normalize(v);
    for (int level = 0; level < levels; ++level) {
        std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoints;
        auto mid = [&](std::uint32_t a, std::uint32_t b) {
            auto key = std::minmax(a, b);
            auto [it, inserted] = midpoints.try_emplace({key.first, key.second}, 0u);
            if (inserted) {
                it->second = static_cast<std::uint32_t>(verts.size());
                verts.push_back(normalize((verts[a] + verts[b]) * 0.5f));
            }
            return it->second;
        };
        std::vector<Tri> next;
        next.reserve(tris.size() * 4);
        for (const Tri& f : tris) {
            std::uint32_t ab = mid(f[0], f[1]), bc = mid(f[1], f[2]), ca = mid(f[2], f[0]);
            next.push_back({f[0], ab, ca});
            next.push_back({f[1], bc, ab});
            next.push_back({f[2], ca, bc});
            next.push_back({ab, bc, ca});
        }
        tris = std::move(next);
    }
}

/// A smooth bumpy radius: a polynomial, so no libm result can differ between machines.
float displacement(const Vec3f& p) {
    float x = p.x, y = p.y, z = p.z;
    return 1.0f + 0.22f * (x * x * y - 0.6f * y * z * z + 0.8f * x * y * z) +
           0.12f * (x * x - z * z) * (1.0f - y * y);
}

void write_blob(ObjText& o, const Vec3f& center, float radius) {
    std::vector<Vec3f> verts;
    std::vector<Tri> tris;
    icosphere(5, verts, tris);
    std::vector<Vec3f> pos(verts.size());
    for (std::size_t i = 0; i < verts.size(); ++i)
        pos[i] = center + verts[i] * (radius * displacement(verts[i]));
    // Vertex normals: area-weighted sums of the face normals around each vertex.
    std::vector<Vec3f> nrm(verts.size());
    for (const Tri& f : tris) {
        Vec3f n = cross(pos[f[1]] - pos[f[0]], pos[f[2]] - pos[f[0]]);
        for (std::uint32_t v : f) nrm[v] += n;
    }
    const std::size_t v0 = o.vertices, n0 = o.normals;
    o.text += "o blob\nusemtl blob_orange\n";
    for (const Vec3f& p : pos) o.v(p);
    for (const Vec3f& n : nrm) o.vn(normalize(n));
    for (const Tri& f : tris)
        o.text += fmt::format("f {}//{} {}//{} {}//{}\n", v0 + f[0] + 1, n0 + f[0] + 1,
                              v0 + f[1] + 1, n0 + f[1] + 1, v0 + f[2] + 1, n0 + f[2] + 1);
}

/// Copies a loaded mesh, scaled about the origin then moved so its lowest point sits on y = 0
/// at `(x, z)`.
void write_copy(ObjText& o, const Scene& s, const char* name, const char* material, float scale,
                float x, float z) {
    float min_y = INFINITY;
    for (const Vec3f& p : s.positions) min_y = std::min(min_y, p.y * scale);
    const Vec3f offset(x, -min_y, z);
    const std::size_t v0 = o.vertices, t0 = o.texcoords;
    o.text += fmt::format("o {}\nusemtl {}\n", name, material);
    for (const Vec3f& p : s.positions) o.v(p * scale + offset);
    for (const Vec2f& t : s.texcoords) o.vt(t);
    for (std::size_t i = 0; i < s.triangle_count(); ++i) {
        o.text += "f";
        for (int k = 0; k < 3; ++k) {
            o.text += fmt::format(" {}", v0 + s.tri_positions[i][k] + 1);
            if (s.tri_texcoords[i][k] != kNoIndex)
                o.text += fmt::format("/{}", t0 + s.tri_texcoords[i][k] + 1);
        }
        o.text += '\n';
    }
}

void write_ground(ObjText& o, int cells, float half) {
    const std::size_t v0 = o.vertices;
    o.text += "o ground\nusemtl ground_green\n";
    for (int j = 0; j <= cells; ++j)
        for (int i = 0; i <= cells; ++i)
            o.v({-half + 2 * half * i / cells, 0.0f, -half + 2 * half * j / cells});
    auto at = [&](int i, int j) { return v0 + static_cast<std::size_t>(j) * (cells + 1) + i + 1; };
    for (int j = 0; j < cells; ++j)
        for (int i = 0; i < cells; ++i) {
            o.text += fmt::format("f {} {} {}\n", at(i, j), at(i, j + 1), at(i + 1, j + 1));
            o.text += fmt::format("f {} {} {}\n", at(i, j), at(i + 1, j + 1), at(i + 1, j));
        }
}

/// Appends the camera block for an eye looking at `target` with a horizontal field of view of
/// 2 atan(1 / gaze_distance), up taken from world y.
void write_camera(ObjText& o, const Vec3f& eye, const Vec3f& target, float gaze_distance) {
    const Vec3f view_dir = normalize(target - eye);
    const Vec3f right = normalize(cross(view_dir, Vec3f(0.0f, 1.0f, 0.0f)));
    o.text += "# camera: eye, gaze point, up\n";
    o.v(eye);
    o.v(eye + view_dir * gaze_distance);
    o.vn(cross(right, view_dir));
    o.text += "c -2 -1 -1\n";
}

void write_if_changed(const std::filesystem::path& path, const std::string& text) {
    std::ifstream in(path, std::ios::binary);
    if (in) {
        std::ostringstream old;
        old << in.rdbuf();
        if (old.str() == text) return;
    }
    write_file_atomic(path, {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
}

}  // namespace

std::filesystem::path write_bench_scene(const std::filesystem::path& dir,
                                        const std::filesystem::path& data_dir) {
    Scene teapot, spot;
    Warnings warnings;
    load_obj(data_dir / "teapot.obj", teapot, warnings);
    load_obj(data_dir / "spot.obj", spot, warnings);

    ObjText o;
    o.text =
        "# toonray benchmark scene, generated by `toonray_bench --generate` "
        "(bench/bench_scene.cpp).\n"
        "# 34968 triangles: a displaced icosphere, the teapot, spot and a ground grid.\n"
        "mtllib scene35k.mtl\n";
    write_blob(o, {0.0f, 3.5f, 0.0f}, 2.2f);
    write_copy(o, teapot, "teapot", "teapot_blue", 1.0f, -6.5f, 1.0f);
    write_copy(o, spot, "spot", "spot_white", 2.5f, 6.0f, 0.5f);
    write_ground(o, 34, 11.0f);

    // A camera block framing the objects (the automatic camera would frame the whole ground):
    // 60 degrees horizontal field of view, so |gaze - eye| = 1 / tan(30 deg).
    write_camera(o, {0.0f, 9.0f, 17.0f}, {0.0f, 2.5f, 0.0f}, 1.7320508f);

    const std::string mtl =
        "# Materials for scene35k.obj\n"
        "newmtl blob_orange\nKd 0.95 0.55 0.2\n\n"
        "newmtl teapot_blue\nKd 0.3 0.5 0.9\n\n"
        "newmtl spot_white\nKd 0.92 0.9 0.85\n\n"
        "newmtl ground_green\nKd 0.55 0.75 0.45\n";
    std::filesystem::create_directories(dir);
    const std::filesystem::path obj = dir / "scene35k.obj";
    write_if_changed(dir / "scene35k.mtl", mtl);
    write_if_changed(obj, o.text);
    return obj;
}

std::filesystem::path write_scan_scene(const std::filesystem::path& dir,
                                       const std::filesystem::path& data_dir) {
    Scene spot;
    Warnings warnings;
    load_obj(data_dir / "spot.obj", spot, warnings);

    // Vertices: spot's own, then one per edge at its midpoint (shared by the two triangles on
    // the edge), then the centroids of the four triangles each triangle is cut into.
    std::vector<Vec3f> positions = spot.positions;
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoints;
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
        auto [it, inserted] = midpoints.try_emplace(std::minmax(a, b), 0u);
        if (inserted) {
            it->second = static_cast<std::uint32_t>(positions.size());
            positions.push_back((positions[a] + positions[b]) * 0.5f);
        }
        return it->second;
    };
    std::vector<Tri> tris;
    tris.reserve(spot.triangle_count() * 12);
    for (const auto& t : spot.tri_positions) {
        const std::uint32_t a = t[0], b = t[1], c = t[2];
        const std::uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
        for (const Tri& q : {Tri{a, ab, ca}, Tri{ab, b, bc}, Tri{ca, bc, c}, Tri{ab, bc, ca}}) {
            const auto g = static_cast<std::uint32_t>(positions.size());
            positions.push_back((positions[q[0]] + positions[q[1]] + positions[q[2]]) / 3.0f);
            tris.push_back({q[0], q[1], g});
            tris.push_back({q[1], q[2], g});
            tris.push_back({q[2], q[0], g});
        }
    }

    ObjText o;
    o.text = fmt::format(
        "# toonray benchmark scan, generated by `toonray_bench --generate` "
        "(bench/bench_scene.cpp).\n"
        "# tests/data/spot.obj, each triangle cut in 4 at its edge midpoints, then each of those "
        "in 3 at its centroid:\n"
        "# {} triangles over {} shared vertices, positions only, as a scanner writes them.\n",
        tris.size(), positions.size());
    for (const Vec3f& p : positions) o.v(p);
    for (const Tri& t : tris) o.text += fmt::format("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    // From the cow's right side, 20 degrees towards its head (spot faces -z) and a little above;
    // 60 degrees horizontal field of view. The cow fills about 85% of the frame's height.
    write_camera(o, {3.0f, 0.8f, -1.0f}, {0.0f, 0.1f, 0.1f}, 1.7320508f);

    std::filesystem::create_directories(dir);
    const std::filesystem::path obj = dir / "scan70k.obj";
    write_if_changed(obj, o.text);
    return obj;
}

}  // namespace toonray::bench
