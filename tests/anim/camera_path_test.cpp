#include "toonray/anim/camera_path.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

#include "toonray/core/error.h"
#include "toonray/piano/piano_model.h"
#include "toonray/scene/camera.h"

namespace toonray {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string error_of(std::string_view text) {
    try {
        parse_camera_path(text, "test.campath");
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

void expect_near(const Vec3f& a, const Vec3f& b, float tol, const std::string& what) {
    EXPECT_NEAR(a.x, b.x, tol) << what;
    EXPECT_NEAR(a.y, b.y, tol) << what;
    EXPECT_NEAR(a.z, b.z, tol) << what;
}

/// Keys at uneven times, moving in all components, with a turn and a change of pace.
const char* kUneven = R"(# uneven key times
key 0.0   eye 0 1.2 2.4      target 0 0.9 0     up 0 1 0  fov 45
key 0.5   eye 0.3 1.25 2.3   target 0.05 0.9 0  fov 44
key 3.0   eye 1.8 1.6 1.5    target 0.2 0.8 0.1 up 0.1 1 0 fov 38
key 3.4   eye 2.0 1.7 1.1    target 0.25 0.8 0.1 fov 37
key 7.0   eye 0.5 0.6 1.2    target 0 0.3 0.2   up 0 1 0 fov 50
key 12.5  eye -1.5 1.0 2.5   target 0 0.7 0     fov 48
)";

TEST(CameraPath, ParsesKeysAndInheritsUpAndFov) {
    CameraPath path = parse_camera_path(kUneven, "uneven");
    ASSERT_EQ(path.keys().size(), 6u);
    EXPECT_FALSE(path.loop_period());
    const CameraKey& k1 = path.keys()[1];
    EXPECT_EQ(k1.line, 3u);
    EXPECT_DOUBLE_EQ(k1.time, 0.5);
    EXPECT_EQ(k1.eye, Vec3f(0.3f, 1.25f, 2.3f));
    EXPECT_EQ(k1.up, Vec3f(0, 1, 0));  // from key 0
    EXPECT_FLOAT_EQ(k1.fov, 44.0f);
    EXPECT_EQ(path.keys()[3].up, Vec3f(0.1f, 1, 0));  // from key 2
    EXPECT_FLOAT_EQ(path.keys()[3].fov, 37.0f);
}

TEST(CameraPath, PassesThroughKeysAndHoldsOutsideThem) {
    CameraPath path = parse_camera_path(kUneven, "uneven");
    for (const CameraKey& k : path.keys()) {
        CameraPose p = path.pose(k.time);
        expect_near(p.eye, k.eye, 1e-5f, "eye at key");
        expect_near(p.target, k.target, 1e-5f, "target at key");
        EXPECT_NEAR(p.fov, k.fov, 1e-4f);
    }
    const CameraPose first = path.pose(0.0), last = path.pose(12.5);
    expect_near(path.pose(-3.0).eye, first.eye, 0, "before the first key");
    expect_near(path.pose(100.0).eye, last.eye, 0, "after the last key");
    EXPECT_EQ(path.pose(100.0).fov, last.fov);
    expect_near(path.pose(NAN).eye, first.eye, 0, "not a time");
}

/// One-sided second-order finite differences of a path channel: the velocity just before
/// (sign -1) or just after (sign +1) time t, exact for quadratics, so the segments' acceleration
/// does not show up as a difference between the two sides, only a jump in velocity does.
template <typename F>
Vec3f one_sided_velocity(F&& at, double t, int side, double dt = 1e-3) {
    const Vec3f p0 = at(t), p1 = at(t + side * dt), p2 = at(t + 2 * side * dt);
    return (p1 * 4.0f - p0 * 3.0f - p2) / static_cast<float>(2 * side * dt);
}

TEST(CameraPath, SpeedIsContinuousAtKeysWithUnevenTimes) {
    CameraPath path = parse_camera_path(kUneven, "uneven");
    auto eye = [&](double t) { return path.pose(t).eye; };
    auto target = [&](double t) { return path.pose(t).target; };
    auto fov = [&](double t) { return Vec3f(path.pose(t).fov, 0, 0); };
    // The scale of "a few per cent": the fastest the eye goes.
    float top_speed = 0;
    for (double t = 0; t < 12.5; t += 0.01)
        top_speed = std::max(top_speed, length(eye(t + 0.01) - eye(t)) / 0.01f);
    ASSERT_GT(top_speed, 0.3f);
    int moving_keys = 0;
    for (std::size_t i = 1; i + 1 < path.keys().size(); ++i) {
        const double t = path.keys()[i].time;
        struct Channel {
            const char* name;
            std::function<Vec3f(double)> at;
            float scale;
        };
        for (const Channel& c :
             {Channel{"eye", eye, top_speed}, Channel{"target", target, top_speed},
              Channel{"fov", fov, 10.0f}}) {
            const Vec3f before = one_sided_velocity(c.at, t, -1);
            const Vec3f after = one_sided_velocity(c.at, t, +1);
            const float speed = std::max(length(before), length(after));
            EXPECT_LT(length(after - before), 0.03f * std::max(speed, c.scale / 3))
                << c.name << " at key " << i << " (t = " << t << "): before " << length(before)
                << ", after " << length(after);
            if (c.name == std::string("eye") && speed > 0.2f) ++moving_keys;
        }
    }
    // Not only stops: most interior keys are passed at speed (a path stopping at every key
    // would pass the test above trivially).
    EXPECT_GE(moving_keys, 2);
}

TEST(CameraPath, NoOvershootAndHoldsStayStill) {
    // x rises then holds; monotone keys must give monotone motion, equal keys a still camera.
    CameraPath path = parse_camera_path(R"(
key 0  eye 0 1 3    target 0 1 0
key 1  eye 1 1 3    target 0 1 0
key 4  eye 1.2 1 3  target 0 1 0
key 6  eye 1.2 1 3  target 0 1 0
key 7  eye 3 1 3    target 0 1 0
)",
                                        "hold");
    float last_x = -1;
    for (int i = 0; i <= 700; ++i) {
        const float x = path.pose(i * 0.01).eye.x;
        EXPECT_GE(x, last_x - 1e-6f) << "t = " << i * 0.01;
        EXPECT_LE(x, 3.0f + 1e-6f);
        last_x = x;
    }
    for (double t = 4.0; t <= 6.0; t += 0.1)
        EXPECT_NEAR(path.pose(t).eye.x, 1.2f, 1e-6f) << "hold, t = " << t;
}

TEST(CameraPath, CameraSpecMatchesTheSeedConvention) {
    CameraPath path = parse_camera_path(kUneven, "uneven");
    for (double t = 0; t <= 12.5; t += 0.37) {
        const CameraPose p = path.pose(t);
        const CameraSpec c = path.camera(t);
        expect_near(c.eye, p.eye, 0, "eye");
        const Vec3f view = c.gaze - c.eye;
        // The seed: horizontal fov = 2 atan(1 / |gaze - eye|).
        const double fov = 2 * std::atan(1.0 / length(view)) * 180 / kPi;
        EXPECT_NEAR(fov, p.fov, 1e-3) << "t = " << t;
        // Looking at the target.
        expect_near(normalize(view), normalize(p.target - p.eye), 1e-5f, "direction");
        // Up unit and orthogonal, and on the same side as the keys' up (+y here).
        EXPECT_NEAR(length(c.up), 1.0f, 1e-5f);
        EXPECT_NEAR(dot(c.up, normalize(view)), 0.0f, 1e-5f);
        EXPECT_GT(c.up.y, 0.5f);
        EXPECT_NO_THROW(make_view_plane(c, 320, 180));
    }
    // Known values: fov 90 puts the gaze point one unit ahead.
    CameraPose p{{0, 0, 5}, {0, 0, -10}, {0, 3, 0}, 90.0f};
    CameraSpec c = camera_spec(p);
    expect_near(c.gaze, Vec3f(0, 0, 4), 1e-6f, "gaze");
    expect_near(c.up, Vec3f(0, 1, 0), 1e-6f, "up");
}

TEST(CameraPath, UpIsReorthogonalised) {
    CameraPath path = parse_camera_path(
        "key 0 eye 0 2 2 target 0 0 0 up 0 1 0 fov 40\n"
        "key 1 eye 2 2 0 target 0 0 0 up 0 5 0 fov 40\n",
        "up");
    for (double t = 0; t <= 1.0; t += 0.1) {
        const CameraSpec c = path.camera(t);
        EXPECT_NEAR(length(c.up), 1.0f, 1e-5f);
        EXPECT_NEAR(dot(c.up, normalize(c.gaze - c.eye)), 0.0f, 1e-5f);
    }
}

TEST(CameraPath, LoopWrapsSmoothly) {
    CameraPath path = parse_camera_path(R"(loop 10   # back to the first key at t = 10
key 0  eye 0 1 3      target 0 0.5 0
key 3  eye 2 1.5 2    target 0 0.5 0 fov 50
key 6  eye 0.5 1.2 2.5 target 0 0.8 0 fov 40
key 8  eye -1.5 0.8 2.5 target 0 0.6 0
)",
                                        "loop");
    ASSERT_TRUE(path.loop_period());
    EXPECT_DOUBLE_EQ(*path.loop_period(), 10.0);
    for (double t : {0.0, 1.3, 4.2, 7.7, 9.99}) {
        expect_near(path.pose(t + 10).eye, path.pose(t).eye, 1e-4f, "periodic");
        expect_near(path.pose(t + 30).target, path.pose(t).target, 1e-4f, "periodic");
        expect_near(path.pose(t - 10).eye, path.pose(t).eye, 1e-4f, "periodic, negative time");
    }
    // Returns to the first key, and passes through it with the same velocity on both sides.
    expect_near(path.pose(10.0).eye, Vec3f(0, 1, 3), 1e-5f, "wrap");
    auto eye = [&](double t) { return path.pose(t).eye; };
    const Vec3f before = one_sided_velocity(eye, 10.0, -1);
    const Vec3f after = one_sided_velocity(eye, 10.0, +1);
    EXPECT_GT(length(before), 0.1f) << "the loop should pass through its first key, not stop";
    EXPECT_LT(length(after - before), 0.03f * length(before));
    // The segment after the last key heads back towards the first.
    EXPECT_GT(path.pose(9.0).eye.x, -1.5f);
    EXPECT_LT(path.pose(9.0).eye.x, 0.0f);
}

