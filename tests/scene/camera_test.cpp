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
