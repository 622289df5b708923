// The robust line mode measured on scenes built in code where the right answer is known.
#include "toonray/render/robust.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <limits>
#include <set>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/render/classic.h"
#include "toonray/render/renderer.h"
#include "toonray/render/trace.h"
#include "support/test_scenes.h"

using namespace toonray;

namespace {

constexpr float kPi = 3.14159265f;

struct Frame {
    Renderer renderer;
    RenderSettings settings;
    std::vector<Light> lights;  ///< none: the default light
    CameraSpec camera;
    ViewPlane view;
    int sub = 1;                     ///< samples per pixel side
    Image<std::uint8_t> sample_hit;  ///< whether each sample's ray hits, traced here one by one
};

std::vector<Light> lights_or_default(const Frame& f, const Scene& scene) {
    return f.lights.empty() ? test_support::default_lights(scene, f.camera) : f.lights;
}

void render(Frame& f, const Scene& scene) {
    TriangleAccel accel;
    accel.build(scene.positions, scene.tri_positions);
    f.view = make_view_plane(f.camera, f.settings.width, f.settings.height);
    f.settings.layers = true;  // coverage() reads the line coverage image
    f.renderer.render(scene, accel, f.camera, lights_or_default(f, scene), f.settings);
    // The renderer keeps no per-sample buffers: which samples see the scene, ray by ray.
    f.sub = f.settings.lines.mode == LineMode::Classic
                ? 1
                : samples_per_side(f.settings.sampling.samples);
    f.sample_hit.resize(f.settings.width * f.sub, f.settings.height * f.sub);
    for (int y = 0; y < f.sample_hit.height(); ++y)
        for (int x = 0; x < f.sample_hit.width(); ++x) {
            Hit hit;
            f.sample_hit(x, y) =
                accel.intersect(Ray{f.view.eye, sample_direction(f.view, x, y, f.sub)}, hit);
        }
}

// Line coverage of pixel (x, y) in [0, 1]: robust's coverage, classic's merged edges (1 on an
// edge).
float coverage(const Frame& f, int x, int y) { return f.renderer.layers().lines(x, y); }

// Pixel coordinates (continuous, pixel centres at +0.5) of a world point.
Vec2f project(const ViewPlane& v, const Vec3f& p) {
    Vec3f d = p - v.eye;
    // The image plane holds upper_left; intersect the ray eye -> p with it.
    float s = dot(v.upper_left - v.eye, v.forward) / dot(d, v.forward);
    Vec3f q = v.eye + d * s - v.upper_left;
    return {dot(q, v.step_x) / dot(v.step_x, v.step_x), dot(q, v.step_y) / dot(v.step_y, v.step_y)};
}

CameraSpec look_at(const Vec3f& eye, const Vec3f& target, float fov_degrees,
                   const Vec3f& world_up = {0, 1, 0}) {
    Vec3f fwd = normalize(target - eye);
    Vec3f right = normalize(cross(fwd, world_up));
    Vec3f up = cross(right, fwd);
    float dist = 1.0f / std::tan(fov_degrees * kPi / 360.0f);
    return {eye, eye + fwd * dist, up};
}

// A mesh of unit voxels: faces between a filled and an empty cell, all vertices on the integer
// grid, so faces share whole edges (no T-junctions). `material_of(x, y, z)` picks the material.
Scene voxels(const std::vector<std::array<int, 3>>& cells, float scale,
             const std::function<std::uint32_t(int, int, int)>& material_of = nullptr) {
    std::set<std::array<int, 3>> filled(cells.begin(), cells.end());
    Scene s;
    for (const char* name : {"red", "blue"}) {
        Material m(name);
        m.kd = std::string(name) == "red" ? Vec3f(0.9f, 0.3f, 0.3f) : Vec3f(0.3f, 0.4f, 0.9f);
        s.materials.push_back(m);
    }
    for (const auto& c : cells)
        for (int axis = 0; axis < 3; ++axis)
            for (int side = 0; side < 2; ++side) {
                std::array<int, 3> n = c;
                n[axis] += side ? 1 : -1;
                if (filled.count(n)) continue;
                // The face on the plane axis = c[axis] + side, spanned by the other two axes.
                int a = (axis + 1) % 3, b = (axis + 2) % 3;
                auto base = static_cast<std::uint32_t>(s.positions.size());
                for (int k = 0; k < 4; ++k) {
                    std::array<float, 3> p{float(c[0]), float(c[1]), float(c[2])};
                    p[axis] += side;
                    p[a] += (k == 1 || k == 2) ? 1 : 0;
                    p[b] += (k >= 2) ? 1 : 0;
                    s.positions.push_back(Vec3f(p[0], p[1], p[2]) * scale);
                }
                std::uint32_t m = material_of ? material_of(c[0], c[1], c[2]) : 1;
                s.add_triangle({base, base + 1, base + 2}, m, 0);
                s.add_triangle({base, base + 2, base + 3}, m, 0);
            }
    return s;
}

// Visible samples along a 3D segment, projected; ends within `margin` pixels are skipped.
std::vector<Vec2f> visible_samples(const Frame& f, const Scene& scene, Vec3f a, Vec3f b,
                                   float margin) {
    TriangleAccel accel;
    accel.build(scene.positions, scene.tri_positions);
    std::vector<Vec2f> out;
    Vec2f pa = project(f.view, a), pb = project(f.view, b);
    float len = std::hypot(pb.x - pa.x, pb.y - pa.y);
    int n = std::max(2, static_cast<int>(len));
    for (int i = 0; i <= n; ++i) {
        float u = static_cast<float>(i) / n;
        if (u * len < margin || (1 - u) * len < margin) continue;
        Vec3f p = a + (b - a) * u;
        Vec2f q = project(f.view, p);
        if (q.x < 2 || q.y < 2 || q.x > f.settings.width - 2 || q.y > f.settings.height - 2)
            continue;
        // Visible when nothing is hit well before the point.
        Vec3f d = p - f.view.eye;
        float dist = length(d);
        Hit hit;
        Ray ray{f.view.eye, d / dist, dist * (1.0f - 1e-3f)};
        if (accel.intersect(ray, hit)) continue;
        out.push_back(q);
    }
    return out;
}

// Largest coverage within one pixel of a continuous position.
float coverage_near(const Frame& f, Vec2f q) {
    float best = 0.0f;
    int cx = static_cast<int>(q.x), cy = static_cast<int>(q.y);
    for (int y = cy - 1; y <= cy + 1; ++y)
        for (int x = cx - 1; x <= cx + 1; ++x)
            if (x >= 0 && y >= 0 && x < f.settings.width && y < f.settings.height)
                best = std::max(best, coverage(f, x, y));
    return best;
}

// Fraction of samples along the edges that are drawn.
float drawn_fraction(const Frame& f, const Scene& scene,
                     const std::vector<std::pair<Vec3f, Vec3f>>& edges,
                     int* samples_out = nullptr) {
    int samples = 0, drawn = 0;
    for (const auto& [a, b] : edges)
        for (Vec2f q : visible_samples(f, scene, a, b, 3.0f)) {
            ++samples;
            if (coverage_near(f, q) > 0.5f) ++drawn;
            else if (std::getenv("TOONRAY_DEBUG_LINES"))
                std::printf("undrawn sample at %.2f %.2f\n", q.x, q.y);
        }
    if (samples_out) *samples_out = samples;
    return samples ? static_cast<float>(drawn) / samples : 0.0f;
}

// Pixels whose every sample hits, and no pixel within `margin` misses.
std::vector<std::pair<int, int>> interior_pixels(const Frame& f, int margin) {
    const int sub = f.sub, w = f.settings.width, h = f.settings.height;
    auto hit = [&](int x, int y) {
        for (int j = 0; j < sub; ++j)
            for (int i = 0; i < sub; ++i)
                if (!f.sample_hit(x * sub + i, y * sub + j)) return false;
        return true;
    };
    std::vector<std::pair<int, int>> out;
    for (int y = margin; y < h - margin; ++y)
        for (int x = margin; x < w - margin; ++x) {
            bool inside = true;
            for (int dy = -margin; dy <= margin && inside; ++dy)
                for (int dx = -margin; dx <= margin && inside; ++dx) inside = hit(x + dx, y + dy);
            if (inside) out.emplace_back(x, y);
        }
    return out;
}

Scene floor_plane(float half, int cells) {
    Scene s;
    for (int j = 0; j <= cells; ++j)
        for (int i = 0; i <= cells; ++i)
            s.positions.push_back(
                {-half + 2 * half * i / cells, 0.0f, -half + 2 * half * j / cells});
    for (int j = 0; j < cells; ++j)
        for (int i = 0; i < cells; ++i) {
            std::uint32_t a = j * (cells + 1) + i, b = a + 1, c = a + cells + 1, d = c + 1;
            s.add_triangle({a, c, b}, 0, 0);
            s.add_triangle({b, c, d}, 0, 0);
        }
    return s;
}

Scene sphere(int segments, int rings, float r) {
    Scene s;
    for (int j = 0; j <= rings; ++j) {
        float phi = kPi * j / rings;
        for (int i = 0; i < segments; ++i) {
            float theta = 2 * kPi * i / segments;
            s.positions.push_back({r * std::sin(phi) * std::cos(theta), r * std::cos(phi),
                                   r * std::sin(phi) * std::sin(theta)});
        }
    }
    for (int j = 0; j < rings; ++j)
        for (int i = 0; i < segments; ++i) {
            std::uint32_t a = j * segments + i, b = j * segments + (i + 1) % segments;
            std::uint32_t c = a + segments, d = b + segments;
            if (j > 0) s.add_triangle({a, b, c}, 0, 0);
            if (j < rings - 1) s.add_triangle({b, d, c}, 0, 0);
        }
    return s;
}

}  // namespace