TEST(CameraPath, ErrorsNameFileAndLine) {
    const std::string k0 = "key 0 eye 0 1 2 target 0 0 0\n";
    EXPECT_EQ(error_of(k0 + "key 1 eye 0 1.x 2 target 0 0 0\n"),
              "test.campath:2: malformed number '1.x' after 'eye'");
    EXPECT_EQ(error_of(k0 + "key 1 eye 0 1 target 0 0 0\n"),
              "test.campath:2: expected 3 numbers after 'eye', found 'target'");
    EXPECT_EQ(error_of(k0 + "key 1 eye 0 1 2 target 0 0\n"),
              "test.campath:2: expected 3 numbers after 'target'");
    EXPECT_EQ(error_of("# a comment\n\n" + k0 + "frame 1 eye 0 1 2\n"),
              "test.campath:4: unknown word 'frame' (a line is 'key ...' or 'loop PERIOD')");
    EXPECT_EQ(error_of(k0 + "key 1 eye 0 1 2 target 0 0 0 zoom 2\n"),
              "test.campath:2: unknown word 'zoom' in a key (expected eye, target, up or fov)");
    EXPECT_EQ(error_of(k0 + "key 0 eye 0 1 2 target 0 0 1\n"),
              "test.campath:2: key times must increase: 0 s comes after 0 s (line 1)");
    EXPECT_EQ(error_of("key 2 eye 0 1 2 target 0 0 0\nkey 1 eye 0 1 2 target 0 0 1\n"),
              "test.campath:2: key times must increase: 1 s comes after 2 s (line 1)");
    EXPECT_EQ(error_of(k0 + "key 1 eye 1 1 1 target 1 1 1\n"),
              "test.campath:2: eye and target are the same point");
    EXPECT_EQ(error_of(k0 + "key 1 eye 0 3 0 target 0 0 0\n"),
              "test.campath:2: up is parallel to the view direction (eye to target)");
    EXPECT_EQ(error_of(k0 + "key 1 eye 0 1 2 target 0 0 0 up 0 0 0\n"),
              "test.campath:2: up vector is zero");
    EXPECT_EQ(error_of(k0 + "key 1 eye 0 1 2 target 0 0 0 fov 179\n"),
              "test.campath:2: fov 179 degrees is outside (1, 179)");
    EXPECT_EQ(error_of(k0 + "key 1 eye 0 1 2 target 0 0 0 fov 1\n"),
              "test.campath:2: fov 1 degrees is outside (1, 179)");
    EXPECT_EQ(error_of("key 0 eye 0 1 2 target 0 0 0 fov -20\n"),
              "test.campath:1: fov -20 degrees is outside (1, 179)");
    EXPECT_EQ(error_of(k0 + "key 1 eye 0 1 2 eye 0 0 0 target 0 0 0\n"),
              "test.campath:2: 'eye' given twice in one key");
    EXPECT_EQ(error_of(k0 + "key 1 target 0 0 0\n"), "test.campath:2: key at 1 s needs an eye");
    EXPECT_EQ(error_of(k0 + "key x eye 0 1 2 target 0 0 0\n"),
              "test.campath:2: malformed number 'x' after 'key'");
    EXPECT_EQ(error_of(k0 + "key nan eye 0 1 2 target 0 0 0\n"),
              "test.campath:2: malformed number 'nan' after 'key'");
    EXPECT_EQ(error_of(k0 + "loop 10 20\n"),
              "test.campath:2: unexpected '20' at the end of the line");
    EXPECT_EQ(error_of("loop 1\n" + k0 + "key 1 eye 0 1 3 target 0 0 0\n"),
              "test.campath:1: loop period 1 s must be longer than the keys' span 1 s: after the "
              "last key the path returns to the first (leave out a closing key equal to the "
              "first)");
    EXPECT_EQ(error_of("loop 0\n" + k0), "test.campath:1: loop period 0 s must be positive");
    EXPECT_EQ(error_of("# nothing\n"),
              "test.campath: no camera keys (lines 'key TIME eye ... target ...')");
}

