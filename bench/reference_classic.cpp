// toonray_reference_classic: the classic toon pipeline written the way an application would
// write it with the usual libraries, as the yardstick of the frame benchmark (bench/frame.py,
// docs/performance.md "Frame"). It does what
//
//   toonray render SCENE.obj -o OUT.png --size WxH --edges classic --threads 1
//
// does, on one thread, with none of toonray's code on the frame's path:
//   parse    tinyobjloader `LoadObj` (triangulate, MTL from the OBJ's directory); the OBJ camera
//            block (`c eye gaze up`, docs/rendering.md) read from the same bytes by a line scan;
//            without one, toonray's auto_camera frames the triangles' vertices (the only
//            toonray function called)
//   build    one Embree 3 triangle geometry, default build quality, device "threads=1"
//   trace    one primary ray per pixel through the pixel centre, the seed's view plane;
//            rtcIntersect8 on 4x2-pixel packets in 16x16-pixel tiles with the coherent flag
//            (Embree's advice for primary rays, and 1.3-1.5x faster than rtcIntersect1 here:
//            `--rays single` uses rtcIntersect1 instead)
//   shade    interpolated vertex normals when a triangle has them, else Embree's geometric
//            normal, facing the viewer; one point light (the eye moved by half the scene's
//            radius along the view's up and right); the seed's 16-level ramp
//            k = clamp(int(l.n * 16), 0, 15) into {0.5 x4, 0.75 x4, 1.0 x8} times the MTL Kd
//            (0.8 grey without a material); white background
//   lines    the seed's: 8-bit depth map (distance / largest distance) and 8-bit normal map,
//            3x3 Sobel on each (magnitude > 8 on depth, > 4 on normals, clamped borders), the
//            two merged, blurred by [1 2 1; 2 4 2; 1 2 1] / 16 and multiplied onto the colours
//   write    libpng at its default settings (zlib level 6, adaptive filters), RGB, row by row
//
// Textured materials (map_Kd) are refused rather than drawn without their texture.
//
//   toonray_reference_classic SCENE.obj -o OUT.png [--size WxH] [--rays packet8|single]
//                             [--timings]
//   toonray_reference_classic --compare A.png B.png [--min-equal FRACTION]
//
// --timings prints each stage's milliseconds on stderr. --compare reads two PNGs (any colour
// type, through libpng's simplified API) and prints the fraction of pixels that are equal and
// that are within 16 in every channel; it exits with 1 when the equal fraction is below
// --min-equal (default 0) or the sizes differ. Exit status 2 on bad arguments or input.

#include <embree3/rtcore.h>
#include <png.h>
#include <tiny_obj_loader.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "toonray/scene/camera.h"