TEST(RobustLines, GrazingPlaneHasNoLinesInside) {
    // A tessellated floor seen at 80 to 89 degrees from its normal: no line may appear inside
    // it, in robust mode. Classic mode is measured for comparison (its depth threshold fires).
    Scene floor = floor_plane(500.0f, 60);
    for (float angle : {80.0f, 85.0f, 89.0f}) {
        float a = angle * kPi / 180.0f;
        // Looking down at the floor with the view direction `angle` from the normal (+y).
        Vec3f dir(0.0f, -std::cos(a), -std::sin(a));
        Vec3f eye(0.0f, 2.0f, 0.0f);
        int false_lines[2] = {0, 0};
        for (LineMode mode : {LineMode::Classic, LineMode::Robust}) {
            Frame f;
            f.settings.width = 320;
            f.settings.height = 180;
            f.settings.lines.mode = mode;
            f.lights = {Light{Light::Kind::Point, Vec3f(0, 1000, 0), 1.0f}};
            f.camera = look_at(eye, eye + dir, 60.0f, {0, 1, 0});
            render(f, floor);
            auto inside = interior_pixels(f, 3);
            ASSERT_GT(inside.size(), 3000u) << angle;
            int lines = 0;
            for (auto [x, y] : inside)
                if (coverage(f, x, y) > 0.0f) ++lines;
            false_lines[mode == LineMode::Robust] = lines;
        }
        std::printf("grazing plane at %.0f deg: false line pixels classic %d, robust %d\n", angle,
                    false_lines[0], false_lines[1]);
        EXPECT_EQ(false_lines[1], 0) << angle;
    }
}

