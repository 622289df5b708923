#pragma once
/// Scenes built in code for the ink tests, the teapot of tests/data, a brute-force occluder
/// count to check the accelerated one against, and the speck count of a line image.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "toonray/accel/triangle_accel.h"
#include "toonray/core/image.h"
#include "toonray/ink/visibility.h"
#include "toonray/scene/camera.h"
#include "toonray/scene/obj_loader.h"
#include "toonray/scene/scene.h"

namespace toonray::test_support {

inline std::uint32_t add_vertex(Scene& s, const Vec3f& p) {
    s.positions.push_back(p);
    return static_cast<std::uint32_t>(s.positions.size() - 1);
}

/// A quad (two triangles, wound a b c / a c d) with its own four vertices.
inline void add_quad(Scene& s, const Vec3f& a, const Vec3f& b, const Vec3f& c, const Vec3f& d,
                     std::uint32_t material = 0, std::uint32_t object = 0) {
    const std::uint32_t ia = add_vertex(s, a), ib = add_vertex(s, b), ic = add_vertex(s, c),
                        id = add_vertex(s, d);
    s.add_triangle({ia, ib, ic}, material, object);
    s.add_triangle({ia, ic, id}, material, object);
}

/// An axis-aligned box from `lo` to `hi`, outward-wound, each face with its own vertices (as
/// OBJ exporters with split normals write it).
inline void add_box(Scene& s, const Vec3f& lo, const Vec3f& hi, std::uint32_t object = 0) {
    auto c = [&](int i) {
        return Vec3f(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
    };
    add_quad(s, c(0), c(2), c(3), c(1), 0, object);  // z = lo
    add_quad(s, c(4), c(5), c(7), c(6), 0, object);  // z = hi
    add_quad(s, c(0), c(1), c(5), c(4), 0, object);  // y = lo
    add_quad(s, c(2), c(6), c(7), c(3), 0, object);  // y = hi
    add_quad(s, c(0), c(4), c(6), c(2), 0, object);  // x = lo
    add_quad(s, c(1), c(3), c(7), c(5), 0, object);  // x = hi
}

/// A raised panel in the plane z = 0 facing +z, `half_x` by `half_y`, moulded by `profile`:
/// (inset from the outer edge, height) pairs from the outer edge inward. Consecutive pairs make
/// a ring of four mitred trapezoids around the panel, the last pair a flat field in the middle.
/// Corners are computed from the same expressions, so rings share positions bit for bit.
inline void add_moulded_panel(Scene& s, float half_x, float half_y,
                              const std::vector<std::pair<float, float>>& profile,
                              std::uint32_t object = 0) {
    // Corner i (counter-clockwise from (-x, -y)) of the rectangle at `inset`, at `height`.
    auto corner = [&](int i, float inset, float height) {
        const float x = half_x - inset, y = half_y - inset;
        const float sx = (i == 1 || i == 2) ? x : -x, sy = i >= 2 ? y : -y;
        return Vec3f(sx, sy, height);
    };
    for (std::size_t k = 0; k + 1 < profile.size(); ++k) {
        const auto [d0, h0] = profile[k];
        const auto [d1, h1] = profile[k + 1];
        for (int i = 0; i < 4; ++i)
            add_quad(s, corner(i, d0, h0), corner((i + 1) % 4, d0, h0), corner((i + 1) % 4, d1, h1),
                     corner(i, d1, h1), 0, object);
    }
    const auto [d, h] = profile.back();
    add_quad(s, corner(0, d, h), corner(1, d, h), corner(2, d, h), corner(3, d, h), 0, object);
}

/// A UV sphere with shared vertices and unit vertex normals.
inline void add_sphere(Scene& s, const Vec3f& centre, float radius, int rings, int segments,
                       std::uint32_t object = 0) {
    const auto base = static_cast<std::uint32_t>(s.positions.size());
    const auto nbase = static_cast<std::uint32_t>(s.normals.size());
    const float pi = std::numbers::pi_v<float>;
    for (int r = 0; r <= rings; ++r)
        for (int k = 0; k < segments; ++k) {
            const float theta = pi * static_cast<float>(r) / static_cast<float>(rings);
            const float phi = 2 * pi * static_cast<float>(k) / static_cast<float>(segments);
            Vec3f n(std::sin(theta) * std::cos(phi), std::cos(theta),
                    std::sin(theta) * std::sin(phi));
            if (r == 0 || r == rings)
                n = Vec3f(0.0f, r == 0 ? 1.0f : -1.0f, 0.0f);  // sin(pi) is not 0 in float
            s.positions.push_back(centre + n * radius);
            s.normals.push_back(n);
        }
    auto id = [&](int r, int k) {
        return static_cast<std::uint32_t>(r * segments + (k % segments));
    };
    for (int r = 0; r < rings; ++r)
        for (int k = 0; k < segments; ++k) {
            const std::uint32_t a = id(r, k), b = id(r, k + 1), c = id(r + 1, k + 1),
                                d = id(r + 1, k);
            if (r > 0)
                s.add_triangle({base + a, base + b, base + c}, 0, object,
                               {nbase + a, nbase + b, nbase + c});
            if (r + 1 < rings)
                s.add_triangle({base + a, base + c, base + d}, 0, object,
                               {nbase + a, nbase + c, nbase + d});
        }
}

/// `count` random triangles in [-1, 1]^3 of size up to `size`, from a fixed seed.
inline Scene random_scene(int count, unsigned seed, float size = 0.4f) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> pos(-1.0f, 1.0f), off(-size, size);
    Scene s;
    for (int i = 0; i < count; ++i) {
        const Vec3f c(pos(rng), pos(rng), pos(rng));
        std::uint32_t v[3];
        for (auto& k : v) k = add_vertex(s, c + Vec3f(off(rng), off(rng), off(rng)));
        s.add_triangle({v[0], v[1], v[2]}, static_cast<std::uint32_t>(i % 3), 0);
    }
    return s;
}

inline TriangleAccel build_accel(const Scene& s) {
    TriangleAccel accel;
    accel.build(s.positions, s.tri_positions);
    return accel;
}

/// The occluders of `point` as count_occluders defines them, by testing every triangle.
inline int brute_force_occluders(const Scene& s, const Vec3f& point, const Vec3f& eye,
                                 const std::vector<std::uint32_t>& ignored,
                                 const ink::VisibilitySettings& settings) {
    int count = 0;
    const Vec3f dir = eye - point;
    for (std::uint32_t t = 0; t < s.triangle_count(); ++t) {
        if (std::binary_search(ignored.begin(), ignored.end(), t)) continue;
        const auto& v = s.tri_positions[t];
        float hit_t, u, w;
        if (intersect_triangle(Ray{point, dir, 1.0f - settings.self_epsilon}, s.positions[v[0]],
                               s.positions[v[1]], s.positions[v[2]], hit_t, u, w) &&
            hit_t > settings.self_epsilon)
            ++count;
    }
    return std::min(count, settings.max_invisibility);
}

/// `camera` turned by `degrees` about the vertical (y) through its gaze point.
inline CameraSpec orbit_camera(const CameraSpec& camera, float degrees) {
    const float a = degrees * std::numbers::pi_v<float> / 180.0f;
    auto turn = [&](const Vec3f& v) {
        return Vec3f(v.x * std::cos(a) - v.z * std::sin(a), v.y,
                     v.x * std::sin(a) + v.z * std::cos(a));
    };
    return {camera.gaze + turn(camera.eye - camera.gaze), camera.gaze, turn(camera.up)};
}

/// The largest deviation of a value in a sequence from the mean of its two neighbours,
/// relative to that mean.
inline double worst_deviation(const std::vector<double>& values) {
    double worst = 0;
    for (std::size_t i = 1; i + 1 < values.size(); ++i) {
        const double mean = 0.5 * (values[i - 1] + values[i + 1]);
        worst = std::max(worst, std::abs(values[i] - mean) / mean);
    }
    return worst;
}

/// Specks: 8-connected groups of at most `max_size` pixels darker than `threshold` (8% of
/// white) in a black-on-white line image.
inline int count_specks(const ImageGray8& lines, int max_size = 12, float threshold = 0.08f) {
    const int w = lines.width(), h = lines.height();
    std::vector<std::uint8_t> seen(static_cast<std::size_t>(w) * h, 0);
    auto dark = [&](int x, int y) { return lines(x, y) < threshold * 255.0f; };
    int specks = 0;
    std::vector<std::pair<int, int>> stack;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (seen[static_cast<std::size_t>(y) * w + x] || !dark(x, y)) continue;
            int size = 0;
            stack.assign(1, {x, y});
            seen[static_cast<std::size_t>(y) * w + x] = 1;
            while (!stack.empty()) {
                auto [cx, cy] = stack.back();
                stack.pop_back();
                ++size;
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        const int nx = cx + dx, ny = cy + dy;
                        if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
                        auto& flag = seen[static_cast<std::size_t>(ny) * w + nx];
                        if (flag || !dark(nx, ny)) continue;
                        flag = 1;
                        stack.push_back({nx, ny});
                    }
            }
            if (size <= max_size) ++specks;
        }
    return specks;
}

/// tests/data/teapot.obj with its accelerator and a camera that frames it in a width x height
/// image.
struct Teapot {
    Scene scene;
    TriangleAccel accel;
    CameraSpec camera;
    Teapot(int w, int h) {
        Warnings warnings;
        load_obj(std::string(TOONRAY_TEST_DATA_DIR) + "/teapot.obj", scene, warnings);
        accel.build(scene.positions, scene.tri_positions);
        std::vector<Vec3f> used;
        for (const auto& t : scene.tri_positions)
            for (std::uint32_t v : t) used.push_back(scene.positions[v]);
        camera = auto_camera(used, w, h);
    }
};

}  // namespace toonray::test_support