namespace {

// ---------------------------------------------------------------------------------------------
// Small vector maths, in the order the seed (and toonray) write it, so the rays come out the same.

struct V3 {
    float x = 0, y = 0, z = 0;
};
V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
V3 operator*(V3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
V3 operator/(V3 a, float s) { return {a.x / s, a.y / s, a.z / s}; }
float dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V3 cross(V3 a, V3 b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
float length(V3 a) { return std::sqrt(dot(a, a)); }
V3 normalize(V3 a) { return a / length(a); }

using Clock = std::chrono::steady_clock;

struct Failure : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// ---------------------------------------------------------------------------------------------
// The scene

struct Camera {
    V3 eye, gaze, up;
};

struct Mesh {
    std::vector<float> vertices;       ///< tinyobjloader's x, y, z per `v`
    std::vector<float> normals;        ///< x, y, z per `vn`
    std::vector<std::uint32_t> index;  ///< three position indices per triangle
    std::vector<std::int32_t> nindex;  ///< three normal indices per triangle, -1 for none
    std::vector<V3> kd;                ///< diffuse colour per triangle
    bool has_camera = false;
    Camera camera;
};

V3 vertex(const std::vector<float>& v, std::size_t i) {
    return {v[3 * i], v[3 * i + 1], v[3 * i + 2]};
}

// The last `c eye gaze up` statement of the file: the 0-based indices of its eye and gaze
// `v` and its up `vn`, resolved against the statements before it (negative indices count back
// from there). tinyobjloader skips these lines, so they are found by a scan of the line starts
// of the same bytes.
struct CameraIndices {
    long long eye = -1, gaze = -1, up = -1;
};

CameraIndices find_camera_block(std::string_view text) {
    CameraIndices found;
    long long v_count = 0, vn_count = 0;
    std::size_t pos = 0;
    while (pos < text.size()) {
        std::size_t end = text.find('\n', pos);
        if (end == std::string_view::npos) end = text.size();
        std::string_view line = text.substr(pos, end - pos);
        pos = end + 1;
        while (!line.empty() && (line.front() == ' ' || line.front() == '\t'))
            line.remove_prefix(1);
        if (line.size() < 2) continue;
        const bool blank = line[1] == ' ' || line[1] == '\t';
        if (line[0] == 'v' && blank) {
            ++v_count;
        } else if (line[0] == 'v' && line[1] == 'n') {
            ++vn_count;
        } else if (line[0] == 'c' && blank) {
            long long idx[3];
            std::istringstream in{std::string(line.substr(2))};
            if (!(in >> idx[0] >> idx[1] >> idx[2]))
                throw Failure("malformed camera statement: " + std::string(line));
            auto resolve = [](long long i, long long count) -> long long {
                const long long r = i > 0 ? i - 1 : count + i;
                if (i == 0 || r < 0 || r >= count) throw Failure("camera index out of range");
                return r;
            };
            found = {resolve(idx[0], v_count), resolve(idx[1], v_count), resolve(idx[2], vn_count)};
        }
    }
    return found;
}

Mesh load(const std::filesystem::path& path) {
    std::ifstream file(path, std::ios::binary);
    if (!file) throw Failure("cannot open " + path.string());
    std::string text(std::filesystem::file_size(path), '\0');
    if (!file.read(text.data(), static_cast<std::streamsize>(text.size())))
        throw Failure("cannot read " + path.string());
    const CameraIndices camera = find_camera_block(text);

    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    std::string warn, err;
    std::string dir = path.parent_path().string();
    if (!dir.empty()) dir += '/';
    tinyobj::MaterialFileReader material_reader(dir);
    {
        std::istringstream in(std::move(text));
        if (!tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &in, &material_reader,
                              /*triangulate=*/true))
            throw Failure("tinyobjloader: " + err);
    }
    for (const auto& m : materials)
        if (!m.diffuse_texname.empty())
            throw Failure("material " + m.name + " has a texture (map_Kd): not implemented here");

    Mesh mesh;
    if (camera.eye >= 0) {
        if (static_cast<std::size_t>(std::max(camera.eye, camera.gaze)) * 3 >=
                attrib.vertices.size() ||
            static_cast<std::size_t>(camera.up) * 3 >= attrib.normals.size())
            throw Failure("camera block: tinyobjloader read fewer vertices than the file has");
        mesh.has_camera = true;
        mesh.camera = {vertex(attrib.vertices, camera.eye), vertex(attrib.vertices, camera.gaze),
                       vertex(attrib.normals, camera.up)};
    }
    std::size_t triangles = 0;
    for (const auto& s : shapes) triangles += s.mesh.num_face_vertices.size();
    mesh.index.reserve(3 * triangles);
    mesh.nindex.reserve(3 * triangles);
    mesh.kd.reserve(triangles);
    for (const auto& s : shapes) {
        for (std::size_t f = 0; f < s.mesh.num_face_vertices.size(); ++f) {
            for (int k = 0; k < 3; ++k) {
                const tinyobj::index_t& i = s.mesh.indices[3 * f + k];
                mesh.index.push_back(static_cast<std::uint32_t>(i.vertex_index));
                mesh.nindex.push_back(i.normal_index);
            }
            const int m = s.mesh.material_ids[f];
            mesh.kd.push_back(m < 0 ? V3{0.8f, 0.8f, 0.8f}
                                    : V3{materials[m].diffuse[0], materials[m].diffuse[1],
                                         materials[m].diffuse[2]});
        }
    }
    mesh.vertices = std::move(attrib.vertices);
    mesh.normals = std::move(attrib.normals);
    return mesh;
}

Camera automatic_camera(const Mesh& mesh, int w, int h) {
    std::vector<toonray::Vec3f> used;
    used.reserve(mesh.index.size());
    for (std::uint32_t i : mesh.index) {
        const V3 p = vertex(mesh.vertices, i);
        used.emplace_back(p.x, p.y, p.z);
    }
    const toonray::CameraSpec c = toonray::auto_camera(used, w, h);
    return {{c.eye.x, c.eye.y, c.eye.z}, {c.gaze.x, c.gaze.y, c.gaze.z}, {c.up.x, c.up.y, c.up.z}};
}

// ---------------------------------------------------------------------------------------------
// Embree

struct Embree {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;

    explicit Embree(const Mesh& mesh) {
        device = rtcNewDevice("threads=1");
        if (!device) throw Failure("Embree: cannot create a device");
        scene = rtcNewScene(device);
        RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        const std::size_t vertex_count = mesh.vertices.size() / 3;
        // Embree's own buffers (padded as its SIMD loads require), filled from tinyobjloader's.
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0,
                                                              RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                              vertex_count));
        std::memcpy(v, mesh.vertices.data(), mesh.vertices.size() * sizeof(float));
        auto* ix = static_cast<std::uint32_t*>(
            rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                    3 * sizeof(std::uint32_t), mesh.index.size() / 3));
        std::memcpy(ix, mesh.index.data(), mesh.index.size() * sizeof(std::uint32_t));
        rtcCommitGeometry(geometry);
        rtcAttachGeometry(scene, geometry);
        rtcReleaseGeometry(geometry);
        rtcCommitScene(scene);
        if (rtcGetDeviceError(device) != RTC_ERROR_NONE) throw Failure("Embree: build failed");
    }
    ~Embree() {
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }
    Embree(const Embree&) = delete;
    Embree& operator=(const Embree&) = delete;
};

