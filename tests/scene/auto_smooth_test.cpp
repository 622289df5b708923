#include "toonray/scene/auto_smooth.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>

#include "toonray/core/error.h"

namespace toonray {
namespace {

// Appends a quad (a, b, c, d counter-clockwise seen from outside) as two triangles with their
// own vertices, as an STL-like scan stores them: nothing is shared but positions.
void add_quad(Scene& s, Vec3f a, Vec3f b, Vec3f c, Vec3f d, std::uint32_t object = 0) {
    for (const auto& tri : {std::array<Vec3f, 3>{a, b, c}, std::array<Vec3f, 3>{a, c, d}}) {
        const auto base = static_cast<std::uint32_t>(s.positions.size());
        for (const Vec3f& p : tri) s.positions.push_back(p);
        s.add_triangle({base, base + 1, base + 2}, 0, object);
    }
}

// A closed cylinder of radius 1 around y from y = 0 to 2: `sides` quads around, fan caps.
Scene cylinder(int sides) {
    Scene s;
    auto ring = [&](int i, float y) {
        const double a = 2.0 * std::numbers::pi * (i % sides) / sides;  // the seam welds
        return Vec3f{static_cast<float>(std::cos(a)), y, static_cast<float>(-std::sin(a))};
    };
    for (int i = 0; i < sides; ++i) {
        add_quad(s, ring(i, 0), ring(i + 1, 0), ring(i + 1, 2), ring(i, 2));
        // Caps: triangles to the centre, wound to face out (up at the top, down at the bottom).
        for (const auto& tri : {std::array<Vec3f, 3>{Vec3f{0, 2, 0}, ring(i, 2), ring(i + 1, 2)},
                                std::array<Vec3f, 3>{Vec3f{0, 0, 0}, ring(i + 1, 0), ring(i, 0)}}) {
            const auto base = static_cast<std::uint32_t>(s.positions.size());
            for (const Vec3f& p : tri) s.positions.push_back(p);
            s.add_triangle({base, base + 1, base + 2}, 0, 0);
        }
    }
    return s;
}

Scene cube() {
    Scene s;
    const Vec3f p[8] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                        {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    add_quad(s, p[0], p[3], p[2], p[1]);  // z = 0, facing -z
    add_quad(s, p[4], p[5], p[6], p[7]);  // z = 1
    add_quad(s, p[0], p[1], p[5], p[4]);  // y = 0
    add_quad(s, p[3], p[7], p[6], p[2]);  // y = 1
    add_quad(s, p[0], p[4], p[7], p[3]);  // x = 0
    add_quad(s, p[1], p[2], p[6], p[5]);  // x = 1
    return s;
}

Vec3f face_normal(const Scene& s, std::size_t t) {
    const auto& tp = s.tri_positions[t];
    return normalize(
        cross(s.positions[tp[1]] - s.positions[tp[0]], s.positions[tp[2]] - s.positions[tp[0]]));
}

TEST(AutoSmooth, CylinderSidesSmoothCapsFlat) {
    const int sides = 24;  // 15 degrees between side faces
    Scene s = cylinder(sides);
    ASSERT_EQ(auto_smooth(s, 30.0f), s.triangle_count());
    for (std::size_t t = 0; t < s.triangle_count(); ++t) {
        const Vec3f fn = face_normal(s, t);
        const bool cap = std::abs(fn.y) > 0.99f;
        for (int k = 0; k < 3; ++k) {
            ASSERT_NE(s.tri_normals[t][k], kNoIndex);
            const Vec3f n = s.normals[s.tri_normals[t][k]];
            const Vec3f p = s.positions[s.tri_positions[t][k]];
            if (cap) {
                // Flat: the cap's own normal, the 90-degree edge to the sides is sharp.
                EXPECT_NEAR(n.x, 0.0f, 1e-6f);
                EXPECT_NEAR(n.y, fn.y > 0 ? 1.0f : -1.0f, 1e-6f);
                EXPECT_NEAR(n.z, 0.0f, 1e-6f);
            } else {
                // Smooth: radial at the vertex, not the face's normal.
                EXPECT_NEAR(n.x, p.x, 1e-5f) << "triangle " << t << " corner " << k;
                EXPECT_NEAR(n.y, 0.0f, 1e-6f);
                EXPECT_NEAR(n.z, p.z, 1e-5f);
                EXPECT_LT(dot(n, fn), 0.9995f);  // cos 1.8 degrees: really not flat
            }
        }
    }
    // Shared by the corners of a welded vertex, not one per corner: one per side vertex (two
    // rings), and per cap one per ring vertex and its centre.
    EXPECT_EQ(s.normals.size(), static_cast<std::size_t>(2 * sides + 2 * (sides + 1)));
}

TEST(AutoSmooth, BelowTheSideAngleTheCylinderStaysFaceted) {
    Scene s = cylinder(24);
    auto_smooth(s, 10.0f);  // side faces meet at 15 degrees: all edges sharp
    for (std::size_t t = 0; t < s.triangle_count(); ++t) {
        const Vec3f fn = face_normal(s, t);
        for (int k = 0; k < 3; ++k) {
            const Vec3f n = s.normals[s.tri_normals[t][k]];
            EXPECT_GT(dot(n, fn), 0.999999f) << "triangle " << t;
        }
    }
}

TEST(AutoSmooth, CubeStaysFlatAt30Degrees) {
    Scene s = cube();
    ASSERT_EQ(auto_smooth(s, 30.0f), 12u);
    for (std::size_t t = 0; t < s.triangle_count(); ++t) {
        const Vec3f fn = face_normal(s, t);
        for (int k = 0; k < 3; ++k) {
            const Vec3f n = s.normals[s.tri_normals[t][k]];
            EXPECT_EQ(n.x, fn.x);
            EXPECT_EQ(n.y, fn.y);
            EXPECT_EQ(n.z, fn.z);
        }
    }
    EXPECT_EQ(s.normals.size(), 24u);  // a normal per face and vertex: 6 x 4
}

TEST(AutoSmooth, WholeCubeSmoothAbove90Degrees) {
    Scene s = cube();
    auto_smooth(s, 91.0f);
    // Every corner of a cube vertex takes the diagonal, whatever face it belongs to.
    for (std::size_t t = 0; t < s.triangle_count(); ++t)
        for (int k = 0; k < 3; ++k) {
            const Vec3f n = s.normals[s.tri_normals[t][k]];
            const Vec3f p = s.positions[s.tri_positions[t][k]];
            const Vec3f expected = normalize(p - Vec3f{0.5f});
            EXPECT_NEAR(dot(n, expected), 1.0f, 1e-6f);
        }
    EXPECT_EQ(s.normals.size(), 8u);
}

TEST(AutoSmooth, ObjectsAndGivenNormalsAreKeptApart) {
    Scene s;
    // Two quads folded by 10 degrees along x = 0, in two objects: not smoothed across.
    const float c = std::cos(0.1745f), sn = std::sin(0.1745f);
    add_quad(s, {-1, 0, 0}, {0, 0, 0}, {0, 0, -1}, {-1, 0, -1}, 0);
    add_quad(s, {0, 0, 0}, {c, sn, 0}, {c, sn, -1}, {0, 0, -1}, 1);
    // A triangle with its own normals: untouched.
    s.normals.push_back({0, 0, 1});
    s.positions.push_back({5, 0, 0});
    s.positions.push_back({6, 0, 0});
    s.positions.push_back({5, 1, 0});
    const auto b = static_cast<std::uint32_t>(s.positions.size() - 3);
    s.add_triangle({b, b + 1, b + 2}, 0, 0, {0, 0, 0});
    EXPECT_EQ(auto_smooth(s, 30.0f), 4u);
    EXPECT_EQ(s.tri_normals[4], (std::array<std::uint32_t, 3>{0, 0, 0}));
    for (std::size_t t = 0; t < 4; ++t) {
        const Vec3f fn = face_normal(s, t);
        for (int k = 0; k < 3; ++k) EXPECT_GT(dot(s.normals[s.tri_normals[t][k]], fn), 0.999999f);
    }
    // In one object the fold is smoothed: the shared edge's normals are the mean.
    for (auto& o : s.tri_object) o = 0;
    s.normals.resize(1);
    for (std::size_t t = 0; t < 4; ++t) s.tri_normals[t] = {kNoIndex, kNoIndex, kNoIndex};
    auto_smooth(s, 30.0f);
    const Vec3f mid = s.normals[s.tri_normals[0][1]];  // corner at (0, 0, 0)
    EXPECT_NEAR(mid.x, -std::sin(0.1745f / 2), 1e-5f);
    EXPECT_NEAR(mid.y, std::cos(0.1745f / 2), 1e-5f);
}

TEST(AutoSmooth, Deterministic) {
    Scene a = cylinder(40), b = cylinder(40);
    auto_smooth(a, 45.0f);
    auto_smooth(b, 45.0f);
    ASSERT_EQ(a.normals.size(), b.normals.size());
    EXPECT_EQ(0, std::memcmp(a.normals.data(), b.normals.data(), a.normals.size() * sizeof(Vec3f)));
    EXPECT_EQ(a.tri_normals, b.tri_normals);
}

TEST(AutoSmooth, RejectsBadAngles) {
    Scene s = cube();
    EXPECT_THROW(auto_smooth(s, -1.0f), Error);
    EXPECT_THROW(auto_smooth(s, 181.0f), Error);
    EXPECT_THROW(auto_smooth(s, std::nanf("")), Error);
}

}  // namespace
}  // namespace toonray
