#pragma once
/// The seed's camera: an eye, a gaze point and an up vector, and the view plane built from them.

#include <span>
#include <string>

#include "toonray/core/bbox.h"
#include "toonray/core/math.h"

namespace toonray {

/// Camera as written in the OBJ camera block (`c eye gaze up`) or given with --camera.
/// The distance from eye to gaze sets the field of view: horizontal fov = 2 atan(1 / |gaze - eye|).
struct CameraSpec {
    Vec3f eye;
    Vec3f gaze;
    Vec3f up;
};

/// The image plane in world space: pixel (x, y), y = 0 at the top, is sampled at
/// `upper_left + (x + 0.5) * step_x + (y + 0.5) * step_y`.
struct ViewPlane {
    Vec3f eye;
    Vec3f upper_left;
    Vec3f step_x;   ///< (UR - UL) / width
    Vec3f step_y;   ///< (LL - UL) / height
    Vec3f right;    ///< unit vector to the right of the view
    Vec3f up;       ///< unit vector up in the image (orthogonal to right and the view direction)
    Vec3f forward;  ///< unit view direction (gaze - eye)

    [[nodiscard]] Vec3f pixel_point(float x, float y) const {
        return upper_left + step_x * x + step_y * y;
    }
};

/// Largest |gaze - eye| and |up| a camera may have.
inline constexpr double kMaxCameraLength = 1e6;
/// Smallest sine of the angle between up and the view direction (about 0.06 degrees).
inline constexpr double kMinUpSine = 1e-3;

/// Throws Error("invalid camera: ...") unless eye, gaze and up are finite, eye != gaze,
/// |gaze - eye| and |up| are at most kMaxCameraLength, up is not zero, and the sine of its angle
/// to the view direction exceeds kMinUpSine (checked in double precision, and again in float
/// where tiny lengths underflow). Every camera that passes gives make_view_plane finite vectors.
void validate_camera(const CameraSpec& camera);

/// Builds the view plane exactly as the seed defines it:
/// viewDir = gaze - eye; center = eye + viewDir; ratio = h / w; right = normalize(viewDir x up);
/// upVec = ratio * up; UL = center + upVec - right, UR = center + upVec + right,
/// LL = center - right - upVec. (As in the seed, `up` is used as given: it should be a unit
/// vector orthogonal to the view direction, which is what exporters write.)
/// Throws validate_camera's Error for an invalid camera.
ViewPlane make_view_plane(const CameraSpec& camera, int width, int height);

/// A camera that frames the points: looks at the centre of their bounds from the front-right
/// and a little above, with 60 degrees of horizontal field of view, as close as it can while
/// every point stays inside the image with a 5% margin. No points: frames the unit cube.
CameraSpec auto_camera(std::span<const Vec3f> points, int width, int height);

/// Parses "ex,ey,ez,gx,gy,gz,ux,uy,uz". Throws Error("camera 'TEXT': ...") when malformed.
CameraSpec parse_camera_spec(const std::string& text);

}  // namespace toonray