// ---------------------------------------------------------------------------------------------
// The frame

struct View {
    V3 eye, upper_left, step_x, step_y, right, up;
};

// The seed's view plane (docs/rendering.md "The camera block").
View make_view(const Camera& c, int w, int h) {
    const V3 view_dir = c.gaze - c.eye;
    if (!(length(view_dir) > 0)) throw Failure("camera: eye and gaze point are the same point");
    const float ratio = static_cast<float>(h) / static_cast<float>(w);
    const V3 center = c.eye + view_dir;
    const V3 right = normalize(cross(view_dir, c.up));
    const V3 up_vec = c.up * ratio;
    const V3 ul = center + up_vec - right, ur = center + up_vec + right,
             ll = center - right - up_vec;
    return {c.eye,
            ul,
            (ur - ul) / static_cast<float>(w),
            (ll - ul) / static_cast<float>(h),
            right,
            normalize(cross(right, view_dir))};
}

V3 ray_dir(const View& v, int x, int y) {
    const V3 p = v.upper_left + v.step_x * (static_cast<float>(x) + 0.5f) +
                 v.step_y * (static_cast<float>(y) + 0.5f);
    return normalize(p - v.eye);
}

float cel_level(float l_dot_n) {
    static constexpr float kRamp[16] = {0.5f, 0.5f, 0.5f, 0.5f, 0.75f, 0.75f, 0.75f, 0.75f,
                                        1.0f, 1.0f, 1.0f, 1.0f, 1.0f,  1.0f,  1.0f,  1.0f};
    const float scaled = l_dot_n * 16.0f;
    const int k = scaled >= 15.0f ? 15 : (scaled > 0.0f ? static_cast<int>(scaled) : 0);
    return kRamp[k];
}

std::uint8_t to_byte(float c) {
    c = c < 0.0f ? 0.0f : (c > 1.0f ? 1.0f : c);
    return static_cast<std::uint8_t>(c * 255.0f + 0.5f);
}

struct Frame {
    int w, h;
    std::vector<float> distance;  ///< +inf where the ray misses
    std::vector<V3> normal;       ///< zero where the ray misses
    std::vector<V3> colour;
};