TEST(CameraPath, DegenerateCameraBetweenKeysIsReported) {
    // The eye flies through the target.
    std::string e = error_of(
        "key 0 eye 0 1 2 target 0 1 0\n"
        "key 2 eye 0 1 -2 target 0 1 0\n");
    EXPECT_EQ(e.rfind("test.campath:1: between this key (0 s) and the next (2 s, line 2) the eye "
                      "reaches the target",
                      0),
              0u)
        << e;
    // Up flips over.
    e = error_of(
        "key 0 eye 0 0 2 target 0 0 0 up 0 1 0\n"
        "key 1 eye 0 0 2 target 0 0 0 up 0 -1 0\n");
    EXPECT_NE(e.find("the up vector vanishes"), std::string::npos) << e;
    // Looking straight down on the way between two fine keys.
    e = error_of(
        "key 0 eye 1 2 0 target 0 0 0\n"
        "key 1 eye -1 2 0 target 0 0 0\n");
    EXPECT_NE(e.find("up turns parallel to the view direction near 0.500 s"), std::string::npos)
        << e;
}

TEST(CameraPath, BuiltInCodeAndSingleKey) {
    CameraKey k;
    k.eye = {0, 1, 3};
    k.target = {0, 1, 0};
    CameraPath one({k});
    expect_near(one.pose(5).eye, k.eye, 0, "single key");
    CameraPath looped({k}, 4.0);
    expect_near(looped.pose(17).eye, k.eye, 0, "single key loop");
    EXPECT_THROW(CameraPath(std::vector<CameraKey>{}), Error);
    CameraKey bad = k;
    bad.time = 1;
    bad.target = bad.eye;
    try {
        CameraPath({k, bad}, {}, "code");
        FAIL();
    } catch (const Error& e) {
        EXPECT_STREQ(e.what(), "code: eye and target are the same point");
    }
    EXPECT_THROW((void)CameraPath().pose(0), Error);
}

