#pragma once
/// Perspective projection of world points to continuous pixel coordinates for the ink lines:
/// pixel (i, j) covers [i, i + 1) x [j, j + 1), so its centre is (i + 0.5, j + 0.5), matching the
/// ray the renderer traces through it (ViewPlane::pixel_point(i + 0.5, j + 0.5)).

#include "toonray/core/math.h"
#include "toonray/scene/camera.h"

namespace toonray::ink {

/// A point on the image: x to the right, y down, in pixels.
struct Point2 {
    float x = 0, y = 0;
    bool operator==(const Point2&) const = default;
};

class ScreenProjection {
public:
    ScreenProjection() = default;
    /// The view plane need not be orthogonal to the view direction, nor its steps to each
    /// other (the camera's up vector is used as given): points are projected onto the plane
    /// through upper_left spanned by the steps, along the line from the eye.
    ScreenProjection(const ViewPlane& view, int width, int height)
        : eye_(view.eye), upper_left_(view.upper_left), width_(width), height_(height) {
        normal_ = normalize(cross(view.step_x, view.step_y));
        if (dot(normal_, view.upper_left - view.eye) < 0.0f) normal_ = -normal_;
        plane_distance_ = dot(view.upper_left - view.eye, normal_);
        // The dual basis of the steps within the plane: r = x step_x + y step_y gives
        // x = dot(r, dual_x), y = dot(r, dual_y).
        const float xx = dot(view.step_x, view.step_x), xy = dot(view.step_x, view.step_y),
                    yy = dot(view.step_y, view.step_y);
        const float det = xx * yy - xy * xy;
        dual_x_ = (view.step_x * yy - view.step_y * xy) / det;
        dual_y_ = (view.step_y * xx - view.step_x * xy) / det;
    }

    /// Distance of `p` in front of the eye, along the image plane's normal (negative behind
    /// it). Linear along a segment in the world, its inverse linear along the segment's image.
    [[nodiscard]] float depth(const Vec3f& p) const { return dot(p - eye_, normal_); }
    /// Pixel coordinates of `p`; only meaningful for depth(p) > 0.
    [[nodiscard]] Point2 project(const Vec3f& p) const {
        const Vec3f d = p - eye_;
        const Vec3f r = eye_ + d * (plane_distance_ / dot(d, normal_)) - upper_left_;
        return {dot(r, dual_x_), dot(r, dual_y_)};
    }
    [[nodiscard]] const Vec3f& eye() const { return eye_; }
    /// The image plane's unit normal (away from the eye), the eye's distance to it, its upper
    /// left corner and the dual basis of its steps: image x = dot(r, dual_x()) and y =
    /// dot(r, dual_y()) for r = (point on the plane) - upper_left().
    [[nodiscard]] const Vec3f& normal() const { return normal_; }
    [[nodiscard]] float plane_distance() const { return plane_distance_; }
    [[nodiscard]] const Vec3f& upper_left() const { return upper_left_; }
    [[nodiscard]] const Vec3f& dual_x() const { return dual_x_; }
    [[nodiscard]] const Vec3f& dual_y() const { return dual_y_; }
    [[nodiscard]] int width() const { return width_; }
    [[nodiscard]] int height() const { return height_; }
    /// Smallest depth a projected point may have: points closer to the eye than this are
    /// clipped away (they would project to huge coordinates).
    [[nodiscard]] float near_depth() const { return plane_distance_ * 1e-3f; }

private:
    Vec3f eye_, upper_left_, normal_, dual_x_, dual_y_;
    float plane_distance_ = 1.0f;
    int width_ = 0, height_ = 0;
};

}  // namespace toonray::ink