// Shading of one hit: the interpolated vertex normal when all three corners have one, else the
// geometric normal; turned to face the eye; the seed's band for one point light.
void shade(const Mesh& mesh, const View& view, V3 light, int pixel, V3 dir, float t,
           std::uint32_t prim, float u, float v, V3 ng, Frame& f) {
    const std::int32_t* ni = &mesh.nindex[3 * static_cast<std::size_t>(prim)];
    V3 n;
    bool interpolated = false;
    if (ni[0] >= 0 && ni[1] >= 0 && ni[2] >= 0) {
        n = vertex(mesh.normals, ni[0]) * (1.0f - u - v) + vertex(mesh.normals, ni[1]) * u +
            vertex(mesh.normals, ni[2]) * v;
        const float len = length(n);
        if (len > 0.0f && std::isfinite(len)) {
            n = n / len;
            interpolated = true;
        }
    }
    if (!interpolated) {
        const float len = length(ng);
        n = len > 0.0f ? ng / len : V3{-dir.x, -dir.y, -dir.z};
    }
    if (dot(n, dir) > 0.0f) n = V3{-n.x, -n.y, -n.z};
    const V3 p = view.eye + dir * t;
    const V3 to_light = light - p;
    const float distance = length(to_light);
    const float l_dot_n = distance > 0.0f ? dot(to_light, n) / distance : 1.0f;
    f.distance[pixel] = t;
    f.normal[pixel] = n;
    f.colour[pixel] = mesh.kd[prim] * cel_level(std::max(0.0f, l_dot_n));
}

void miss(int pixel, Frame& f) {
    f.distance[pixel] = std::numeric_limits<float>::infinity();
    f.normal[pixel] = {};
    f.colour[pixel] = {1.0f, 1.0f, 1.0f};
}

constexpr int kTile = 16;

void trace_packets(const Embree& embree, const Mesh& mesh, const View& view, V3 light, Frame& f) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    alignas(32) RTCRayHit8 rh;
    alignas(32) int valid[8];
    V3 dirs[8];
    const int w = f.w, h = f.h;
    for (int ty = 0; ty < h; ty += kTile)
        for (int tx = 0; tx < w; tx += kTile)
            for (int y0 = ty; y0 < std::min(ty + kTile, h); y0 += 2)
                for (int x0 = tx; x0 < std::min(tx + kTile, w); x0 += 4) {
                    for (int k = 0; k < 8; ++k) {
                        const int x = x0 + (k & 3), y = y0 + (k >> 2);
                        valid[k] = x < w && y < h ? -1 : 0;
                        dirs[k] = valid[k] ? ray_dir(view, x, y) : V3{0, 0, 1};
                        rh.ray.org_x[k] = view.eye.x;
                        rh.ray.org_y[k] = view.eye.y;
                        rh.ray.org_z[k] = view.eye.z;
                        rh.ray.dir_x[k] = dirs[k].x;
                        rh.ray.dir_y[k] = dirs[k].y;
                        rh.ray.dir_z[k] = dirs[k].z;
                        rh.ray.tnear[k] = 0.0f;
                        rh.ray.tfar[k] = std::numeric_limits<float>::infinity();
                        rh.ray.time[k] = 0.0f;
                        rh.ray.mask[k] = 0xffffffffu;
                        rh.ray.id[k] = 0;
                        rh.ray.flags[k] = 0;
                        rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
                    }
                    rtcIntersect8(valid, embree.scene, &context, &rh);
                    for (int k = 0; k < 8; ++k) {
                        if (!valid[k]) continue;
                        const int pixel = (y0 + (k >> 2)) * w + x0 + (k & 3);
                        if (rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) {
                            miss(pixel, f);
                            continue;
                        }
                        shade(mesh, view, light, pixel, dirs[k], rh.ray.tfar[k], rh.hit.primID[k],
                              rh.hit.u[k], rh.hit.v[k],
                              {rh.hit.Ng_x[k], rh.hit.Ng_y[k], rh.hit.Ng_z[k]}, f);
                    }
                }
}