TEST(RobustLines, TessellatedSphereHasLinesOnlyAtItsSilhouette) {
    // 40,000 triangles, no vertex normals: robust lines only near the silhouette, and all of it.
    Scene ball = sphere(200, 101, 1.0f);
    ASSERT_GT(ball.triangle_count(), 39000u);
    int false_lines[2] = {0, 0};
    for (LineMode mode : {LineMode::Classic, LineMode::Robust}) {
        Frame f;
        f.settings.width = 640;
        f.settings.height = 360;
        f.settings.lines.mode = mode;
        f.camera = look_at({0.3f, 0.8f, 4.0f}, {0, 0, 0}, 45.0f);
        render(f, ball);
        const int sub = f.sub;
        // Distance of each pixel to the silhouette, from the per-pixel hit mask.
        auto hit = [&](int x, int y) {
            return f.sample_hit(x * sub + sub / 2, y * sub + sub / 2) != 0;
        };
        const float width = f.settings.lines.width;  // pixels at 720 lines
        const int near = static_cast<int>(std::ceil(width * f.settings.height / 720.0f)) + 1;
        int silhouette = 0, silhouette_drawn = 0;
        for (int y = near; y < f.settings.height - near; ++y)
            for (int x = near; x < f.settings.width - near; ++x) {
                bool near_miss = false, near_hit = false;
                for (int dy = -near; dy <= near; ++dy)
                    for (int dx = -near; dx <= near; ++dx)
                        (hit(x + dx, y + dy) ? near_hit : near_miss) = true;
                float c = coverage(f, x, y);
                if (hit(x, y) && !near_miss && c > 0.0f) ++false_lines[mode == LineMode::Robust];
                // Silhouette pixels: a hit with a miss as a 4-neighbour.
                if (hit(x, y) &&
                    (!hit(x - 1, y) || !hit(x + 1, y) || !hit(x, y - 1) || !hit(x, y + 1))) {
                    ++silhouette;
                    if (coverage_near(f, {x + 0.5f, y + 0.5f}) > 0.5f) ++silhouette_drawn;
                }
            }
        if (mode == LineMode::Robust) {
            EXPECT_GT(silhouette, 500);
            EXPECT_EQ(silhouette_drawn, silhouette) << "silhouette incomplete";
        }
    }
    std::printf("tessellated sphere: line pixels away from the silhouette: classic %d, robust %d\n",
                false_lines[0], false_lines[1]);
    EXPECT_EQ(false_lines[1], 0);
}

// The grazing floor and the tessellated sphere above, adaptively sampled against full
// supersampling (--adaptive off), in both modes that sample: at most 0.5% of pixels may differ
// by more than 2/255.
TEST(RobustLines, AdaptiveSamplingKeepsTheGrazingFloorAndTheSphere) {
    struct Case {
        const char* name;
        Scene scene;
        CameraSpec camera;
    };
    const float a = 85.0f * kPi / 180.0f;
    const Vec3f eye(0.0f, 2.0f, 0.0f), dir(0.0f, -std::cos(a), -std::sin(a));
    const Case cases[] = {
        {"grazing floor", floor_plane(500.0f, 60), look_at(eye, eye + dir, 60.0f, {0, 1, 0})},
        {"sphere", sphere(200, 101, 1.0f), look_at({0.3f, 0.8f, 4.0f}, {0, 0, 0}, 45.0f)}};
    for (const Case& c : cases)
        for (LineMode mode : {LineMode::Robust, LineMode::Ink}) {
            Frame adaptive, full;
            for (Frame* f : {&adaptive, &full}) {
                f->settings.width = 640;
                f->settings.height = 360;
                f->settings.lines.mode = mode;
                f->lights = {Light{Light::Kind::Point, Vec3f(0, 1000, 0), 1.0f}};
                f->settings.sampling.adaptive = f == &adaptive;
                f->camera = c.camera;
                render(*f, c.scene);
            }
            const ImageRgb8& x = adaptive.renderer.layers().cel;
            const ImageRgb8& y = full.renderer.layers().cel;
            ASSERT_EQ(x.size(), y.size());
            // The final image: colours and lines.
            std::size_t differing = 0;
            const ImageF& ex = adaptive.renderer.layers().lines;
            const ImageF& ey = full.renderer.layers().lines;
            for (std::size_t i = 0; i < x.size(); ++i) {
                bool differs = std::abs(ex.data()[i] - ey.data()[i]) * 255.0f > 2.0f;
                for (int ch = 0; ch < 3; ++ch)
                    differs |= std::abs(x.data()[i][ch] - y.data()[i][ch]) > 2;
                differing += differs;
            }
            const double share = static_cast<double>(differing) / static_cast<double>(x.size());
            std::printf("%s, %s: %.3f%% of pixels differ by more than 2/255 (%llu refined)\n",
                        c.name, mode == LineMode::Ink ? "ink" : "robust", 100 * share,
                        static_cast<unsigned long long>(adaptive.renderer.refined_pixels()));
            EXPECT_LE(share, 0.005) << c.name;
            EXPECT_LT(adaptive.renderer.refined_pixels(), x.size() / 4) << c.name;
        }
}

