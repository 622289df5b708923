#pragma once
/// Affine transforms of 3D points in double precision: instance placements (scene/scene.h),
/// meshes appended by a transform (scene/scene_arrays.h) and glTF node matrices. Products are
/// summed in double and rounded to float once, so that a point transformed here has the same
/// bits whoever transforms it (an instance's triangle when it is shaded, the same triangle
/// flattened into the scene's own arrays).

#include <array>
#include <cmath>
#include <span>

#include "toonray/core/bbox.h"
#include "toonray/core/math.h"

namespace toonray {

/// p' = L p + t: a 3x4 matrix, row-major, m[row][3] the translation (the last row of the 4x4
/// matrix is 0 0 0 1).
struct Affine3 {
    std::array<std::array<double, 4>, 3> m{{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}};

    /// From a 4x4 matrix stored column by column (glTF's order; numpy's `M.T.ravel()`).
    /// The last row is not read: a projective matrix is the caller's to refuse
    /// (is_affine_column_major).
    static Affine3 from_column_major(std::span<const double, 16> c) {
        Affine3 a;
        for (int r = 0; r < 3; ++r)
            for (int k = 0; k < 4; ++k) a.m[r][k] = c[static_cast<std::size_t>(k * 4 + r)];
        return a;
    }
    /// From a 4x4 matrix stored row by row (numpy's `M.ravel()`, Blender's `matrix_world`
    /// rows).
    static Affine3 from_row_major(std::span<const double, 16> rows) {
        Affine3 a;
        for (int r = 0; r < 3; ++r)
            for (int k = 0; k < 4; ++k) a.m[r][k] = rows[static_cast<std::size_t>(r * 4 + k)];
        return a;
    }
    static Affine3 translation(const Vec3f& t) {
        Affine3 a;
        for (int r = 0; r < 3; ++r) a.m[r][3] = t[r];
        return a;
    }

    /// m [p; 1], each coordinate summed in double from left to right and rounded once.
    [[nodiscard]] Vec3f point(const Vec3f& p) const {
        return {static_cast<float>(m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3]),
                static_cast<float>(m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3]),
                static_cast<float>(m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3])};
    }
    /// L d (no translation).
    [[nodiscard]] Vec3f direction(const Vec3f& d) const {
        return {static_cast<float>(m[0][0] * d.x + m[0][1] * d.y + m[0][2] * d.z),
                static_cast<float>(m[1][0] * d.x + m[1][1] * d.y + m[1][2] * d.z),
                static_cast<float>(m[2][0] * d.x + m[2][1] * d.y + m[2][2] * d.z)};
    }
    /// A normal: by the cofactor matrix of L (the inverse transpose times the determinant,
    /// which also works for singular matrices and keeps the normal outward for mirrors), not
    /// normalised.
    [[nodiscard]] Vec3f normal(const Vec3f& n) const {
        double cof[3][3];
        for (int r = 0; r < 3; ++r)
            for (int k = 0; k < 3; ++k) {
                const int r1 = (r + 1) % 3, r2 = (r + 2) % 3, k1 = (k + 1) % 3, k2 = (k + 2) % 3;
                cof[r][k] = m[r1][k1] * m[r2][k2] - m[r1][k2] * m[r2][k1];
            }
        return {static_cast<float>(cof[0][0] * n.x + cof[0][1] * n.y + cof[0][2] * n.z),
                static_cast<float>(cof[1][0] * n.x + cof[1][1] * n.y + cof[1][2] * n.z),
                static_cast<float>(cof[2][0] * n.x + cof[2][1] * n.y + cof[2][2] * n.z)};
    }
    /// normal(n) scaled to unit length, or zero when it has none (as the glTF loader stores
    /// transformed normals).
    [[nodiscard]] Vec3f unit_normal(const Vec3f& n) const {
        const Vec3f t = normal(n);
        const float len = length(t);
        return len > 0 && std::isfinite(len) ? t / len : Vec3f(0.0f);
    }
    [[nodiscard]] double determinant() const {
        return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
               m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
               m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    }
    /// Whether every entry is finite and L can be inverted (|det| > 0).
    [[nodiscard]] bool invertible() const {
        for (const auto& row : m)
            for (double v : row)
                if (!std::isfinite(v)) return false;
        const double det = determinant();
        return det != 0.0 && std::isfinite(det) && std::isfinite(1.0 / det);
    }
    /// The inverse (only meaningful when invertible()).
    [[nodiscard]] Affine3 inverse() const {
        const double inv_det = 1.0 / determinant();
        Affine3 r;
        for (int i = 0; i < 3; ++i)
            for (int k = 0; k < 3; ++k) {
                // (L^-1)[i][k] = cofactor[k][i] / det.
                const int k1 = (k + 1) % 3, k2 = (k + 2) % 3, i1 = (i + 1) % 3, i2 = (i + 2) % 3;
                r.m[i][k] = (m[k1][i1] * m[k2][i2] - m[k1][i2] * m[k2][i1]) * inv_det;
            }
        for (int i = 0; i < 3; ++i)
            r.m[i][3] = -(r.m[i][0] * m[0][3] + r.m[i][1] * m[1][3] + r.m[i][2] * m[2][3]);
        return r;
    }
    friend Affine3 operator*(const Affine3& a, const Affine3& b) {
        Affine3 r;
        for (int i = 0; i < 3; ++i)
            for (int k = 0; k < 4; ++k) {
                double s = k == 3 ? a.m[i][3] : 0.0;
                for (int j = 0; j < 3; ++j) s += a.m[i][j] * b.m[j][k];
                r.m[i][k] = s;
            }
        return r;
    }
    /// The box around the transformed corners of `box` (point() of each, so that it holds the
    /// transformed points of everything inside `box`, whatever their rounding: point() is
    /// monotonic in each input within one rounding, and the corners are the extremes). Empty
    /// stays empty.
    [[nodiscard]] BBox box(const BBox& b) const {
        BBox out;
        if (b.empty()) return out;
        for (int c = 0; c < 8; ++c)
            out.extend(point(
                {(c & 1) ? b.hi.x : b.lo.x, (c & 2) ? b.hi.y : b.lo.y, (c & 4) ? b.hi.z : b.lo.z}));
        return out;
    }
    bool operator==(const Affine3&) const = default;
};

/// Whether a 4x4 matrix stored column by column is affine: its last row is exactly 0 0 0 1.
[[nodiscard]] inline bool is_affine_column_major(std::span<const double, 16> c) {
    return c[3] == 0.0 && c[7] == 0.0 && c[11] == 0.0 && c[15] == 1.0;
}

}  // namespace toonray