// --- The demo's default path ------------------------------------------------------------------

TEST(EntertainerPath, LoadsLoopsAndKeepsClearOfThePiano) {
    CameraPath path = load_camera_path(TOONRAY_DATA_DIR "/entertainer.campath");
    ASSERT_TRUE(path.loop_period());
    EXPECT_NEAR(*path.loop_period(), 30.0, 5.0);
    const double period = *path.loop_period();
    // Checked against the piano the demo renders: its bounds and camera anchors.
    const PianoModel piano = build_piano();
    const BBox box = piano.bounds;
    ASSERT_FALSE(box.empty());
    constexpr float kClearance = 0.15f;  // the eye keeps this far from the piano's box
    float max_speed = 0;
    for (int i = 0; i <= 3000; ++i) {
        const double t = period * i / 3000.0;
        const CameraPose p = path.pose(t);
        const Vec3f e = p.eye;
        const bool inside = e.x > box.lo.x - kClearance && e.x < box.hi.x + kClearance &&
                            e.y < box.hi.y + kClearance && e.z > box.lo.z - kClearance &&
                            e.z < box.hi.z + kClearance;
        EXPECT_FALSE(inside) << "eye inside the piano at t = " << t;
        EXPECT_GT(e.y, 0.3f) << "t = " << t;
        EXPECT_GT(p.fov, 20.0f);
        EXPECT_LT(p.fov, 70.0f);
        EXPECT_NO_THROW(make_view_plane(path.camera(t), 1280, 720));
        if (i > 0) {
            const float speed = length(p.eye - path.pose(t - period / 3000.0).eye) /
                                static_cast<float>(period / 3000.0);
            max_speed = std::max(max_speed, speed);
        }
    }
    EXPECT_LT(max_speed, 1.5f) << "a calm camera: under 1.5 m/s";
    // It visits each view: the target comes close to each anchor at some time.
    auto visits = [&](Vec3f anchor, float radius) {
        for (int i = 0; i < 300; ++i)
            if (length(path.pose(period * i / 300.0).target - anchor) < radius) return true;
        return false;
    };
    EXPECT_TRUE(visits(piano.keyboard_center, 0.1f)) << "keyboard";
    EXPECT_TRUE(visits(piano.roll_window_center, 0.05f)) << "roll";
    EXPECT_TRUE(visits(piano.pedal_center, 0.1f)) << "pedals";
    // And starts wide: all of the piano (its vertices in its bounds, so not the floor) is in
    // the 16:9 picture.
    const CameraPose start = path.pose(0);
    const Vec3f dir = normalize(start.target - start.eye);
    const Vec3f right = normalize(cross(dir, start.up));
    const float half_width = std::tan(0.5f * start.fov * static_cast<float>(kPi) / 180);
    float widest = 0, highest = 0;
    for (const Vec3f& p : piano.scene.positions) {
        if (p.x < box.lo.x || p.x > box.hi.x || p.y < box.lo.y || p.y > box.hi.y ||
            p.z < box.lo.z || p.z > box.hi.z)
            continue;
        const Vec3f v = p - start.eye;
        widest = std::max(widest, std::abs(dot(v, right) / dot(v, dir)) / half_width);
        highest =
            std::max(highest, std::abs(dot(v, start.up) / dot(v, dir)) / (half_width * 9 / 16));
    }
    EXPECT_LT(widest, 0.95f) << "the piano is wider than the opening view";
    EXPECT_LT(highest, 0.95f) << "the piano is taller than the opening view";
    EXPECT_GT(std::max(widest, highest), 0.6f) << "the piano is lost in the opening view";
}

}  // namespace
}  // namespace toonray