TEST(RobustLines, EveryVisibleCreaseOfACubeAndAStairIsDrawn) {
    Frame f;
    f.settings.width = 960;
    f.settings.height = 720;
    // A cube seen from a corner: three faces, nine visible edges; the three that meet at the
    // near corner are creases between visible faces, the other six its outline.
    Scene cube = voxels({{0, 0, 0}}, 1.0f);
    f.camera = look_at({2.6f, 2.1f, 3.0f}, {0.5f, 0.5f, 0.5f}, 40.0f);
    render(f, cube);
    std::vector<std::pair<Vec3f, Vec3f>> edges, inner;
    for (int axis = 0; axis < 3; ++axis)
        for (int i = 0; i < 4; ++i) {
            Vec3f a(0.0f), b(0.0f);
            a[(axis + 1) % 3] = b[(axis + 1) % 3] = float(i & 1);
            a[(axis + 2) % 3] = b[(axis + 2) % 3] = float(i >> 1);
            b[axis] = 1.0f;
            edges.push_back({a, b});
            if (i == 3) inner.push_back({a, b});  // the edges through the corner (1, 1, 1)
        }
    int samples = 0;
    float cube_drawn = drawn_fraction(f, cube, edges, &samples);
    EXPECT_GT(samples, 1000);
    EXPECT_EQ(cube_drawn, 1.0f);
    f.settings.lines.types = kLineCrease;  // creases alone find the inner three
    render(f, cube);
    EXPECT_EQ(drawn_fraction(f, cube, inner, &samples), 1.0f);
    EXPECT_GT(samples, 300);

    // A staircase of voxels: convex and concave creases.
    std::vector<std::array<int, 3>> cells;
    for (int z = 0; z < 2; ++z)
        for (int step = 0; step < 3; ++step)
            for (int x = 0; x < 3 - step; ++x) cells.push_back({x, step, z});
    Scene stair = voxels(cells, 1.0f);
    Frame g;
    g.settings = f.settings;
    g.camera = look_at({5.5f, 4.5f, 6.0f}, {1.5f, 1.2f, 1.0f}, 45.0f);
    render(g, stair);
    std::vector<std::pair<Vec3f, Vec3f>> stair_edges;
    for (int step = 0; step < 3; ++step) {
        float x = 3.0f - step, y = step + 1.0f;
        stair_edges.push_back({{x, y, 0}, {x, y, 2}});      // convex nosing
        stair_edges.push_back({{x, y - 1, 2}, {x, y, 2}});  // riser, front side edge
        if (step < 2)
            stair_edges.push_back(
                {{x - 1, y, 0}, {x - 1, y, 2}});            // concave foot of the next riser
        stair_edges.push_back({{x - 1, y, 2}, {x, y, 2}});  // tread, front side edge
    }
    float stair_drawn = drawn_fraction(g, stair, stair_edges, &samples);
    EXPECT_GT(samples, 300);
    EXPECT_EQ(stair_drawn, 1.0f);
}

TEST(RobustLines, BoundariesBetweenMaterialsAndObjects) {
    // Two unit boxes side by side, touching at x = 1, their front faces coplanar: nothing but
    // the material (or object) change marks the boundary.
    std::vector<std::array<int, 3>> cells = {{0, 0, 0}, {1, 0, 0}};
    Scene two = voxels(cells, 1.0f, [](int x, int, int) { return x == 0 ? 1u : 2u; });
    Frame f;
    f.settings.width = 960;
    f.settings.height = 720;
    f.camera = look_at({1.0f, 0.5f, 4.0f}, {1.0f, 0.5f, 0.0f}, 40.0f);  // straight at the front
    render(f, two);
    std::vector<std::pair<Vec3f, Vec3f>> boundary = {{{1, 0, 1}, {1, 1, 1}}};
    EXPECT_EQ(drawn_fraction(f, two, boundary), 1.0f);
    // Without the material lines, or with one material, there is no line there.
    f.settings.lines.types = kLineAll & ~kLineMaterial;
    render(f, two);
    EXPECT_EQ(drawn_fraction(f, two, boundary), 0.0f);
    Scene same = voxels(cells, 1.0f);
    f.settings.lines.types = kLineAll;
    render(f, same);
    EXPECT_EQ(drawn_fraction(f, same, boundary), 0.0f);
    // Two objects of one material: the object lines mark it.
    for (std::size_t t = 0; t < same.triangle_count(); ++t)
        same.tri_object[t] = same.positions[same.tri_positions[t][0]].x +
                                         same.positions[same.tri_positions[t][1]].x +
                                         same.positions[same.tri_positions[t][2]].x >
                                     3.0f
                                 ? 1u
                                 : 0u;
    same.objects.push_back("right");
    render(f, same);
    EXPECT_EQ(drawn_fraction(f, same, boundary), 1.0f);
}

