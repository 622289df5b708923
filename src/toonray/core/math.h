#pragma once
/// Small fixed-size vector types. Float geometry throughout: the renderer never needs double.

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace toonray {

struct Vec2f {
    float x = 0, y = 0;
};

struct Vec3f {
    float x = 0, y = 0, z = 0;

    constexpr Vec3f() = default;
    constexpr Vec3f(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}
    constexpr explicit Vec3f(float s) : x(s), y(s), z(s) {}

    constexpr float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    constexpr float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
    constexpr Vec3f operator-() const { return {-x, -y, -z}; }
    constexpr Vec3f& operator+=(const Vec3f& o) {
        x += o.x;
        y += o.y;
        z += o.z;
        return *this;
    }
    constexpr Vec3f& operator-=(const Vec3f& o) {
        x -= o.x;
        y -= o.y;
        z -= o.z;
        return *this;
    }
    constexpr Vec3f& operator*=(float s) {
        x *= s;
        y *= s;
        z *= s;
        return *this;
    }
    constexpr bool operator==(const Vec3f&) const = default;
};

constexpr Vec3f operator+(Vec3f a, const Vec3f& b) { return a += b; }
constexpr Vec3f operator-(Vec3f a, const Vec3f& b) { return a -= b; }
constexpr Vec3f operator*(Vec3f a, float s) { return a *= s; }
constexpr Vec3f operator*(float s, Vec3f a) { return a *= s; }
constexpr Vec3f operator*(const Vec3f& a, const Vec3f& b) {
    return {a.x * b.x, a.y * b.y, a.z * b.z};
}
constexpr Vec3f operator/(const Vec3f& a, float s) { return {a.x / s, a.y / s, a.z / s}; }

constexpr float dot(const Vec3f& a, const Vec3f& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr Vec3f cross(const Vec3f& a, const Vec3f& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float length(const Vec3f& a) { return std::sqrt(dot(a, a)); }
inline Vec3f normalize(const Vec3f& a) { return a / length(a); }
constexpr Vec3f min(const Vec3f& a, const Vec3f& b) {
    return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
constexpr Vec3f max(const Vec3f& a, const Vec3f& b) {
    return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
inline bool is_finite(const Vec3f& a) {
    return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}

/// The unit geometric normal of triangle p0 p1 p2, (p1 - p0) x (p2 - p0) normalised, or zero
/// for a degenerate triangle (a zero, infinite or NaN cross product). Always inlined: as a call
/// it made the ink's per-triangle pass keep its sums in memory.
[[gnu::always_inline]] inline Vec3f unit_face_normal(const Vec3f& p0, const Vec3f& p1,
                                                     const Vec3f& p2) {
    const Vec3f n = cross(p1 - p0, p2 - p0);
    const float len = length(n);
    if (!(len > 0.0f) || !std::isfinite(len)) return Vec3f(0.0f);
    return n / len;
}

}  // namespace toonray
