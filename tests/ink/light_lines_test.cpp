// Band and shadow lines (ink/light_lines.h) against the analytic answer: on a smooth sphere under
// a directional light each band boundary is a circle, and the sphere's shadow on a plane is an
// ellipse. The SVG's points must lie within 0.5 px of the projected curves, and rsvg-convert's
// drawing of the SVG must cover at least 99% of their visible length.

#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <string>
#include <vector>

#include "ink/ink_scenes.h"
#include "support/test_support.h"
#include "toonray/ink/ink.h"
#include "toonray/ink/light_lines.h"
#include "toonray/ink/svg.h"
#include "toonray/io/file.h"
#include "toonray/io/png.h"

using namespace toonray;

namespace {

using ink::Point2;

constexpr int kWidth = 800, kHeight = 600;

// The points of every path in the SVG group `group` (its `<g id="group">` up to its `</g>`).
std::vector<std::vector<Point2>> group_paths(const std::string& svg, const std::string& group) {
    std::vector<std::vector<Point2>> paths;
    const std::size_t start = svg.find("<g id=\"" + group + "\">");
    if (start == std::string::npos) return paths;
    const std::size_t end = svg.find("</g>", start);
    const std::string body = svg.substr(start, end - start);
    // Each path's d="..." and its numbers with a decimal point (the SVG writes every
    // coordinate so), read by hand: std::regex trips g++ 12's maybe-uninitialized warning in
    // the sanitizer build.
    for (std::size_t at = body.find("d=\""); at != std::string::npos; at = body.find("d=\"", at)) {
        at += 3;
        const std::size_t close = body.find('"', at);
        const std::string d = body.substr(at, close - at);
        at = close;
        std::vector<float> values;
        for (std::size_t i = 0; i < d.size();) {
            std::size_t j = i + (d[i] == '-' ? 1 : 0);
            if (j >= d.size() || !std::isdigit(static_cast<unsigned char>(d[j]))) {
                ++i;
                continue;
            }
            while (j < d.size() && std::isdigit(static_cast<unsigned char>(d[j]))) ++j;
            const bool decimal = j + 1 < d.size() && d[j] == '.' &&
                                 std::isdigit(static_cast<unsigned char>(d[j + 1]));
            if (decimal) {
                ++j;
                while (j < d.size() && std::isdigit(static_cast<unsigned char>(d[j]))) ++j;
                values.push_back(std::stof(d.substr(i, j - i)));
            }
            i = j;
        }
        std::vector<Point2> points;
        for (std::size_t i = 0; i + 1 < values.size(); i += 2)
            points.push_back({values[i], values[i + 1]});
        if (d.find('Z') != std::string::npos && !points.empty()) points.push_back(points.front());
        paths.push_back(points);
    }
    return paths;
}

double segment_distance(Point2 p, Point2 a, Point2 b) {
    const double dx = b.x - a.x, dy = b.y - a.y, len2 = dx * dx + dy * dy;
    double t = len2 > 0 ? ((p.x - a.x) * dx + (p.y - a.y) * dy) / len2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    return std::hypot(p.x - (a.x + dx * t), p.y - (a.y + dy * t));
}

// Distance from p to a polyline.
double polyline_distance(Point2 p, const std::vector<Point2>& line) {
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i + 1 < line.size(); ++i)
        best = std::min(best, segment_distance(p, line[i], line[i + 1]));
    if (line.size() == 1) best = std::hypot(p.x - line[0].x, p.y - line[0].y);
    return best;
}

// An analytic curve: its points densely, each with whether it is seen (front of the sphere, in
// the frame, not hidden).
struct Curve {
    std::vector<Point2> points;
    std::vector<bool> seen;
};

// Draws the SVG with rsvg-convert and returns its dark pixels.
std::vector<bool> rsvg_dark(const std::string& svg, const std::filesystem::path& dir,
                            const std::string& name) {
    EXPECT_EQ(std::system("rsvg-convert --version > /dev/null 2>&1"), 0)
        << "rsvg-convert (Debian librsvg2-bin) is not installed: bash scripts/install-deps.sh all";
    const auto svg_path = dir / (name + ".svg"), png_path = dir / (name + ".png");
    write_file_atomic(svg_path,
                      std::span(reinterpret_cast<const std::uint8_t*>(svg.data()), svg.size()));
    const std::string convert =
        "rsvg-convert -b white -o " + png_path.string() + " " + svg_path.string();
    EXPECT_EQ(std::system(convert.c_str()), 0) << convert;
    const DecodedPng png = read_png(png_path);
    std::vector<bool> dark(static_cast<std::size_t>(png.width) * png.height);
    for (int y = 0; y < png.height; ++y)
        for (int x = 0; x < png.width; ++x)
            dark[static_cast<std::size_t>(y) * png.width + x] = png.rgb(x, y)[0] < 128;
    return dark;
}

