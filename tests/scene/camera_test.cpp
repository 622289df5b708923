#include "toonray/scene/camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "toonray/core/error.h"

using namespace toonray;

namespace {
void expect_near(const Vec3f& a, const Vec3f& b, float eps = 1e-5f) {
    EXPECT_NEAR(a.x, b.x, eps);
    EXPECT_NEAR(a.y, b.y, eps);
    EXPECT_NEAR(a.z, b.z, eps);
}
}  // namespace

TEST(ViewPlane, FollowsTheSeedsCornerFormulas) {
    // Looking down -Z from z = 2 with the gaze point one unit away: the plane is z = 1.
    CameraSpec cam{{0, 0, 2}, {0, 0, 1}, {0, 1, 0}};
    const int w = 200, h = 100;
    ViewPlane v = make_view_plane(cam, w, h);
    // right = normalize(viewDir x up) = (1,0,0); upVec = 0.5 * up; UL = center + upVec - right.
    expect_near(v.upper_left, {-1.0f, 0.5f, 1.0f});
    expect_near(v.pixel_point(w, 0), {1.0f, 0.5f, 1.0f});    // UR
    expect_near(v.pixel_point(0, h), {-1.0f, -0.5f, 1.0f});  // LL
    expect_near(v.pixel_point(w, h), {1.0f, -0.5f, 1.0f});   // LR
    // Pixel centres: (x + 0.5) / w across.
    expect_near(v.pixel_point(0.5f, 0.5f), {-1.0f + 1.0f / w, 0.5f - 0.5f / h, 1.0f});
}

TEST(ViewPlane, HorizontalFovIsTwoAtanOfInverseDistance) {
    for (float d : {0.5f, 1.0f, 2.0f}) {
        CameraSpec cam{{0, 0, 0}, {0, 0, -d}, {0, 1, 0}};
        ViewPlane v = make_view_plane(cam, 64, 64);
        Vec3f left = normalize(v.pixel_point(0, 32) - cam.eye);
        Vec3f right = normalize(v.pixel_point(64, 32) - cam.eye);
        float fov = std::acos(dot(left, right));
        EXPECT_NEAR(fov, 2 * std::atan(1 / d), 1e-5f);
    }
}

TEST(ViewPlane, InvalidCamerasAreErrors) {
    EXPECT_THROW(make_view_plane({{1, 2, 3}, {1, 2, 3}, {0, 1, 0}}, 10, 10), Error);
    EXPECT_THROW(make_view_plane({{0, 0, 0}, {0, 0, -1}, {0, 0, 1}}, 10, 10), Error);
    EXPECT_THROW(make_view_plane({{0, 0, 0}, {0, 0, -1}, {0, 0, 0}}, 10, 10), Error);
    EXPECT_THROW(make_view_plane({{0, 0, NAN}, {0, 0, -1}, {0, 1, 0}}, 10, 10), Error);
}

TEST(AutoCamera, EveryPointProjectsInsideTheImage) {
    std::vector<Vec3f> points;
    for (int i = 0; i < 200; ++i)
        points.push_back(
            {std::sin(i * 0.7f) * 3.0f, std::cos(i * 1.3f) * 0.5f + 10.0f, (i % 17) * 0.2f});
    for (auto [w, h] : {std::pair{1280, 720}, std::pair{400, 800}}) {
        CameraSpec cam = auto_camera(points, w, h);
        ViewPlane v = make_view_plane(cam, w, h);
        Vec3f fwd = normalize(cam.gaze - cam.eye);
        float view_len = length(cam.gaze - cam.eye);
        float half_w = 1.0f, half_h = static_cast<float>(h) / w;
        float max_u = 0, max_v = 0;
        for (const Vec3f& p : points) {
            Vec3f o = p - cam.eye;
            float depth = dot(o, fwd);
            ASSERT_GT(depth, 0.0f);
            float u = std::abs(dot(o, v.right)) / depth * view_len / half_w;
            float vv = std::abs(dot(o, v.up)) / depth * view_len / half_h;
            max_u = std::max(max_u, u);
            max_v = std::max(max_v, vv);
        }
        EXPECT_LE(max_u, 0.9001f);
        EXPECT_LE(max_v, 0.9001f);
        // Tight: the limiting direction reaches the 5% margin.
        EXPECT_GT(std::max(max_u, max_v), 0.89f);
    }
}