TEST(RobustLines, WidthScalesWithResolution) {
    // The same cube at 720p and 2160p: lines three times as wide (within 15%). Width is total
    // coverage over line length, and length itself scales by 3.
    Scene cube = voxels({{0, 0, 0}}, 1.0f);
    double total[2] = {0, 0};
    int i = 0;
    for (int height : {720, 2160}) {
        Frame f;
        f.settings.width = height * 16 / 9;
        f.settings.height = height;
        f.settings.sampling.samples = 1;  // keeps the 4K G-buffer small; widths do not depend on it
        f.camera = look_at({2.6f, 2.1f, 3.0f}, {0.5f, 0.5f, 0.5f}, 40.0f);
        render(f, cube);
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < f.settings.width; ++x) total[i] += coverage(f, x, y);
        ++i;
    }
    double width_ratio = total[1] / total[0] / 3.0;
    std::printf("line width 2160p / 720p = %.3f (ideal 3)\n", width_ratio);
    EXPECT_NEAR(width_ratio, 3.0, 0.45);
}

TEST(RobustLines, LinesChangeSmoothlyUnderASlowCameraMove) {
    // Ten frames of a slow orbit around a tessellated sphere on a stepped block: the amount of
    // line in each frame stays within a small fraction of its neighbours' mean (no flicker).
    std::vector<std::array<int, 3>> cells;
    for (int x = -2; x < 2; ++x)
        for (int z = -2; z < 2; ++z) cells.push_back({x, -1, z});
    cells.push_back({-2, 0, -2});
    cells.push_back({1, 0, 1});
    Scene scene = voxels(cells, 1.0f);
    Scene ball = sphere(64, 33, 0.8f);
    auto base = static_cast<std::uint32_t>(scene.positions.size());
    for (const Vec3f& p : ball.positions) scene.positions.push_back(p + Vec3f(0, 0.8f, 0));
    for (std::size_t t = 0; t < ball.triangle_count(); ++t) {
        auto tri = ball.tri_positions[t];
        scene.add_triangle({tri[0] + base, tri[1] + base, tri[2] + base}, 2, 0);
    }
    std::vector<double> amount;
    for (int frame = 0; frame < 10; ++frame) {
        float a = 0.6f + 0.004f * frame;  // about a quarter of a degree per frame
        Frame f;
        f.settings.width = 480;
        f.settings.height = 270;
        f.camera = look_at({6.0f * std::sin(a), 3.5f, 6.0f * std::cos(a)}, {0, 0.3f, 0}, 45.0f);
        render(f, scene);
        double sum = 0;
        for (int y = 0; y < f.settings.height; ++y)
            for (int x = 0; x < f.settings.width; ++x) sum += coverage(f, x, y);
        amount.push_back(sum);
    }
    double worst = 0;
    for (int i = 1; i + 1 < 10; ++i) {
        double mean = 0.5 * (amount[i - 1] + amount[i + 1]);
        worst = std::max(worst, std::abs(amount[i] - mean) / mean);
    }
    std::printf(
        "slow camera move: largest deviation of a frame's line amount from its neighbours' mean: %.4f\n",
        worst);
    EXPECT_LT(worst, 0.01);
}

TEST(RobustLines, ParsesLineTypes) {
    EXPECT_EQ(parse_line_types("all"), static_cast<unsigned>(kLineAll));
    EXPECT_EQ(parse_line_types("none"), 0u);
    EXPECT_EQ(parse_line_types("silhouette,crease"),
              static_cast<unsigned>(kLineSilhouette | kLineCrease));
    EXPECT_THROW((void)parse_line_types("silhouette,outline"), Error);
    for (unsigned types : {0u, 1u, 5u, 30u, unsigned(kLineAll), unsigned(kLineAll | kLineBand),
                           unsigned(kLineSilhouette | kLineShadow), unsigned(kLineBand)})
        EXPECT_EQ(parse_line_types(format_line_types(types)), types) << format_line_types(types);
    // Band and shadow lines are not among "all" (the default): they are added by name.
    EXPECT_EQ(parse_line_types("all,band,shadow"),
              static_cast<unsigned>(kLineAll | kLineBand | kLineShadow));
    EXPECT_EQ(format_line_types(kLineAll | kLineShadow), "all,shadow");
    try {
        (void)parse_line_types("silhouette,outline");
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()),
                  "unknown line type 'outline' (choose from silhouette, crease, depth, "
                  "object, material, band, shadow, all, none)");
    }
}

TEST(RobustLines, DistanceTransformIsExact) {
    Image<std::uint8_t> seeds(9, 7, 0);
    seeds(2, 3) = 1;
    seeds(7, 1) = 4;
    ImageF d;
    distance_to_seeds(seeds, d, 1);
    for (int y = 0; y < 7; ++y)
        for (int x = 0; x < 9; ++x) {
            float a = float((x - 2) * (x - 2) + (y - 3) * (y - 3)),
                  b = float((x - 7) * (x - 7) + (y - 1) * (y - 1));
            EXPECT_EQ(d(x, y), std::min(a, b)) << x << "," << y;
        }
    Image<std::uint8_t> none(4, 4, 0);
    distance_to_seeds(none, d, 1);
    EXPECT_TRUE(std::isinf(d(2, 2)));
}

