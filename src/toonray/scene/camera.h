#pragma once
/// The seed's camera: an eye, a gaze point and an up vector, and the view plane built from them.

#include <optional>
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
    /// Lens shift (an off-axis view, as Blender's shift): the view plane's centre moves by
    /// shift.x times the plane's width along its right vector and shift.y times the width
    /// along `up`. The OBJ camera block and --camera have none.
    Vec2f shift{0.0f, 0.0f};
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

/// Largest lens shift a camera may have, in image widths.
inline constexpr double kMaxCameraShift = 100.0;

/// Builds the view plane exactly as the seed defines it:
/// viewDir = gaze - eye; center = eye + viewDir; ratio = h / w; right = normalize(viewDir x up);
/// upVec = ratio * up; UL = center + upVec - right, UR = center + upVec + right,
/// LL = center - right - upVec. (As in the seed, `up` is used as given: it should be a unit
/// vector orthogonal to the view direction, which is what exporters write.) A lens shift then
/// moves the plane within itself: center += 2 shift.x right + 2 shift.y up.
/// Throws validate_camera's Error for an invalid camera.
ViewPlane make_view_plane(const CameraSpec& camera, int width, int height);

/// A camera that frames the points: looks at the centre of their bounds from the front-right
/// and a little above, with 60 degrees of horizontal field of view, as close as it can while
/// every point stays inside the image with a 5% margin. No points: frames the unit cube.
CameraSpec auto_camera(std::span<const Vec3f> points, int width, int height);

/// How a lens camera's sensor spans the image (Blender's sensor fit).
enum class SensorFit {
    Auto,        ///< the sensor width spans the longer side of the frame
    Horizontal,  ///< the sensor width spans the frame's width
    Vertical,    ///< the sensor height spans the frame's height
};

/// A camera as photographers and Blender give it: where it is, what it looks at, and either
/// its vertical field of view or a lens and sensor. It becomes a CameraSpec for one image size
/// (lens_camera), since the seed's camera fixes the horizontal field of view.
struct LensCamera {
    Vec3f eye;
    Vec3f target;       ///< a point the camera looks at
    Vec3f up{0, 1, 0};  ///< need not be orthogonal to the view direction; not parallel to it
    /// Vertical field of view in degrees, in (0, 180); when set, the lens and sensor are not
    /// used.
    std::optional<float> vertical_fov;
    float focal_length = 50.0f;                         ///< millimetres
    float sensor_width = 36.0f, sensor_height = 24.0f;  ///< millimetres
    SensorFit fit = SensorFit::Auto;
    /// Lens shift in units of the fitted side of the frame (Blender's shift_x, shift_y).
    Vec2f shift{0.0f, 0.0f};
    /// The height of a pixel over its width (Blender's pixel_aspect_y / pixel_aspect_x): the
    /// frame shows width x (height * pixel_aspect) of the scene's square units.
    float pixel_aspect = 1.0f;
};

/// The CameraSpec of `lens` for a `width` x `height` image, with Blender's field-of-view rule
/// (BKE_camera_params_compute_viewplane): the fitted side (AUTO: the longer displayed side)
/// spans the sensor size at the focal length, or the vertical field of view spans the height.
/// Throws Error("invalid camera: ...") for a camera it cannot make (non-positive or
/// non-finite lens, sensor or field of view, up parallel to the view) and validate_camera's.
[[nodiscard]] CameraSpec lens_camera(const LensCamera& lens, int width, int height);

/// Parses "ex,ey,ez,gx,gy,gz,ux,uy,uz". Throws Error("camera 'TEXT': ...") when malformed.
CameraSpec parse_camera_spec(const std::string& text);

}  // namespace toonray