TEST(ParseCameraSpec, NineNumbers) {
    CameraSpec c = parse_camera_spec("1,2,3,4,5,6,0,1,0");
    EXPECT_EQ(c.eye, Vec3f(1, 2, 3));
    EXPECT_EQ(c.gaze, Vec3f(4, 5, 6));
    EXPECT_EQ(c.up, Vec3f(0, 1, 0));
    EXPECT_THROW(parse_camera_spec("1,2,3"), Error);
    EXPECT_THROW(parse_camera_spec("1,2,3,4,5,6,0,1,x"), Error);
}

namespace {
std::string camera_error(const CameraSpec& c) {
    try {
        validate_camera(c);
    } catch (const Error& e) {
        return e.what();
    }
    return "(valid)";
}
}  // namespace

TEST(ValidateCamera, NamesWhatIsWrong) {
    EXPECT_EQ(camera_error({{0, 0, 0}, {0, 0, -1}, {0, 1, 0}}), "(valid)");
    EXPECT_EQ(camera_error({{0, 0, NAN}, {0, 0, -1}, {0, 1, 0}}),
              "invalid camera: eye, gaze and up must be finite");
    EXPECT_EQ(camera_error({{1, 2, 3}, {1, 2, 3}, {0, 1, 0}}),
              "invalid camera: eye and gaze point are the same point");
    EXPECT_EQ(camera_error({{0, 0, 0}, {0, 0, -1}, {0, 0, 0}}),
              "invalid camera: up vector is zero or parallel to the view direction");
    EXPECT_EQ(camera_error({{0, 0, 0}, {0, 0, -1}, {0, 0, 1}}),
              "invalid camera: up vector is zero or parallel to the view direction");
    EXPECT_EQ(
        camera_error({{0, 0, 0}, {0, 0, -3e7f}, {0, 1, 0}}),
        "invalid camera: the gaze point is 3e+07 from the eye (at most 1e6; the distance sets the field of "
        "view, 1 gives 90 degrees)");
    EXPECT_EQ(camera_error({{0, 0, 0}, {0, 0, -1}, {0, 2e6f, 0}}),
              "invalid camera: up vector of length 2e+06 (at most 1e6)");
    // Up 0.05 degrees from the view direction is too close; 0.1 degrees is enough.
    const float a = 0.05f * 3.14159265f / 180.0f, b = 0.1f * 3.14159265f / 180.0f;
    EXPECT_NE(camera_error({{0, 0, 0}, {0, 0, -1}, {0, std::sin(a), -std::cos(a)}}), "(valid)");
    EXPECT_EQ(camera_error({{0, 0, 0}, {0, 0, -1}, {0, std::sin(b), -std::cos(b)}}), "(valid)");
}

TEST(ValidateCamera, IsWhatMakeViewPlaneChecks) {
    // Huge values that pass validation give finite view planes; what it refuses, make_view_plane
    // refuses with the same message.
    const CameraSpec cameras[] = {{{1e30f, 0, 0}, {1e30f, 0, -1e6f}, {0, 1e6f, 0}},
                                  {{0, 0, 0}, {0, 0, -1e-3f}, {0, 1e-30f, 0}},
                                  {{0, 0, 0}, {0, 0, -3e7f}, {0, 1, 0}},
                                  {{5, 5, 5}, {5, 5, 5}, {0, 1, 0}}};
    for (const CameraSpec& c : cameras) {
        const std::string expected = camera_error(c);
        std::string got = "(valid)";
        try {
            const ViewPlane v = make_view_plane(c, 64, 48);
            EXPECT_TRUE(is_finite(v.upper_left) && is_finite(v.step_x) && is_finite(v.step_y));
            EXPECT_TRUE(is_finite(v.right) && is_finite(v.up) && is_finite(v.forward));
        } catch (const Error& e) {
            got = e.what();
        }
        EXPECT_EQ(got, expected);
    }
}