// ---- The fast row-wise stages against straightforward references ----------------------------

namespace {

// find_line_seeds as it was first written, pixel by pixel: the reference the row-wise,
// vectorised version must match bit for bit.
Image<std::uint8_t> reference_seeds(const FineBuffers& fine, const LineSettings& s) {
    const float inf = std::numeric_limits<float>::infinity();
    const int w = fine.depth.width(), h = fine.depth.height();
    Image<std::uint8_t> seeds(w, h, 0);
    const float cos_crease = std::cos(s.crease_angle * 3.14159265f / 180.0f);
    auto pair_bits = [&](int ax, int ay, int bx, int by) -> unsigned {
        float za = fine.depth(ax, ay), zb = fine.depth(bx, by);
        bool hit_a = za != inf, hit_b = zb != inf;
        if (!hit_a && !hit_b) return 0;
        if (hit_a != hit_b) return s.types & kLineSilhouette;
        unsigned bits = 0;
        if ((s.types & kLineObject) && fine.object(ax, ay) != fine.object(bx, by))
            bits |= kLineObject;
        if ((s.types & kLineMaterial) && fine.material(ax, ay) != fine.material(bx, by))
            bits |= kLineMaterial;
        if ((s.types & kLineCrease) &&
            dot(fine.geometric_normal(ax, ay), fine.geometric_normal(bx, by)) < cos_crease)
            bits |= kLineCrease;
        return bits;
    };
    auto depth_bits = [&](int x, int y) -> unsigned {
        float z = fine.depth(x, y);
        if (z == inf) return 0;
        const float inv = 1.0f / z;
        float farthest_step = -1.0f;
        auto along = [&](int x0, int y0, int x1, int y1) {
            float z0 = fine.depth(x0, y0), z1 = fine.depth(x1, y1);
            if (z0 == inf || z1 == inf) return;
            float i0 = 1.0f / z0, i1 = 1.0f / z1;
            if (!(std::abs(i0 - 2.0f * inv + i1) > s.robust.depth_step * inv)) return;
            bool first = std::abs(i0 - inv) > std::abs(i1 - inv);
            float z_across = first ? z0 : z1;
            if (z_across > z) farthest_step = std::max(farthest_step, (z_across - z) / z);
        };
        if (x > 0 && x + 1 < w) along(x - 1, y, x + 1, y);
        if (y > 0 && y + 1 < h) along(x, y - 1, x, y + 1);
        if (farthest_step < 0.0f) return 0;
        return s.types & (farthest_step > s.robust.silhouette_ratio ? kLineSilhouette : kLineDepth);
    };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            unsigned bits = 0;
            const int nx[4] = {x - 1, x + 1, x, x};
            const int ny[4] = {y, y, y - 1, y + 1};
            for (int i = 0; i < 4; ++i) {
                if (nx[i] < 0 || nx[i] >= w || ny[i] < 0 || ny[i] >= h) continue;
                unsigned b = pair_bits(x, y, nx[i], ny[i]);
                if (!b) continue;
                float z_self = fine.depth(x, y), z_other = fine.depth(nx[i], ny[i]);
                bool tie = std::abs(z_self - z_other) <= 1e-5f * std::min(z_self, z_other);
                bool first_in_scan = ny[i] > y || (ny[i] == y && nx[i] > x);
                if (tie ? first_in_scan : z_self < z_other) bits |= b;
            }
            seeds(x, y) = static_cast<std::uint8_t>(bits | depth_bits(x, y));
        }
    return seeds;
}

// A random fine G-buffer with every case the line tests tell apart: background, ties and
// near-ties in depth, sloped planes (1/z affine), small and large steps, few ids, normals
// from a small set (some pairs across the crease angle).
struct RandomGBuffer {
    RandomGBuffer(int w, int h, unsigned seed)
        : depth(w, h), normal(w, h), object(w, h), material(w, h) {
        std::srand(seed);
        auto unit = [] { return static_cast<float>(std::rand()) / static_cast<float>(RAND_MAX); };
        const Vec3f normals[4] = {normalize(Vec3f(0, 0, 1)), normalize(Vec3f(0.2f, 0, 1)),
                                  normalize(Vec3f(1, 0, 1)), normalize(Vec3f(0, 1, 0.3f))};
        const float a = 0.3f + unit(), b = unit() * 0.01f, c = unit() * 0.01f;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                float r = unit();
                float plane = 1.0f / (a + b * x + c * y);  // 1/z affine: no depth lines inside
                float z = r < 0.1f    ? std::numeric_limits<float>::infinity()
                          : r < 0.5f  ? plane
                          : r < 0.6f  ? plane * (1.0f + 4e-6f)  // a tie with the plane
                          : r < 0.75f ? plane * 1.05f           // a small step (depth line)
                          : r < 0.9f  ? plane * 1.5f            // a large step (silhouette)
                                      : 0.5f + 10.0f * unit();
                depth(x, y) = z;
                bool hit = z != std::numeric_limits<float>::infinity();
                normal(x, y) = hit ? normals[std::rand() % 4] : Vec3f(0.0f);
                object(x, y) = hit ? static_cast<std::uint32_t>(std::rand() % 3) : kNoIndex;
                material(x, y) = hit ? static_cast<std::uint32_t>(std::rand() % 3) : kNoIndex;
            }
    }
    [[nodiscard]] FineBuffers fine() const { return {depth, normal, object, material}; }
    ImageF depth;
    Image<Vec3f> normal;
    Image<std::uint32_t> object, material;
};

