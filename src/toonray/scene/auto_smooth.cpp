#include "toonray/scene/auto_smooth.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <fmt/format.h>
#include <numbers>
#include <numeric>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/core/index.h"
#include "toonray/core/limits.h"
#include "toonray/core/portable_math.h"

namespace toonray {
namespace {

using Vec3d = std::array<double, 3>;

Vec3d to_double(const Vec3f& v) { return {v.x, v.y, v.z}; }
Vec3d sub(const Vec3d& a, const Vec3d& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3d cross(const Vec3d& a, const Vec3d& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Vec3d& a, const Vec3d& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double length(const Vec3d& a) { return std::sqrt(dot(a, a)); }

// atan(t) for |t| <= tan(pi/8) (0.4142...): its Taylor series to 1e-17, in IEEE operations
// only, so the normals have the same bits wherever they are computed (core/portable_math.h).
double atan_small(double t) {
    const double t2 = t * t;
    double sum = 0.0;
    for (int k = 23; k >= 0; --k) sum = (k % 2 ? -1.0 : 1.0) / (2 * k + 1) + t2 * sum;
    return t * sum;
}

// atan(t) for |t| <= 1.
double atan_unit(double t) {
    const double a = std::fabs(t);
    if (a <= 0.41421356237309503) return atan_small(t);
    const double r = std::numbers::pi / 4 + atan_small((a - 1.0) / (a + 1.0));
    return t < 0 ? -r : r;
}

// The angle in [0, pi] with sine proportional to y >= 0 and cosine to x: atan2(y, x), portably.
double angle_of(double y, double x) {
    if (y == 0.0 && x >= 0.0) return 0.0;
    if (y <= std::fabs(x)) {
        const double a = atan_unit(y / std::fabs(x));
        return x > 0.0 ? a : std::numbers::pi - a;
    }
    return std::numbers::pi / 2 - atan_unit(x / y);
}

// The bits of a coordinate as a weld key: -0 and +0 weld together.
std::uint32_t weld_bits(float f) { return std::bit_cast<std::uint32_t>(f == 0.0f ? 0.0f : f); }

struct WeldKey {
    std::uint32_t object, x, y, z;
    auto operator<=>(const WeldKey&) const = default;
};

// Union-find over corners; the smaller index becomes the root, so the result depends on the
// scene alone.
class CornerSets {
public:
    explicit CornerSets(std::size_t n) : parent_(n) {
        std::iota(parent_.begin(), parent_.end(), std::uint32_t{0});
    }
    std::uint32_t find(std::uint32_t c) {
        while (parent_[c] != c) {
            parent_[c] = parent_[parent_[c]];
            c = parent_[c];
        }
        return c;
    }
    void join(std::uint32_t a, std::uint32_t b) {
        a = find(a);
        b = find(b);
        if (a < b) parent_[b] = a;
        else if (b < a) parent_[a] = b;
    }

private:
    std::vector<std::uint32_t> parent_;
};

// An edge of a triangle, between welded vertices lo < hi; `k` is the corner it starts at.
struct Edge {
    std::uint32_t lo, hi;
    std::uint32_t tri;  // index into the smoothed triangles
    std::uint8_t k;
    bool forward;  // runs lo -> hi in the triangle's winding
};

}  // namespace

std::size_t auto_smooth(TriangleMesh& scene, float angle_degrees) {
    if (!(angle_degrees >= 0.0f && angle_degrees <= 180.0f))
        throw Error(
            fmt::format("auto-smooth angle {} is not between 0 and 180 degrees", angle_degrees));
    const double cos_limit =
        portable::cos(static_cast<double>(angle_degrees) * (std::numbers::pi / 180.0));

    // The triangles to smooth, with their unit face normals.
    std::vector<std::uint32_t> tris;
    std::vector<Vec3d> face_normal;
    for (std::size_t t = 0; t < scene.triangle_count(); ++t) {
        const auto& tn = scene.tri_normals[t];
        if (tn[0] != kNoIndex && tn[1] != kNoIndex && tn[2] != kNoIndex) continue;
        const auto& tp = scene.tri_positions[t];
        const Vec3d p0 = to_double(scene.positions[tp[0]]);
        const Vec3d n = cross(sub(to_double(scene.positions[tp[1]]), p0),
                              sub(to_double(scene.positions[tp[2]]), p0));
        const double len = length(n);
        if (!(len > 0.0) || !std::isfinite(len)) continue;  // degenerate: stays flat
        tris.push_back(static_cast<std::uint32_t>(t));
        face_normal.push_back({n[0] / len, n[1] / len, n[2] / len});
    }
    if (tris.empty()) return 0;
    const std::size_t corners = 3 * tris.size();
    if (corners >= kMaxIndexable)
        throw Error(fmt::format("auto-smooth: {} triangles are too many to smooth", tris.size()));

    // Weld corners by object and position.
    std::vector<WeldKey> key(corners);
    for (std::size_t i = 0; i < tris.size(); ++i)
        for (int k = 0; k < 3; ++k) {
            const Vec3f& p = scene.positions[scene.tri_positions[tris[i]][k]];
            key[3 * i + k] = {scene.tri_object[tris[i]], weld_bits(p.x), weld_bits(p.y),
                              weld_bits(p.z)};
        }
    std::vector<std::uint32_t> order(corners);
    std::iota(order.begin(), order.end(), std::uint32_t{0});
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
        return key[a] != key[b] ? key[a] < key[b] : a < b;
    });
    std::vector<std::uint32_t> weld(corners);
    std::uint32_t next = 0;
    for (std::size_t i = 0; i < corners; ++i) {
        if (i > 0 && key[order[i]] != key[order[i - 1]]) ++next;
        weld[order[i]] = next;
    }
    key = {};
    order = {};

