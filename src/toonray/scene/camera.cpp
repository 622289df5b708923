#include "toonray/scene/camera.h"

#include <charconv>
#include <cmath>
#include <fmt/format.h>
#include <numbers>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/core/portable_math.h"

namespace toonray {

void validate_camera(const CameraSpec& camera) {
    if (!is_finite(camera.eye) || !is_finite(camera.gaze) || !is_finite(camera.up))
        throw Error("invalid camera: eye, gaze and up must be finite");
    if (!(std::abs(camera.shift.x) <= kMaxCameraShift) ||
        !(std::abs(camera.shift.y) <= kMaxCameraShift))
        throw Error(
            fmt::format("invalid camera: lens shift {:g},{:g} (finite, at most {:g} "
                        "image widths)",
                        camera.shift.x, camera.shift.y, kMaxCameraShift));
    // In double precision, so that large values cannot overflow into a camera that passes here
    // and yields NaN rays in make_view_plane's float arithmetic.
    const double vx = double{camera.gaze.x} - camera.eye.x,
                 vy = double{camera.gaze.y} - camera.eye.y,
                 vz = double{camera.gaze.z} - camera.eye.z;
    const double ux = camera.up.x, uy = camera.up.y, uz = camera.up.z;
    const double view = std::sqrt(vx * vx + vy * vy + vz * vz);
    const double up = std::sqrt(ux * ux + uy * uy + uz * uz);
    if (!(view > 0)) throw Error("invalid camera: eye and gaze point are the same point");
    // |gaze - eye| sets the field of view (2 atan(1 / |gaze - eye|)) and up is a direction:
    // beyond 1e6 neither means anything, and the float arithmetic overflows.
    if (view > kMaxCameraLength)
        throw Error(
            fmt::format("invalid camera: the gaze point is {:g} from the eye (at most 1e6; the "
                        "distance sets the field of view, 1 gives 90 degrees)",
                        view));
    if (up > kMaxCameraLength)
        throw Error(fmt::format("invalid camera: up vector of length {:g} (at most 1e6)", up));
    // The sine of the angle between up and the view direction; below ~0.06 degrees the view's
    // right vector is unusable.
    const double cx = vy * uz - vz * uy, cy = vz * ux - vx * uz, cz = vx * uy - vy * ux;
    const double sine = std::sqrt(cx * cx + cy * cy + cz * cz) / (view * up);
    if (!(up > 0) || !(sine > kMinUpSine))
        throw Error("invalid camera: up vector is zero or parallel to the view direction");
    // The same in the float arithmetic that builds the view plane, where tiny lengths underflow
    // to zero.
    const Vec3f view_dir = camera.gaze - camera.eye;
    const float view_len = length(view_dir), up_len = length(camera.up);
    if (!(view_len > 0)) throw Error("invalid camera: eye and gaze point are the same point");
    if (!(up_len > 0) ||
        !(length(cross(view_dir, camera.up)) > static_cast<float>(kMinUpSine) * view_len * up_len))
        throw Error("invalid camera: up vector is zero or parallel to the view direction");
}

ViewPlane make_view_plane(const CameraSpec& camera, int width, int height) {
    validate_camera(camera);
    Vec3f view_dir = camera.gaze - camera.eye;
    float view_len = length(view_dir);
    Vec3f side = cross(view_dir, camera.up);

    const float ratio = static_cast<float>(height) / static_cast<float>(width);
    Vec3f center = camera.eye + view_dir;
    Vec3f right = normalize(side);
    // Only a shifted camera moves the centre, so that unshifted views keep the seed's exact
    // arithmetic.
    if (camera.shift.x != 0.0f || camera.shift.y != 0.0f)
        center = center + right * (2.0f * camera.shift.x) + camera.up * (2.0f * camera.shift.y);
    Vec3f up_vec = camera.up * ratio;
    Vec3f ul = center + up_vec - right;
    Vec3f ur = center + up_vec + right;
    Vec3f ll = center - right - up_vec;

    ViewPlane plane;
    plane.eye = camera.eye;
    plane.upper_left = ul;
    plane.step_x = (ur - ul) / static_cast<float>(width);
    plane.step_y = (ll - ul) / static_cast<float>(height);
    plane.right = right;
    plane.up = normalize(cross(right, view_dir));
    plane.forward = view_dir / view_len;
    return plane;
}

CameraSpec auto_camera(std::span<const Vec3f> points, int width, int height) {
    BBox box;
    for (const Vec3f& p : points) box.extend(p);
    const Vec3f unit_cube[2] = {Vec3f(-1.0f), Vec3f(1.0f)};
    if (box.empty()) {
        box = BBox{unit_cube[0], unit_cube[1]};
        points = unit_cube;
    }
    Vec3f center = box.center();
    // Look at the centre from the front-right, slightly above, 60 degrees horizontal field of
    // view (|viewDir| = 1 / tan(30 deg)).
    const float view_len = 1.0f / portable::tan(30.0f * 3.14159265f / 180.0f);
    const float tan_x = 1.0f / view_len;
    const float tan_y = tan_x * static_cast<float>(height) / static_cast<float>(width);
    Vec3f dir = normalize(Vec3f(0.55f, 0.45f, 1.0f));  // from the centre towards the eye
    Vec3f forward = -dir;
    Vec3f right = normalize(cross(forward, Vec3f(0.0f, 1.0f, 0.0f)));
    Vec3f up = cross(right, forward);
    // Nearest distance at which every point projects inside the image, with a 5% margin on
    // each side: a point at offset o needs depth >= |o.right| / tan_x (and likewise
    // vertically), and its depth is distance - o.dir.
    float distance = 0.0f;
    const float margin = 0.9f;
    for (const Vec3f& p : points) {
        Vec3f o = p - center;
        float need = std::max(std::abs(dot(o, right)) / (tan_x * margin),
                              std::abs(dot(o, up)) / (tan_y * margin)) +
                     dot(o, dir);
        distance = std::max(distance, need);
    }
    float radius = 0.5f * length(box.extent());
    distance = std::max(distance, radius * 1.01f);  // keep the eye outside the box
    if (!(distance > 0.0f)) distance = 1.0f;
    CameraSpec cam;
    cam.eye = center + dir * distance;
    cam.gaze = cam.eye + forward * view_len;
    cam.up = up;
    return cam;
}

CameraSpec lens_camera(const LensCamera& lens, int width, int height) {
    if (width <= 0 || height <= 0)
        throw Error(fmt::format("invalid camera: image size {}x{}", width, height));
    if (!(lens.pixel_aspect > 0.0f) || !std::isfinite(lens.pixel_aspect))
        throw Error(
            fmt::format("invalid camera: pixel aspect {:g} (must be positive)", lens.pixel_aspect));
    if (!is_finite(lens.eye) || !is_finite(lens.target) || !is_finite(lens.up))
        throw Error("invalid camera: eye, target and up must be finite");
    // In double precision: the displayed frame is width x (height * pixel_aspect).
    const double displayed_w = static_cast<double>(width),
                 displayed_h = static_cast<double>(height) * lens.pixel_aspect;
    const double aspect = displayed_w / displayed_h;
    double tan_x = 0.0;
    bool fitted_horizontally = true;
    if (lens.vertical_fov) {
        const double fov = *lens.vertical_fov;
        if (!(fov > 0.0 && fov < 180.0))
            throw Error(fmt::format(
                "invalid camera: vertical field of view {:g} degrees (must be in (0, 180))", fov));
        tan_x = std::tan(fov * std::numbers::pi / 360.0) * aspect;
        fitted_horizontally = aspect >= 1.0;
    } else {
        if (!(lens.focal_length > 0.0f) || !std::isfinite(lens.focal_length))
            throw Error(fmt::format("invalid camera: focal length {:g} mm (must be positive)",
                                    lens.focal_length));
        const float sensor =
            lens.fit == SensorFit::Vertical ? lens.sensor_height : lens.sensor_width;
        if (!(sensor > 0.0f) || !std::isfinite(sensor))
            throw Error(
                fmt::format("invalid camera: sensor size {:g} mm (must be positive)", sensor));
        fitted_horizontally = lens.fit == SensorFit::Horizontal ||
                              (lens.fit == SensorFit::Auto && displayed_w >= displayed_h);
        tan_x = double{sensor} / (2.0 * lens.focal_length);
        if (!fitted_horizontally) tan_x *= aspect;
    }
    if (!(tan_x > 0.0) || !std::isfinite(tan_x))
        throw Error("invalid camera: the field of view is not finite");
    const Vec3f view = lens.target - lens.eye;
    const float view_len = length(view);
    if (!(view_len > 0.0f) || !std::isfinite(view_len))
        throw Error("invalid camera: eye and target are the same point");
    const Vec3f forward = view / view_len;
    const Vec3f up = lens.up - forward * dot(lens.up, forward);
    const float up_len = length(up);
    if (!(up_len > static_cast<float>(kMinUpSine) * length(lens.up)) || !std::isfinite(up_len))
        throw Error("invalid camera: up vector is zero or parallel to the view direction");
    CameraSpec camera;
    camera.eye = lens.eye;
    camera.gaze = lens.eye + forward * static_cast<float>(1.0 / tan_x);
    // |up| = pixel aspect: the plane's height is then (height / width) * pixel aspect of its
    // width, the displayed frame's.
    camera.up = up * (lens.pixel_aspect / up_len);
    // The shift is in units of the fitted side; the spec's in units of the displayed width,
    // its vertical part along `up` as given (of length pixel_aspect).
    const double side = fitted_horizontally ? 1.0 : 1.0 / aspect;
    camera.shift = {static_cast<float>(lens.shift.x * side),
                    static_cast<float>(lens.shift.y * side / lens.pixel_aspect)};
    validate_camera(camera);
    return camera;
}

CameraSpec parse_camera_spec(const std::string& text) {
    std::vector<float> values;
    const char* p = text.data();
    const char* end = p + text.size();
    while (p < end) {
        float v;
        auto [next, ec] = std::from_chars(p, end, v);
        if (ec != std::errc() || !std::isfinite(v))
            throw Error(fmt::format("camera '{}': malformed number", text));
        values.push_back(v);
        p = next;
        if (p < end) {
            if (*p != ',')
                throw Error(fmt::format("camera '{}': expected ',' between numbers", text));
            ++p;
        }
    }
    if (values.size() != 9)
        throw Error(
            fmt::format("camera '{}': expected 9 numbers ex,ey,ez,gx,gy,gz,ux,uy,uz, got {}", text,
                        values.size()));
    return {{values[0], values[1], values[2]},
            {values[3], values[4], values[5]},
            {values[6], values[7], values[8]}};
}

}  // namespace toonray