// The SVG's points against the curves (every point within 0.5 px of one of them), and the
// share of the curves' seen length that rsvg-convert draws dark within a pixel of.
void expect_svg_follows(const std::string& svg, const std::string& group,
                        const std::vector<Curve>& curves, const std::string& name) {
    const auto paths = group_paths(svg, group);
    ASSERT_FALSE(paths.empty()) << name << ": no paths in " << group;
    double worst = 0.0;
    long points = 0;
    for (const auto& path : paths)
        for (const Point2& p : path) {
            double best = std::numeric_limits<double>::infinity();
            for (const Curve& c : curves) best = std::min(best, polyline_distance(p, c.points));
            if (best > 0.5 && worst <= 0.5) {
                std::printf("%s: the point (%.3f, %.3f) is %.3f px from every curve; its path:",
                            name.c_str(), p.x, p.y, best);
                for (const Point2& q : path) std::printf(" (%.1f %.1f)", q.x, q.y);
                std::printf("\n");
            }
            worst = std::max(worst, best);
            ++points;
        }
    test_support::TempDir dir(name);
    const std::vector<bool> dark = rsvg_dark(svg, dir.path, name);
    double seen = 0.0, covered = 0.0;
    for (const Curve& c : curves)
        for (std::size_t i = 0; i + 1 < c.points.size(); ++i) {
            if (!c.seen[i] || !c.seen[i + 1]) continue;
            const Point2 a = c.points[i], b = c.points[i + 1];
            const double length = std::hypot(b.x - a.x, b.y - a.y);
            const Point2 m{(a.x + b.x) * 0.5f, (a.y + b.y) * 0.5f};
            bool found = false;
            for (int dy = -1; dy <= 1 && !found; ++dy)
                for (int dx = -1; dx <= 1 && !found; ++dx) {
                    const int x = static_cast<int>(std::floor(m.x)) + dx,
                              y = static_cast<int>(std::floor(m.y)) + dy;
                    found = x >= 0 && y >= 0 && x < kWidth && y < kHeight &&
                            dark[static_cast<std::size_t>(y) * kWidth + x];
                }
            seen += length;
            covered += found ? length : 0.0;
        }
    std::printf(
        "%s: %ld SVG points, the farthest %.3f px from its curve; rsvg covers %.3f%% of %.0f px seen\n",
        name.c_str(), points, worst, 100.0 * covered / seen, seen);
    EXPECT_LE(worst, 0.5) << name;
    EXPECT_GE(covered / seen, 0.99) << name;
}

struct SphereView {
    Scene scene;
    TriangleAccel accel;
    CameraSpec camera;
    ink::ScreenProjection view;
};

}  // namespace

TEST(LightLines, BandBoundariesOnASphereAreItsCircles) {
    SphereView s;
    test_support::add_sphere(s.scene, Vec3f(0.0f), 1.0f, 96, 192);
    s.accel.build(s.scene.positions, s.scene.tri_positions);
    s.camera = {{0.4f, 0.6f, 3.0f}, {0, 0, 0}, {0, 1, 0}};
    const ink::ScreenProjection view(make_view_plane(s.camera, kWidth, kHeight), kWidth, kHeight);
    const Vec3f travel = normalize(Vec3f(1.0f, -0.4f, -0.5f));
    const std::vector<Light> lights{{Light::Kind::Directional, travel, 1.0f}};
    const std::vector<float> thresholds{0.25f, 0.5f};
    ink::InkSettings settings;
    settings.edges.silhouettes = settings.edges.borders = settings.edges.creases = false;
    settings.edges.materials = settings.edges.intersections = false;
    settings.bands = true;
    settings.lights = lights;
    settings.band_thresholds = thresholds;
    ink::InkLines lines;
    ink::draw_ink_lines(s.scene, s.accel, s.camera, kWidth, kHeight, settings, 2, lines);
    // Circles p.l = c on the unit sphere, l toward the light, for c = 0 (the terminator) and
    // each threshold; seen where the sphere faces the eye.
    const Vec3f l = -travel, u = normalize(cross(l, Vec3f(0, 1, 0))), v = cross(l, u);
    const Vec3f eye = s.camera.eye;
    std::vector<Curve> curves;
    for (float c : {0.0f, 0.25f, 0.5f}) {
        Curve curve;
        const float r = std::sqrt(1.0f - c * c);
        for (int i = 0; i <= 8192; ++i) {
            const float a = 2.0f * std::numbers::pi_v<float> * static_cast<float>(i) / 8192.0f;
            const Vec3f p = l * c + (u * std::cos(a) + v * std::sin(a)) * r;
            const Point2 q = view.project(p);
            curve.points.push_back(q);
            // Clear of the silhouette, where a line turns away along the view.
            const float facing = dot(p, normalize(eye - p));
            curve.seen.push_back(facing > 0.05f && q.x >= 2 && q.y >= 2 && q.x < kWidth - 2 &&
                                 q.y < kHeight - 2);
        }
        curves.push_back(curve);
    }
    ink::SvgSettings svg;
    svg.width = kWidth;
    svg.height = kHeight;
    svg.thickness = ink::stroke_thickness(settings.width, kHeight);
    svg.pens = lines.pens;
    expect_svg_follows(ink::svg_text(lines.strokes, svg), "visible-band", curves, "band_sphere");
}