Image<std::uint8_t> random_seeds(int w, int h, float density, unsigned seed) {
    std::srand(seed);
    Image<std::uint8_t> seeds(w, h, 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            if (static_cast<float>(std::rand()) / static_cast<float>(RAND_MAX) < density)
                seeds(x, y) = static_cast<std::uint8_t>(1u << (std::rand() % 5));
    return seeds;
}

// resolve_lines as it was first written, pixel by pixel, with to_byte.
void reference_resolve(const Image<Vec3f>& fine_colour, const ImageF& squared_distance,
                       float thickness, int sub, const Vec3f& line_colour, ImageRgb8& final_image,
                       ImageRgb8& cel, ImageGray8& lines) {
    const int w = fine_colour.width() / sub, h = fine_colour.height() / sub;
    final_image.resize(w, h);
    cel.resize(w, h);
    lines.resize(w, h);
    const float reach = thickness > 0.0f ? thickness * 0.5f + 0.5f : 0.0f;
    const float reach2 = reach * reach;
    const float inv_n = 1.0f / static_cast<float>(sub * sub);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            Vec3f sum(0.0f);
            float covered = 0.0f;
            for (int j = 0; j < sub; ++j)
                for (int i = 0; i < sub; ++i) {
                    int fx = x * sub + i, fy = y * sub + j;
                    sum += fine_colour(fx, fy);
                    float d2 = squared_distance(fx, fy);
                    if (d2 < reach2) covered += std::min(1.0f, reach - std::sqrt(d2));
                }
            Vec3f colour = sum * inv_n;
            float a = covered * inv_n;
            Vec3f out = colour * (1.0f - a) + line_colour * a;
            final_image(x, y) = {to_byte(out.x), to_byte(out.y), to_byte(out.z)};
            cel(x, y) = {to_byte(colour.x), to_byte(colour.y), to_byte(colour.z)};
            lines(x, y) = to_byte(1.0f - a);
        }
}

// Exact squared distance to the nearest seed by looking at all of them; +inf for none.
float brute_force_squared_distance(const Image<std::uint8_t>& seeds, int x, int y) {
    float best = std::numeric_limits<float>::infinity();
    for (int sy = 0; sy < seeds.height(); ++sy)
        for (int sx = 0; sx < seeds.width(); ++sx)
            if (seeds(sx, sy))
                best =
                    std::min(best, static_cast<float>((sx - x) * (sx - x) + (sy - y) * (sy - y)));
    return best;
}

}  // namespace

TEST(RobustLines, SeedsMatchThePerPixelReference) {
    const int sizes[][2] = {{1, 1}, {1, 9}, {9, 1}, {2, 2}, {37, 23}, {64, 70}};
    unsigned seed = 1;
    int lines_found = 0;
    for (const auto& size : sizes)
        for (unsigned types : {unsigned(kLineAll), unsigned(kLineSilhouette | kLineDepth),
                               unsigned(kLineCrease), 0u})
            for (int threads : {1, 2, 3}) {
                RandomGBuffer g(size[0], size[1], ++seed);
                LineSettings settings;
                settings.types = types;
                Image<std::uint8_t> expected = reference_seeds(g.fine(), settings), seeds;
                find_line_seeds(g.fine(), settings, seeds, threads);
                ASSERT_EQ(seeds.width(), size[0]);
                ASSERT_EQ(seeds.height(), size[1]);
                for (int y = 0; y < size[1]; ++y)
                    for (int x = 0; x < size[0]; ++x) {
                        ASSERT_EQ(seeds(x, y), expected(x, y))
                            << x << "," << y << " in " << size[0] << "x" << size[1] << ", types "
                            << types;
                        lines_found += seeds(x, y) != 0;
                    }
            }
    EXPECT_GT(lines_found, 1000);  // the random images do exercise the tests
}

TEST(RobustLines, DistanceTransformMatchesBruteForce) {
    for (float density : {0.0f, 0.002f, 0.05f, 0.5f})
        for (int threads : {1, 2}) {
            Image<std::uint8_t> seeds = random_seeds(41, 29, density, 7 + threads);
            ImageF d;
            distance_to_seeds(seeds, d, threads);
            for (int y = 0; y < seeds.height(); ++y)
                for (int x = 0; x < seeds.width(); ++x)
                    ASSERT_EQ(d(x, y), brute_force_squared_distance(seeds, x, y)) << x << "," << y;
        }
}