TEST(ParseCameraSpec, MessagesQuoteTheText) {
    auto error_of = [](const std::string& text) {
        try {
            (void)parse_camera_spec(text);
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("(no error)");
    };
    EXPECT_EQ(error_of("1,2,3"),
              "camera '1,2,3': expected 9 numbers ex,ey,ez,gx,gy,gz,ux,uy,uz, got 3");
    EXPECT_EQ(error_of("1,2,x"), "camera '1,2,x': malformed number");
    EXPECT_EQ(error_of("1;2"), "camera '1;2': expected ',' between numbers");
}

TEST(ViewPlane, LensShiftMovesThePlaneWithinItself) {
    const CameraSpec straight{{0, 0, 2}, {0, 0, 1}, {0, 1, 0}};
    CameraSpec shifted = straight;
    shifted.shift = {0.25f, -0.1f};
    const ViewPlane a = make_view_plane(straight, 200, 100), b = make_view_plane(shifted, 200, 100);
    // A quarter of the width (2) right and a tenth of it down; the same plane and directions.
    expect_near(b.upper_left, a.upper_left + Vec3f(0.5f, -0.2f, 0.0f));
    expect_near(b.step_x, a.step_x);
    expect_near(b.step_y, a.step_y);
    expect_near(b.forward, a.forward);
    expect_near(b.right, a.right);
    expect_near(b.up, a.up);
    EXPECT_EQ(camera_error({{0, 0, 0}, {0, 0, -1}, {0, 1, 0}, {NAN, 0}}),
              "invalid camera: lens shift nan,0 (finite, at most 100 image widths)");
    EXPECT_EQ(camera_error({{0, 0, 0}, {0, 0, -1}, {0, 1, 0}, {0, 101}}),
              "invalid camera: lens shift 0,101 (finite, at most 100 image widths)");
}

TEST(LensCamera, BlendersFieldOfViewRule) {
    LensCamera lens;
    lens.eye = {1, 2, 3};
    lens.target = {1, 2, -7};  // looking down -Z from 10 units away
    lens.up = {0, 1, 0.5f};    // not orthogonal to the view: straightened
    lens.focal_length = 50;
    lens.sensor_width = 36;
    lens.sensor_height = 24;
    auto distance = [](const CameraSpec& c) { return length(c.gaze - c.eye); };
    // AUTO, landscape: the sensor width spans the width, tan(fov_x / 2) = 36 / 100.
    CameraSpec c = lens_camera(lens, 1920, 1080);
    EXPECT_NEAR(distance(c), 100.0f / 36.0f, 1e-5f);
    expect_near(c.eye, lens.eye);
    expect_near(c.up, {0, 1, 0});
    expect_near((c.gaze - c.eye) / distance(c), {0, 0, -1});
    // AUTO, portrait: the sensor width spans the height.
    c = lens_camera(lens, 1080, 1920);
    EXPECT_NEAR(distance(c), 1.0f / (0.36f * 1080.0f / 1920.0f), 1e-4f);
    // VERTICAL: the sensor height spans the height.
    lens.fit = SensorFit::Vertical;
    c = lens_camera(lens, 1920, 1080);
    EXPECT_NEAR(distance(c), 1.0f / (0.24f * 1920.0f / 1080.0f), 1e-4f);
    // HORIZONTAL on a portrait frame: still the width.
    lens.fit = SensorFit::Horizontal;
    c = lens_camera(lens, 1080, 1920);
    EXPECT_NEAR(distance(c), 100.0f / 36.0f, 1e-5f);
    // A vertical field of view of 60 degrees: tan(fov_x / 2) = tan(30) * 16 / 9.
    lens.vertical_fov = 60.0f;
    c = lens_camera(lens, 1920, 1080);
    EXPECT_NEAR(distance(c), 1.0f / (std::tan(3.14159265f / 6) * 16.0f / 9.0f), 1e-5f);
    // The rendered plane spans the field of view: its top edge is 30 degrees up.
    const ViewPlane v = make_view_plane(c, 1920, 1080);
    const Vec3f top = normalize(v.pixel_point(960, 0) - c.eye);
    EXPECT_NEAR(std::acos(dot(top, v.forward)) * 180.0f / 3.14159265f, 30.0f, 1e-3f);
}

TEST(LensCamera, ShiftIsInUnitsOfTheFittedSide) {
    LensCamera lens;
    lens.eye = {0, 0, 0};
    lens.target = {0, 0, -1};
    lens.shift = {0.1f, 0.2f};
    // Fitted horizontally: units of the width, as the spec's.
    CameraSpec c = lens_camera(lens, 400, 200);
    EXPECT_FLOAT_EQ(c.shift.x, 0.1f);
    EXPECT_FLOAT_EQ(c.shift.y, 0.2f);
    // Fitted vertically (portrait AUTO): units of the height, twice the width here.
    c = lens_camera(lens, 200, 400);
    EXPECT_FLOAT_EQ(c.shift.x, 0.2f);
    EXPECT_FLOAT_EQ(c.shift.y, 0.4f);
    // The shifted view's centre pixel looks where the shift says: 0.1 widths right and 0.2
    // widths up at the plane's distance.
    c = lens_camera(lens, 400, 200);
    const ViewPlane v = make_view_plane(c, 400, 200);
    const Vec3f centre = v.pixel_point(200, 100) - c.eye;
    const float d = length(c.gaze - c.eye);
    expect_near(centre, {0.2f, 0.4f, -d});
}

TEST(LensCamera, PixelAspectStretchesThePlaneVertically) {
    LensCamera lens;
    lens.eye = {0, 0, 0};
    lens.target = {0, 0, -1};
    lens.pixel_aspect = 2.0f;  // pixels twice as tall as wide: 200x100 shows a 1:1 frame
    const CameraSpec c = lens_camera(lens, 200, 100);
    const ViewPlane v = make_view_plane(c, 200, 100);
    EXPECT_NEAR(length(v.step_y), 2.0f * length(v.step_x), 1e-6f);
    // The displayed frame is square (AUTO fits horizontally): 36 mm across both ways.
    EXPECT_NEAR(length(c.gaze - c.eye), 100.0f / 36.0f, 1e-5f);
}

TEST(LensCamera, InvalidLensesAreErrors) {
    auto error = [](LensCamera lens, int w = 100, int h = 100) {
        try {
            (void)lens_camera(lens, w, h);
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("(valid)");
    };
    LensCamera lens;
    lens.eye = {0, 0, 0};
    lens.target = {0, 0, -1};
    EXPECT_EQ(error(lens), "(valid)");
    LensCamera bad = lens;
    bad.focal_length = 0;
    EXPECT_EQ(error(bad), "invalid camera: focal length 0 mm (must be positive)");
    bad = lens;
    bad.sensor_width = -1;
    EXPECT_EQ(error(bad), "invalid camera: sensor size -1 mm (must be positive)");
    bad = lens;
    bad.vertical_fov = 180.0f;
    EXPECT_EQ(error(bad),
              "invalid camera: vertical field of view 180 degrees (must be in (0, 180))");
    bad = lens;
    bad.target = bad.eye;
    EXPECT_EQ(error(bad), "invalid camera: eye and target are the same point");
    bad = lens;
    bad.up = {0, 0, 1};
    EXPECT_EQ(error(bad), "invalid camera: up vector is zero or parallel to the view direction");
    bad = lens;
    bad.pixel_aspect = 0;
    EXPECT_EQ(error(bad), "invalid camera: pixel aspect 0 (must be positive)");
    EXPECT_EQ(error(lens, 0, 10), "invalid camera: image size 0x10");
}
