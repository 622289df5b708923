#pragma once
/// Building blocks for procedural models: boxes, chamfered boxes, extrusions, surfaces of
/// revolution and mitred profile sweeps, appended to a Scene with outward winding.
///
/// Winding is never left to the caller's care: every face is given the direction it should face
/// (or, for smooth faces, its vertex normals) and is flipped when its corners run the other
/// way. Flat faces get no vertex normals (the renderer then uses the geometric normal); only
/// surfaces meant to look curved get them.

#include <array>
#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "toonray/core/math.h"
#include "toonray/scene/scene.h"

namespace toonray {

/// A rigid placement: local (x, y, z) maps to origin + x * ex + y * ey + z * ez, with ex, ey,
/// ez orthonormal and right-handed.
struct Frame {
    Vec3f origin{0.0f};
    Vec3f ex{1.0f, 0.0f, 0.0f};
    Vec3f ey{0.0f, 1.0f, 0.0f};
    Vec3f ez{0.0f, 0.0f, 1.0f};

    [[nodiscard]] Vec3f point(const Vec3f& p) const {
        return origin + ex * p.x + ey * p.y + ez * p.z;
    }
    [[nodiscard]] Vec3f direction(const Vec3f& d) const { return ex * d.x + ey * d.y + ez * d.z; }

    /// Local frame at `origin` whose +Y is `axis` (any perpendicular X); for lathes.
    static Frame along(const Vec3f& origin, const Vec3f& axis);
    /// This frame followed by a rotation of `angle` radians about the world axis `axis`
    /// through the world point `pivot`.
    [[nodiscard]] Frame rotated(const Vec3f& pivot, const Vec3f& axis, float angle) const;
    /// `local` placed inside this frame: its coordinates map to world through both.
    [[nodiscard]] Frame compose(const Frame& local) const;
    /// This frame moved by a world offset.
    [[nodiscard]] Frame translated(const Vec3f& offset) const;
};

/// Rotates `v` about the unit axis `axis` by `angle` radians (right-hand rule).
Vec3f rotate_about(const Vec3f& v, const Vec3f& axis, float angle);

/// A 2D profile point (u, v). `smooth` points share one normal between their two segments
/// (the surface is meant to be curved there); other points are creases.
struct ProfilePoint {
    float u = 0.0f;
    float v = 0.0f;
    bool smooth = false;
};

/// Appends an arc of `segments` steps from angle a0 to a1 (radians, counter-clockwise in the
/// (u, v) plane) around (cu, cv), including both ends; inner points are smooth, the end points
/// are smooth when `smooth_ends`.
void append_arc(std::vector<ProfilePoint>& out, float cu, float cv, float radius, float a0,
                float a1, int segments, bool smooth_ends = false);

/// Triangulates a simple polygon (any orientation) by ear clipping; returns index triples into
/// `poly` oriented counter-clockwise in the (u, v) plane.
std::vector<std::array<std::uint32_t, 3>> triangulate_polygon(std::span<const ProfilePoint> poly);

class MeshBuilder {
public:
    explicit MeshBuilder(Scene& scene) : scene_(scene) {}

    Scene& scene() { return scene_; }

    /// Adds a material (diffuse colour `kd`) and returns its index.
    std::uint32_t add_material(std::string name, const Vec3f& kd);
    /// Starts a new object: the geometry that follows belongs to it. Returns its index.
    std::uint32_t begin_object(std::string name);
    void set_material(std::uint32_t material) { material_ = material; }
    void set_frame(const Frame& frame) { frame_ = frame; }
    [[nodiscard]] const Frame& frame() const { return frame_; }

    /// A vertex at local position `p` (through the current frame).
    std::uint32_t vertex(const Vec3f& p);
    /// A unit normal from the local direction `n`.
    std::uint32_t normal(const Vec3f& n);

    /// Flat triangle turned to face the world direction `outward`.
    void triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c, const Vec3f& outward);
    /// Smooth triangle; its winding follows the sum of its vertex normals.
    void triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t na,
                  std::uint32_t nb, std::uint32_t nc);
    /// Flat convex polygon (fan), facing `outward` (world).
    void polygon(std::initializer_list<std::uint32_t> corners, const Vec3f& outward);
    void polygon(std::span<const std::uint32_t> corners, const Vec3f& outward);
    /// Smooth quad a-b-c-d with one normal per corner.
    void quad(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d, std::uint32_t na,
              std::uint32_t nb, std::uint32_t nc, std::uint32_t nd);

    /// Axis-aligned (in the local frame) box.
    void box(const Vec3f& lo, const Vec3f& hi);
    /// Box with all twelve edges chamfered by `c` (flat 45-degree bevels, crisp).
    void chamfer_box(const Vec3f& lo, const Vec3f& hi, float c);
    /// Convex solid given by its corner points and faces (index lists into `points`); each face
    /// is turned away from the points' centroid.
    void convex_solid(std::span<const Vec3f> points,
                      std::initializer_list<std::initializer_list<int>> faces);

    /// Prism: the closed polygon `poly` in the plane spanned by local directions `u_dir`,
    /// `v_dir`, extruded along `w_dir` from w0 to w1, with both caps. Sides at smooth points
    /// get vertex normals.
    void extrude(std::span<const ProfilePoint> poly, const Vec3f& u_dir, const Vec3f& v_dir,
                 const Vec3f& w_dir, float w0, float w1);

    /// Surface of revolution about the local +Y axis: profile points (u = radius >= 0,
    /// v = height) from bottom to top, the outside to the right of travel. Points with radius
    /// 0 close the surface there; `cap_bottom` / `cap_top` close open ends with flat discs.
    /// Rotated surfaces always get vertex normals (curved around the axis), except flat rings.
    void lathe(std::span<const ProfilePoint> profile, int segments, bool cap_bottom = true,
               bool cap_top = true);

    /// Sweeps a profile (u = offset outward from the path in its plane, v = height along `up`)
    /// along a path in the plane with normal `up`. A closed path must run counter-clockwise seen
    /// from +up (its outside is then to the right of travel); corners are mitred. The profile
    /// runs with the solid on its left (outer bottom, over the top, to the inner bottom); open
    /// paths get flat end caps when `caps`.
    void sweep(std::span<const Vec3f> path, bool closed, const Vec3f& up,
               std::span<const ProfilePoint> profile, bool caps = true);

private:
    Scene& scene_;
    Frame frame_;
    std::uint32_t material_ = 0;
    std::uint32_t object_ = 0;
};

}  // namespace toonray