TEST(RobustLines, BandedDistanceIsTheExactOneClamped) {
    unsigned seed = 100;
    for (float density : {0.0f, 0.001f, 0.01f, 0.1f, 0.6f})
        for (int band : {0, 1, 2, 3, 5, 9, kMaxDistanceBand})
            for (int threads : {1, 2}) {
                Image<std::uint8_t> seeds = random_seeds(150, 90, density, ++seed);
                ImageF exact;
                Image<std::uint16_t> banded;
                distance_to_seeds(seeds, exact, 1);
                distance_to_seeds_banded(seeds, band, banded, threads);
                const float clamp = static_cast<float>((band + 1) * (band + 1));
                for (int y = 0; y < seeds.height(); ++y)
                    for (int x = 0; x < seeds.width(); ++x)
                        ASSERT_EQ(static_cast<float>(banded(x, y)), std::min(exact(x, y), clamp))
                            << x << "," << y << " band " << band << " density " << density;
            }
    Image<std::uint8_t> seeds(4, 4, 0);
    Image<std::uint16_t> banded;
    EXPECT_THROW(distance_to_seeds_banded(seeds, -1, banded, 1), Error);
    EXPECT_THROW(distance_to_seeds_banded(seeds, kMaxDistanceBand + 1, banded, 1), Error);
}

TEST(RobustLines, ResolvingMatchesThePerPixelReference) {
    unsigned seed = 500;
    // Thicknesses from none through the usual to wider than kMaxDistanceBand (the fallback).
    for (float thickness : {0.0f, 0.5f, 1.0f, 2.0f, 4.0f, 7.3f, 8.0f, 300.0f})
        for (int sub = 1; sub <= 4; ++sub)
            for (int threads : {1, 2}) {
                const int w = 23, h = 17;
                Image<std::uint8_t> seeds = random_seeds(w * sub, h * sub, 0.01f, ++seed);
                // Colours partly outside [0, 1] (as with specular highlights), to test the clamp.
                Image<Vec3f> colour(w * sub, h * sub);
                for (std::size_t i = 0; i < colour.size(); ++i)
                    colour.data()[i] =
                        Vec3f(static_cast<float>(std::rand() % 1000) / 997.0f,
                              static_cast<float>(std::rand() % 2000) / 991.0f - 0.5f, 0.25f);
                const Vec3f line_colour(0.1f, 0.2f, 0.05f);
                ImageF distance;
                ImageRgb8 final_ref, cel_ref, final_a, cel_a, final_b, cel_b;
                ImageGray8 lines_ref, lines_a, lines_b;
                distance_to_seeds(seeds, distance, 1);
                reference_resolve(colour, distance, thickness, sub, line_colour, final_ref, cel_ref,
                                  lines_ref);
                resolve_lines(colour, distance, thickness, sub, line_colour, final_a, &cel_a,
                              &lines_a, threads);
                resolve_lines_from_seeds(colour, seeds, thickness, sub, line_colour, final_b,
                                         &cel_b, &lines_b, threads);
                // Without the feature outputs, the same final image.
                ImageRgb8 final_alone;
                resolve_lines_from_seeds(colour, seeds, thickness, sub, line_colour, final_alone,
                                         nullptr, nullptr, threads);
                ASSERT_EQ(final_alone.size(), final_b.size());
                ASSERT_EQ(0, std::memcmp(final_alone.data(), final_b.data(),
                                         final_b.size() * sizeof(Rgb8)));
                for (const ImageRgb8* image : {&final_a, &cel_a, &final_b, &cel_b}) {
                    ASSERT_EQ(image->width(), w);
                    ASSERT_EQ(image->height(), h);
                }
                for (int y = 0; y < h; ++y)
                    for (int x = 0; x < w; ++x) {
                        ASSERT_EQ(final_a(x, y), final_ref(x, y))
                            << x << "," << y << " thickness " << thickness;
                        ASSERT_EQ(cel_a(x, y), cel_ref(x, y));
                        ASSERT_EQ(lines_a(x, y), lines_ref(x, y))
                            << x << "," << y << " thickness " << thickness;
                        ASSERT_EQ(final_b(x, y), final_ref(x, y))
                            << x << "," << y << " thickness " << thickness;
                        ASSERT_EQ(cel_b(x, y), cel_ref(x, y));
                        ASSERT_EQ(lines_b(x, y), lines_ref(x, y))
                            << x << "," << y << " thickness " << thickness;
                    }
            }
}

TEST(RobustLines, SeedTypeImagesCountSamples) {
    for (int sub = 1; sub <= 4; ++sub)
        for (int threads : {1, 2}) {
            const int w = 19, h = 11;
            Image<std::uint8_t> seeds = random_seeds(w * sub, h * sub, 0.3f, 900 + sub);
            for (unsigned type :
                 {unsigned(kLineSilhouette), unsigned(kLineCrease), unsigned(kLineMaterial)}) {
                ImageGray8 out;
                resolve_seed_type(seeds, type, sub, out, threads);
                for (int y = 0; y < h; ++y)
                    for (int x = 0; x < w; ++x) {
                        int n = 0;
                        for (int j = 0; j < sub; ++j)
                            for (int i = 0; i < sub; ++i)
                                n += (seeds(x * sub + i, y * sub + j) & type) != 0;
                        const float inv_n = 1.0f / static_cast<float>(sub * sub);
                        ASSERT_EQ(out(x, y), to_byte(1.0f - static_cast<float>(n) * inv_n))
                            << x << "," << y << " sub " << sub;
                    }
            }
        }
}