void trace_single(const Embree& embree, const Mesh& mesh, const View& view, V3 light, Frame& f) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    const int w = f.w, h = f.h;
    for (int ty = 0; ty < h; ty += kTile)
        for (int tx = 0; tx < w; tx += kTile)
            for (int y = ty; y < std::min(ty + kTile, h); ++y)
                for (int x = tx; x < std::min(tx + kTile, w); ++x) {
                    const V3 dir = ray_dir(view, x, y);
                    RTCRayHit rh{};
                    rh.ray.org_x = view.eye.x;
                    rh.ray.org_y = view.eye.y;
                    rh.ray.org_z = view.eye.z;
                    rh.ray.dir_x = dir.x;
                    rh.ray.dir_y = dir.y;
                    rh.ray.dir_z = dir.z;
                    rh.ray.tnear = 0.0f;
                    rh.ray.tfar = std::numeric_limits<float>::infinity();
                    rh.ray.mask = 0xffffffffu;
                    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                    rtcIntersect1(embree.scene, &context, &rh);
                    const int pixel = y * w + x;
                    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) miss(pixel, f);
                    else
                        shade(mesh, view, light, pixel, dir, rh.ray.tfar, rh.hit.primID, rh.hit.u,
                              rh.hit.v, {rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z}, f);
                }
}

// Rounds a value in [0, 255] to the nearest byte.
std::uint8_t round_byte(float v) { return static_cast<std::uint8_t>(v + 0.5f); }

// The squared 3x3 Sobel magnitude at the pixel whose channels start at c in row `mid`, with
// its left and right neighbours' at l and r, summed over C interleaved channels.
template <int C>
inline int sobel_magnitude2(const std::uint8_t* up, const std::uint8_t* mid,
                            const std::uint8_t* down, int l, int c, int r) {
    int m = 0;
    for (int k = 0; k < C; ++k) {
        const int gx =
            (up[r + k] + 2 * mid[r + k] + down[r + k]) - (up[l + k] + 2 * mid[l + k] + down[l + k]);
        const int gy =
            (down[l + k] + 2 * down[c + k] + down[r + k]) - (up[l + k] + 2 * up[c + k] + up[r + k]);
        m += gx * gx + gy * gy;
    }
    return m;
}

// 3x3 Sobel of an image of C interleaved 8-bit channels with clamped borders: 0 where the
// magnitude (summed over the channels) exceeds `threshold`, else 255. Compared squared, in
// integers, which is exact. The first and last columns apart, so the loop between them has no
// clamping.
template <int C>
std::vector<std::uint8_t> sobel(const std::vector<std::uint8_t>& in, int w, int h, int threshold) {
    std::vector<std::uint8_t> out(static_cast<std::size_t>(w) * h);
    const int limit = threshold * threshold;
    const std::size_t stride = static_cast<std::size_t>(w) * C;
    for (int y = 0; y < h; ++y) {
        const std::uint8_t* up = in.data() + std::max(y - 1, 0) * stride;
        const std::uint8_t* mid = in.data() + y * stride;
        const std::uint8_t* down = in.data() + std::min(y + 1, h - 1) * stride;
        std::uint8_t* row = out.data() + static_cast<std::size_t>(y) * w;
        auto edge = [&](int l, int x, int r) {
            row[x] = sobel_magnitude2<C>(up, mid, down, l * C, x * C, r * C) > limit ? 0 : 255;
        };
        edge(0, 0, std::min(1, w - 1));
        for (int x = 1; x < w - 1; ++x) edge(x - 1, x, x + 1);
        if (w > 1) edge(w - 2, w - 1, w - 1);
    }
    return out;
}

void compose_row(const float* colour, const float* weight, int values, std::uint8_t* out) {
    for (int i = 0; i < values; ++i) out[i] = to_byte(colour[i] * weight[i]);
}

