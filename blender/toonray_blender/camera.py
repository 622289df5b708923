"""The toonray camera block for a Blender camera.

toonray's view plane (docs/rendering.md, "The camera block") is the seed's: the horizontal field
of view is 2 atan(1 / |gaze - eye|) and the image's vertical extent is (h / w) times the
horizontal one. So a camera with Blender's horizontal field of view fov_x puts the gaze point at
distance 1 / tan(fov_x / 2) from the eye, along the view direction.

Blender's horizontal field of view depends on the lens, the sensor, the sensor fit and the
render resolution with its pixel aspect (BKE_camera_params_compute_viewplane):

- the fit is HORIZONTAL or VERTICAL as set; AUTO is horizontal when the frame is at least as wide
  as it is tall (width * pixel_aspect_x >= height * pixel_aspect_y), else vertical;
- the sensor size is sensor_height for the VERTICAL fit and sensor_width otherwise (so AUTO
  spans the longer side of the frame with sensor_width);
- fitted horizontally: tan(fov_x / 2) = sensor / (2 lens); fitted vertically
  tan(fov_y / 2) = sensor / (2 lens) and tan(fov_x / 2) = tan(fov_y / 2) * aspect, where
  aspect = (width * pixel_aspect_x) / (height * pixel_aspect_y), the frame's displayed aspect.

Coordinates follow the OBJ exporter's axis conversion, forward -Z and up Y:
Blender (x, y, z) -> OBJ (x, z, -y), a proper rotation, so right = view x up survives it.
"""

import math

CAMERA_START = "# Camera start"
CAMERA_END = "# Camera end"


class CameraError(Exception):
    pass


def blender_to_obj(v):
    """Blender Z-up -> OBJ Y-up with forward -Z (the exporter's NEGATIVE_Z / Y)."""
    x, y, z = v
    return (x, z, -y)


def frame_aspect(res_x, res_y, pixel_aspect_x=1.0, pixel_aspect_y=1.0):
    """Displayed width / height of the rendered frame."""
    return (res_x * pixel_aspect_x) / (res_y * pixel_aspect_y)


def effective_fit(sensor_fit, res_x, res_y, pixel_aspect_x=1.0, pixel_aspect_y=1.0):
    """'HORIZONTAL' or 'VERTICAL': which side the sensor spans."""
    if sensor_fit == "AUTO":
        return "HORIZONTAL" if res_x * pixel_aspect_x >= res_y * pixel_aspect_y else "VERTICAL"
    if sensor_fit not in ("HORIZONTAL", "VERTICAL"):
        raise CameraError("unknown sensor fit %r" % (sensor_fit,))
    return sensor_fit


def tan_half_fov_x(lens, sensor_width, sensor_height, sensor_fit, res_x, res_y,
                   pixel_aspect_x=1.0, pixel_aspect_y=1.0):
    """tan(fov_x / 2) of a perspective camera (lens and sensor in millimetres)."""
    if not (lens > 0):
        raise CameraError("the camera's focal length must be positive (got %r)" % (lens,))
    fit = effective_fit(sensor_fit, res_x, res_y, pixel_aspect_x, pixel_aspect_y)
    sensor = sensor_height if sensor_fit == "VERTICAL" else sensor_width
    if not (sensor > 0):
        raise CameraError("the camera's sensor size must be positive (got %r)" % (sensor,))
    t = sensor / (2.0 * lens)
    if fit == "VERTICAL":
        t *= frame_aspect(res_x, res_y, pixel_aspect_x, pixel_aspect_y)
    return t


def square_pixel_size(res_x, res_y, pixel_aspect_x=1.0, pixel_aspect_y=1.0):
    """The toonray --size (square pixels) that shows Blender's whole frame: the width kept,
    the height scaled by pixel_aspect_y / pixel_aspect_x."""
    if pixel_aspect_x == pixel_aspect_y:
        return res_x, res_y
    return res_x, max(1, int(round(res_y * pixel_aspect_y / pixel_aspect_x)))


def camera_block_vectors(matrix_world, tan_half_fov, scale=1.0):
    """(eye, gaze, up) in OBJ coordinates for a camera with this world matrix (4x4, rows
    indexable as m[row][col]) and tan(fov_x / 2). The camera looks down its local -Z with local
    +Y up; scale and shear in the matrix are removed (Gram-Schmidt)."""
    eye = [matrix_world[i][3] * scale for i in range(3)]
    fwd = [-matrix_world[i][2] for i in range(3)]
    up = [matrix_world[i][1] for i in range(3)]
    fwd = _normalized(fwd, "the camera's view direction")
    d = sum(u * f for u, f in zip(up, fwd))
    up = _normalized([u - d * f for u, f in zip(up, fwd)], "the camera's up vector")
    if not (tan_half_fov > 0 and math.isfinite(tan_half_fov)):
        raise CameraError("bad field of view (tan(fov_x / 2) = %r)" % (tan_half_fov,))
    dist = 1.0 / tan_half_fov
    gaze = [e + dist * f for e, f in zip(eye, fwd)]
    return blender_to_obj(eye), blender_to_obj(gaze), blender_to_obj(up)


def _normalized(v, what):
    n = math.sqrt(sum(c * c for c in v))
    if not (n > 1e-12) or not math.isfinite(n):
        raise CameraError("%s is degenerate (the camera's matrix has zero scale?)" % what)
    return [c / n for c in v]


def _num(x):
    text = "%.9g" % x
    return "0" if text in ("-0", "0") else text


def camera_block_text(eye, gaze, up, comment=None):
    """The block appended to an OBJ file: eye and gaze as v, up as vn, c -2 -1 -1 (relative
    indices, so appending never shifts the file's own indices)."""
    lines = []
    if comment:
        for line in comment.splitlines():
            lines.append("# " + line)
    lines.append(CAMERA_START)
    lines.append("v %s %s %s" % tuple(_num(c) for c in eye))
    lines.append("v %s %s %s" % tuple(_num(c) for c in gaze))
    lines.append("vn %s %s %s" % tuple(_num(c) for c in up))
    lines.append("c -2 -1 -1")
    lines.append(CAMERA_END)
    return "\n".join(lines) + "\n"


def toonray_pixel(eye, gaze, up, point, width, height):
    """Where toonray's view plane puts an OBJ-space point: (x, y) in pixels, y = 0 at the top,
    pixel (i, j) covering [i, i+1) x [j, j+1). For tests and debugging."""
    view = [g - e for g, e in zip(gaze, eye)]
    right = _normalized(_cross(view, up), "right")
    up_vec = [c * height / width for c in up]
    rel = [p - e for p, e in zip(point, eye)]
    # Solve rel = s * (view + a * right + b * up_vec): project on the orthogonal frame.
    dist = math.sqrt(sum(c * c for c in view))
    fwd = [c / dist for c in view]
    zf = sum(r * f for r, f in zip(rel, fwd))
    if zf <= 0:
        return None
    xr = sum(r * c for r, c in zip(rel, right)) / zf * dist  # in units where right has length 1
    yu = sum(r * c for r, c in zip(rel, up)) / zf * dist
    x = (xr + 1.0) * 0.5 * width
    y = (1.0 - yu / (height / width)) * 0.5 * height
    return x, y


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