    // A triangle with two corners welded together has no proper edges: it stays flat.
    std::vector<bool> usable(tris.size());
    for (std::size_t i = 0; i < tris.size(); ++i)
        usable[i] = weld[3 * i] != weld[3 * i + 1] && weld[3 * i + 1] != weld[3 * i + 2] &&
                    weld[3 * i + 2] != weld[3 * i];

    // Smooth edges join the corners at their two ends.
    std::vector<Edge> edges;
    edges.reserve(corners);
    for (std::size_t i = 0; i < tris.size(); ++i) {
        if (!usable[i]) continue;
        for (std::uint8_t k = 0; k < 3; ++k) {
            const std::uint32_t a = weld[3 * i + k], b = weld[3 * i + (k + 1) % 3];
            edges.push_back(
                {std::min(a, b), std::max(a, b), static_cast<std::uint32_t>(i), k, a < b});
        }
    }
    std::sort(edges.begin(), edges.end(), [](const Edge& a, const Edge& b) {
        if (a.lo != b.lo) return a.lo < b.lo;
        if (a.hi != b.hi) return a.hi < b.hi;
        return a.tri != b.tri ? a.tri < b.tri : a.k < b.k;
    });
    CornerSets sets(corners);
    for (std::size_t i = 0; i < edges.size();) {
        std::size_t j = i + 1;
        while (j < edges.size() && edges[j].lo == edges[i].lo && edges[j].hi == edges[i].hi) ++j;
        if (j - i == 2) {
            const Edge& e1 = edges[i];
            const Edge& e2 = edges[i + 1];
            if (e1.forward != e2.forward &&
                dot(face_normal[e1.tri], face_normal[e2.tri]) > cos_limit) {
                // e1 runs a -> b from its corner k; e2 runs b -> a from its corner k.
                const std::uint32_t a1 = 3 * e1.tri + e1.k, b1 = 3 * e1.tri + (e1.k + 1) % 3;
                const std::uint32_t b2 = 3 * e2.tri + e2.k, a2 = 3 * e2.tri + (e2.k + 1) % 3;
                sets.join(a1, a2);
                sets.join(b1, b2);
            }
        }
        i = j;
    }
    edges = {};

    // Each group's normal: its face normals weighted by the corner angles, summed in corner
    // order.
    std::vector<Vec3d> sum(corners, Vec3d{0.0, 0.0, 0.0});
    for (std::size_t i = 0; i < tris.size(); ++i) {
        if (!usable[i]) continue;
        const auto& tp = scene.tri_positions[tris[i]];
        for (int k = 0; k < 3; ++k) {
            const Vec3d p = to_double(scene.positions[tp[k]]);
            const Vec3d u = sub(to_double(scene.positions[tp[(k + 1) % 3]]), p);
            const Vec3d v = sub(to_double(scene.positions[tp[(k + 2) % 3]]), p);
            const double angle = angle_of(length(cross(u, v)), dot(u, v));
            Vec3d& s = sum[sets.find(static_cast<std::uint32_t>(3 * i + k))];
            for (int c = 0; c < 3; ++c) s[c] += face_normal[i][c] * angle;
        }
    }
    std::vector<std::uint32_t> normal_of(corners, kNoIndex);
    std::size_t smoothed = 0;
    for (std::size_t i = 0; i < tris.size(); ++i) {
        if (!usable[i]) continue;
        std::array<std::uint32_t, 3> tn{};
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t root = sets.find(static_cast<std::uint32_t>(3 * i + k));
            if (normal_of[root] == kNoIndex) {
                const Vec3d& s = sum[root];
                const double len = length(s);
                const Vec3d n = len > 0.0 && std::isfinite(len)
                                    ? Vec3d{s[0] / len, s[1] / len, s[2] / len}
                                    : face_normal[i];
                if (scene.normals.size() >= kMaxIndexable)
                    throw Error("auto-smooth: the normals would not fit 32-bit indices");
                normal_of[root] = static_cast<std::uint32_t>(scene.normals.size());
                scene.normals.push_back(Vec3f{static_cast<float>(n[0]), static_cast<float>(n[1]),
                                              static_cast<float>(n[2])});
            }
            tn[k] = normal_of[root];
        }
        scene.tri_normals[tris[i]] = tn;
        ++smoothed;
    }
    return smoothed;
}

std::size_t auto_smooth_scene(Scene& scene, float angle_degrees) {
    std::size_t count = auto_smooth(static_cast<TriangleMesh&>(scene), angle_degrees);
    for (auto& mesh : scene.meshes) {
        bool flat = false;
        for (const auto& tn : mesh->tri_normals)
            flat = flat || tn[0] == kNoIndex || tn[1] == kNoIndex || tn[2] == kNoIndex;
        if (!flat) continue;
        auto smoothed = std::make_shared<TriangleMesh>(*mesh);
        // One object: the instance names the triangles, not the mesh.
        std::fill(smoothed->tri_object.begin(), smoothed->tri_object.end(), 0u);
        count += auto_smooth(*smoothed, angle_degrees);
        mesh = std::move(smoothed);
    }
    return count;
}

}  // namespace toonray