std::vector<std::uint8_t> lines_and_compose(const Frame& f) {
    const int w = f.w, h = f.h;
    const std::size_t n = static_cast<std::size_t>(w) * h;
    float t_max = 0.0f;
    for (float t : f.distance)
        if (std::isfinite(t)) t_max = std::max(t_max, t);
    // 8-bit maps: depth as t / t_max (misses white), normals as n * 0.5 + 0.5 (misses black).
    std::vector<std::uint8_t> depth(n), normal(3 * n);
    for (std::size_t i = 0; i < n; ++i) {
        const float t = f.distance[i];
        depth[i] = !std::isfinite(t) ? 255 : (t_max > 0.0f ? round_byte(t / t_max * 255.0f) : 0);
    }
    const float* nv = &f.normal.data()->x;  // misses have zero normals: only their bytes differ
    for (std::size_t i = 0; i < 3 * n; ++i) normal[i] = round_byte((nv[i] * 0.5f + 0.5f) * 255.0f);
    for (std::size_t i = 0; i < n; ++i)
        if (!std::isfinite(f.distance[i]))
            normal[3 * i] = normal[3 * i + 1] = normal[3 * i + 2] = 0;
    const std::vector<std::uint8_t> depth_edges = sobel<1>(depth, w, h, 8);
    const std::vector<std::uint8_t> normal_edges = sobel<3>(normal, w, h, 4);
    // Merged: 1 off the lines, 0 on either image's lines.
    std::vector<std::uint8_t> keep(n);
    for (std::size_t i = 0; i < n; ++i) keep[i] = (depth_edges[i] & normal_edges[i]) != 0;
    // Blurred by [1 2 1; 2 4 2; 1 2 1] / 16 and multiplied onto the colours: per row the blur
    // weight of each channel value, then the row's colours times their weights.
    std::vector<std::uint8_t> image(3 * n);
    std::vector<float> weight(3 * static_cast<std::size_t>(w));
    const float* colour = &f.colour.data()->x;
    for (int y = 0; y < h; ++y) {
        const std::uint8_t* up = keep.data() + static_cast<std::size_t>(std::max(y - 1, 0)) * w;
        const std::uint8_t* mid = keep.data() + static_cast<std::size_t>(y) * w;
        const std::uint8_t* down =
            keep.data() + static_cast<std::size_t>(std::min(y + 1, h - 1)) * w;
        for (int x = 0; x < w; ++x) {
            const int l = x > 0 ? x - 1 : 0, r = x < w - 1 ? x + 1 : x;
            const int sum = up[l] + 2 * up[x] + up[r] + 2 * (mid[l] + 2 * mid[x] + mid[r]) +
                            down[l] + 2 * down[x] + down[r];
            weight[3 * x] = weight[3 * x + 1] = weight[3 * x + 2] = static_cast<float>(sum) / 16.0f;
        }
        const std::size_t first = static_cast<std::size_t>(y) * w * 3;
        compose_row(colour + first, weight.data(), 3 * w, image.data() + first);
    }
    return image;
}

void write_png(const std::filesystem::path& path, int w, int h,
               const std::vector<std::uint8_t>& rgb) {
    FILE* file = std::fopen(path.c_str(), "wb");
    if (!file) throw Failure("cannot write " + path.string());
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    if (!info || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        std::fclose(file);
        throw Failure("libpng: cannot write " + path.string());
    }
    png_init_io(png, file);
    // Defaults only: no png_set_compression_level or png_set_filter.
    png_set_IHDR(png, info, static_cast<png_uint_32>(w), static_cast<png_uint_32>(h), 8,
                 PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    for (int y = 0; y < h; ++y)
        png_write_row(png, rgb.data() + static_cast<std::size_t>(y) * w * 3);
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    if (std::fclose(file) != 0) throw Failure("cannot write " + path.string());
}

// ---------------------------------------------------------------------------------------------
// --compare

std::vector<std::uint8_t> read_png_rgb(const std::string& path, int& w, int& h) {
    png_image image{};
    image.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&image, path.c_str()))
        throw Failure(path + ": " + image.message);
    image.format = PNG_FORMAT_RGB;
    std::vector<std::uint8_t> rgb(PNG_IMAGE_SIZE(image));
    if (!png_image_finish_read(&image, nullptr, rgb.data(), 0, nullptr))
        throw Failure(path + ": " + image.message);
    w = static_cast<int>(image.width);
    h = static_cast<int>(image.height);
    return rgb;
}