TEST(LightLines, ASpheresShadowOnAPlaneIsItsEllipse) {
    SphereView s;
    const Vec3f centre(0.0f, 0.2f, 0.0f);
    test_support::add_sphere(s.scene, centre, 1.0f, 96, 192);
    const float floor_y = -1.2f;
    test_support::add_quad(s.scene, {-6, floor_y, -6}, {-6, floor_y, 6}, {6, floor_y, 6},
                           {6, floor_y, -6}, 0, 1);
    s.scene.objects.push_back("floor");
    s.accel.build(s.scene.positions, s.scene.tri_positions);
    s.camera = {{0.4f, 2.6f, 4.2f}, {0.6f, -1.0f, 0.6f}, {0, 1, 0}};
    const ink::ScreenProjection view(make_view_plane(s.camera, kWidth, kHeight), kWidth, kHeight);
    const Vec3f travel = normalize(Vec3f(0.6f, -1.0f, 0.5f));
    const std::vector<Light> lights{{Light::Kind::Directional, travel, 1.0f}};
    ink::InkSettings settings;
    settings.edges.silhouettes = settings.edges.borders = settings.edges.creases = false;
    settings.edges.materials = settings.edges.intersections = false;
    settings.shadows = true;
    settings.lights = lights;
    ink::InkLines lines;
    ink::draw_ink_lines(s.scene, s.accel, s.camera, kWidth, kHeight, settings, 2, lines);
    // The sphere's outline seen along the light, carried along it onto the floor.
    const Vec3f u = normalize(cross(travel, Vec3f(1, 0, 0))), v = cross(travel, u);
    const Vec3f eye = s.camera.eye;
    Curve ellipse;
    for (int i = 0; i <= 8192; ++i) {
        const float a = 2.0f * std::numbers::pi_v<float> * static_cast<float>(i) / 8192.0f;
        const Vec3f q = centre + (u * std::cos(a) + v * std::sin(a));
        const Vec3f p = q + travel * ((floor_y - q.y) / travel.y);
        const Point2 image = view.project(p);
        ellipse.points.push_back(image);
        // Seen unless the sphere is in the way (kept a little clear of its outline).
        const Vec3f d = normalize(p - eye), oc = eye - centre;
        const float b = dot(oc, d), disc = b * b - (dot(oc, oc) - 1.0f);
        const bool behind_sphere = disc > -0.05f && -b > 0.0f;
        ellipse.seen.push_back(!behind_sphere && image.x >= 2 && image.y >= 2 &&
                               image.x < kWidth - 2 && image.y < kHeight - 2);
    }
    ink::SvgSettings svg;
    svg.width = kWidth;
    svg.height = kHeight;
    svg.thickness = ink::stroke_thickness(settings.width, kHeight);
    svg.pens = lines.pens;
    expect_svg_follows(ink::svg_text(lines.strokes, svg), "visible-shadow", {ellipse},
                       "shadow_ellipse");
}

TEST(LightLines, AreTheSameForEveryThreadCount) {
    Scene scene;
    test_support::add_sphere(scene, Vec3f(0.0f, 0.2f, 0.0f), 1.0f, 32, 64);
    test_support::add_quad(scene, {-6, -1.2f, -6}, {-6, -1.2f, 6}, {6, -1.2f, 6}, {6, -1.2f, -6});
    TriangleAccel accel;
    accel.build(scene.positions, scene.tri_positions);
    const CameraSpec camera{{0.5f, 4.0f, 6.0f}, {0.0f, -0.8f, 0.0f}, {0, 1, 0}};
    const std::vector<Light> lights{{Light::Kind::Point, {3.0f, 5.0f, 2.0f}, 1.0f}};
    const std::vector<float> thresholds{0.25f, 0.5f};
    ink::InkSettings settings;
    settings.bands = settings.shadows = true;
    settings.lights = lights;
    settings.band_thresholds = thresholds;
    ink::InkLines one, two;
    ink::draw_ink_lines(scene, accel, camera, 400, 300, settings, 1, one);
    ink::draw_ink_lines(scene, accel, camera, 400, 300, settings, 2, two);
    ink::SvgSettings svg;
    svg.width = 400;
    svg.height = 300;
    const std::string a = ink::svg_text(one.strokes, svg), b = ink::svg_text(two.strokes, svg);
    EXPECT_EQ(a, b);
    EXPECT_FALSE(group_paths(a, "visible-band").empty());
    EXPECT_FALSE(group_paths(a, "visible-shadow").empty());
}