int compare(const std::string& a, const std::string& b, double min_equal) {
    int wa, ha, wb, hb;
    const std::vector<std::uint8_t> pa = read_png_rgb(a, wa, ha), pb = read_png_rgb(b, wb, hb);
    if (wa != wb || ha != hb) {
        std::printf("sizes differ: %dx%d and %dx%d\n", wa, ha, wb, hb);
        return 1;
    }
    const std::size_t n = static_cast<std::size_t>(wa) * ha;
    std::size_t equal = 0, close = 0;
    for (std::size_t i = 0; i < n; ++i) {
        int worst = 0;
        for (int k = 0; k < 3; ++k)
            worst = std::max(worst, std::abs(pa[3 * i + k] - pb[3 * i + k]));
        equal += worst == 0;
        close += worst <= 16;
    }
    const double fraction = static_cast<double>(equal) / static_cast<double>(n);
    std::printf("agreement: %zu pixels, %.4f equal, %.4f within 16 per channel\n", n, fraction,
                static_cast<double>(close) / static_cast<double>(n));
    return fraction >= min_equal ? 0 : 1;
}

int usage(const char* message) {
    std::fprintf(stderr,
                 "toonray_reference_classic: %s\n"
                 "usage: toonray_reference_classic SCENE.obj -o OUT.png [--size WxH]\n"
                 "                                 [--rays packet8|single] [--timings]\n"
                 "       toonray_reference_classic --compare A.png B.png [--min-equal F]\n",
                 message);
    return 2;
}

int run(int argc, char** argv) {
    std::string scene, output, rays = "packet8";
    int w = 1280, h = 720;
    bool timings = false;
    std::vector<std::string> to_compare;
    double min_equal = 0.0;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= argc) throw Failure(a + " needs a value");
            return argv[++i];
        };
        if (a == "-o" || a == "--output") output = value();
        else if (a == "--size") {
            const std::string s = value();
            if (std::sscanf(s.c_str(), "%dx%d", &w, &h) != 2 || w < 1 || h < 1)
                return usage("--size must be WIDTHxHEIGHT");
        } else if (a == "--rays") {
            rays = value();
            if (rays != "packet8" && rays != "single") return usage("--rays is packet8 or single");
        } else if (a == "--timings") timings = true;
        else if (a == "--compare") {
            to_compare.push_back(value());
            to_compare.push_back(value());
        } else if (a == "--min-equal") min_equal = std::stod(value());
        else if (!a.empty() && a[0] == '-') return usage(("unknown option " + a).c_str());
        else if (scene.empty()) scene = a;
        else return usage("one scene only");
    }
    if (!to_compare.empty()) return compare(to_compare[0], to_compare[1], min_equal);
    if (scene.empty() || output.empty()) return usage("a scene and -o OUT.png are required");

    std::vector<std::pair<const char*, double>> stages;
    auto t0 = Clock::now();
    auto lap = [&](const char* stage) {
        const auto t1 = Clock::now();
        stages.emplace_back(stage, std::chrono::duration<double, std::milli>(t1 - t0).count());
        t0 = t1;
    };
    const Mesh mesh = load(scene);
    const Camera camera = mesh.has_camera ? mesh.camera : automatic_camera(mesh, w, h);
    lap("parse");
    const Embree embree(mesh);
    lap("build");
    const View view = make_view(camera, w, h);
    RTCBounds b;
    rtcGetSceneBounds(embree.scene, &b);
    const float radius = mesh.index.empty()
                             ? 1.0f
                             : 0.5f * length(V3{b.upper_x - b.lower_x, b.upper_y - b.lower_y,
                                                b.upper_z - b.lower_z});
    const V3 light = view.eye + (view.up + view.right) * (0.5f * radius);
    Frame f{w, h, {}, {}, {}};
    const std::size_t n = static_cast<std::size_t>(w) * h;
    f.distance.resize(n);
    f.normal.resize(n);
    f.colour.resize(n);
    if (rays == "single") trace_single(embree, mesh, view, light, f);
    else trace_packets(embree, mesh, view, light, f);
    lap("trace+shade");
    const std::vector<std::uint8_t> image = lines_and_compose(f);
    lap("lines");
    write_png(output, w, h, image);
    lap("png");
    if (timings) {
        for (const auto& [stage, ms] : stages) std::fprintf(stderr, "%s %.2f ms\n", stage, ms);
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        return run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "toonray_reference_classic: %s\n", e.what());
        return 2;
    }
}
