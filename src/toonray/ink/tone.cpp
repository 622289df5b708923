#include "toonray/ink/tone.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <fmt/format.h>
#include <numbers>

#include "toonray/core/error.h"
#include "toonray/core/parse.h"
#include "toonray/core/portable_math.h"
#include "toonray/ink/chunks.h"
#include "toonray/ink/light_lines.h"

namespace toonray::ink {

std::string_view tone_mode_name(ToneMode mode) {
    switch (mode) {
        case ToneMode::Cel: return "cel";
        case ToneMode::Hatch: return "hatch";
        case ToneMode::Screentone: return "screentone";
    }
    return "cel";
}

ToneMode parse_tone_mode(std::string_view text) {
    for (ToneMode mode : {ToneMode::Cel, ToneMode::Hatch, ToneMode::Screentone})
        if (text == tone_mode_name(mode)) return mode;
    throw Error(fmt::format("unknown tone '{}' (cel, hatch or screentone)", text));
}

std::string_view tone_anchor_name(ToneAnchor anchor) {
    return anchor == ToneAnchor::Screen ? "screen" : "object";
}

ToneAnchor parse_tone_anchor(std::string_view text) {
    if (text == "object") return ToneAnchor::Object;
    if (text == "screen") return ToneAnchor::Screen;
    throw Error(fmt::format("unknown tone anchor '{}' (object or screen)", text));
}

HatchDirection parse_hatch_direction(std::string_view text) {
    using Kind = HatchDirection::Kind;
    HatchDirection d;
    if (text == "curvature") return d;
    if (text == "light" || text == "screen") {
        d.kind = text == "light" ? Kind::Light : Kind::Screen;
        return d;
    }
    d.kind = Kind::Axis;
    if (text == "x" || text == "y" || text == "z") {
        d.axis =
            Vec3f(text == "x" ? 1.0f : 0.0f, text == "y" ? 1.0f : 0.0f, text == "z" ? 1.0f : 0.0f);
        return d;
    }
    if (text.find(',') == std::string_view::npos)
        throw Error(fmt::format(
            "unknown hatch direction '{}' (curvature, light, screen, x, y, z or X,Y,Z)", text));
    const Vec3f v = parse_vec3(text, "hatch direction");
    const float len = length(v);
    if (!(len > 0.0f) || !std::isfinite(len))
        throw Error(fmt::format("hatch direction '{}': the vector must not be zero", text));
    d.axis = v;  // as given, so that it writes back to the same text
    return d;
}

std::string format_hatch_direction(const HatchDirection& d) {
    using Kind = HatchDirection::Kind;
    switch (d.kind) {
        case Kind::Curvature: return "curvature";
        case Kind::Light: return "light";
        case Kind::Screen: return "screen";
        case Kind::Axis: break;
    }
    if (d.axis == Vec3f(1, 0, 0)) return "x";
    if (d.axis == Vec3f(0, 1, 0)) return "y";
    if (d.axis == Vec3f(0, 0, 1)) return "z";
    return format_vec3(d.axis);
}

std::array<float, kHatchFamilies> hatch_shares(float darkness, float coverage, float opacity) {
    std::array<float, kHatchFamilies> out{};
    if (!(coverage > 0.0f) || !(opacity > 0.0f)) return out;
    const float d = std::clamp(darkness / opacity, 0.0f, 1.0f);
    const float most = std::min(coverage, 1.0f);
    float left = 1.0f;  // the share of the surface no earlier family covers
    for (int k = 0; k < kHatchFamilies && left > 0.0f; ++k) {
        const float c = std::clamp(1.0f - (1.0f - d) / left, 0.0f, most);
        out[static_cast<std::size_t>(k)] = c / coverage;
        left *= 1.0f - c;
    }
    return out;
}

double plane_rank(std::int64_t k) {
    // Of |K|: below 2^53 every bit counts, so r(2K) = r(K) / 2 exactly (two's complement
    // negatives would have their endless ones cut); the planes are mirrored about plane 0.
    std::uint64_t r = k < 0 ? 0 - static_cast<std::uint64_t>(k) : static_cast<std::uint64_t>(k);
    // Bits reversed: halves, then quarters, ... swapped.
    r = (r >> 32) | (r << 32);
    r = ((r >> 16) & 0x0000ffff0000ffffull) | ((r & 0x0000ffff0000ffffull) << 16);
    r = ((r >> 8) & 0x00ff00ff00ff00ffull) | ((r & 0x00ff00ff00ff00ffull) << 8);
    r = ((r >> 4) & 0x0f0f0f0f0f0f0f0full) | ((r & 0x0f0f0f0f0f0f0f0full) << 4);
    r = ((r >> 2) & 0x3333333333333333ull) | ((r & 0x3333333333333333ull) << 2);
    r = ((r >> 1) & 0x5555555555555555ull) | ((r & 0x5555555555555555ull) << 1);
    // The top 53 bits exactly.
    return std::ldexp(static_cast<double>(r >> 11), -53);
}

float drawn_disc_radius(float area) {
    if (!(area > 0.0f)) return 0.0f;
    constexpr float pi = std::numbers::pi_v<float>;
    if (area >= pi / 3.0f) return std::sqrt(area / pi - 1.0f / 12.0f);
    return portable::pow(3.0f * area / pi, 1.0f / 3.0f) - 0.5f;
}

namespace {

// ---- Families of slicing planes ------------------------------------------------------------

// u(p) = dot(p - origin, along) / (dot(p - origin, depth) + depth0): a world coordinate along a
// direction (depth 0, depth0 1) or an image coordinate (the plane through the eye and an image
// line, origin the eye, depth the image plane's normal, depth0 0). Its planes u = K spacing
// are the slices; with corners' (numerator, denominator) a slice's crossing of an edge is where
// numerator - c denominator changes sign, exactly linear along the edge.
struct Slicing {
    Vec3f origin, along, depth;
    float depth0 = 1.0f;
    bool screen = false;
    std::uint32_t tag = 0;  // family (and fallback) bits of the endpoint keys

    void values(const Vec3f& p, double& num, double& den) const {
        const Vec3f d = p - origin;
        num = static_cast<double>(d.x) * along.x + static_cast<double>(d.y) * along.y +
              static_cast<double>(d.z) * along.z;
        den = screen ? static_cast<double>(d.x) * depth.x + static_cast<double>(d.y) * depth.y +
                           static_cast<double>(d.z) * depth.z
                     : 1.0;
    }
};

Vec3f perpendicular(const Vec3f& a) {
    // The world axis least along a, crossed with it.
    const Vec3f ax(std::abs(a.x), std::abs(a.y), std::abs(a.z));
    const Vec3f e = ax.x <= ax.y && ax.x <= ax.z ? Vec3f(1, 0, 0)
                    : ax.y <= ax.z               ? Vec3f(0, 1, 0)
                                                 : Vec3f(0, 0, 1);
    return normalize(cross(a, e));
}

// Eigenvectors of a symmetric 3x3 matrix by cyclic Jacobi rotations (IEEE operations only):
// columns of v, eigenvalues in w.
void symmetric_eigen(double a[3][3], double v[3][3], double w[3]) {
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) v[i][j] = i == j ? 1.0 : 0.0;
    for (int sweep = 0; sweep < 50; ++sweep) {
        const double off = std::abs(a[0][1]) + std::abs(a[0][2]) + std::abs(a[1][2]);
        const double scale = std::abs(a[0][0]) + std::abs(a[1][1]) + std::abs(a[2][2]);
        if (!(off > 1e-15 * scale)) break;
        for (int p = 0; p < 2; ++p)
            for (int q = p + 1; q < 3; ++q) {
                if (a[p][q] == 0.0) continue;
                const double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                const double t =
                    (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
                const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
                for (int k = 0; k < 3; ++k) {  // a = a J (columns p and q)
                    const double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; ++k) {  // a = J^T a (rows p and q)
                    const double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for (int k = 0; k < 3; ++k) {
                    const double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = c * vkp - s * vkq;
                    v[k][q] = s * vkp + c * vkq;
                }
            }
    }
    for (int i = 0; i < 3; ++i) w[i] = a[i][i];
}

// A unit vector with a sign fixed by its largest component (eigenvectors have none).
Vec3f signed_unit(double x, double y, double z) {
    const double ax = std::abs(x), ay = std::abs(y), az = std::abs(z);
    const double big = ax >= ay && ax >= az ? x : (ay >= az ? y : z);
    const Vec3f v(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
    return normalize(big < 0 ? -v : v);
}

// An object's frame for object-anchored tone: where its planes are counted from (its first
// triangle's first corner, which moves with it) and three orthonormal axes e1, e2, e3; the
// families' plane normals are e1, e2, and two diagonals out of their plane.
struct ObjectFrame {
    Vec3f origin;
    Vec3f e[3]{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    bool seen = false;
};

std::vector<ObjectFrame> object_frames(const ToneContext& c) {
    using Kind = HatchDirection::Kind;
    const Scene& scene = c.scene;
    std::size_t objects = scene.objects.size();
    for (std::size_t t = 0; t < scene.triangle_count(); ++t)
        objects = std::max<std::size_t>(objects, scene.tri_object[t] + std::size_t{1});
    std::vector<ObjectFrame> frames(objects);
    std::vector<std::array<double, 6>> covariance(objects, std::array<double, 6>{});
    std::vector<std::array<double, 4>> centroid(objects, std::array<double, 4>{});
    for (std::size_t t = 0; t < scene.triangle_count(); ++t) {
        const auto& v = scene.tri_positions[t];
        const Vec3f p0 = scene.positions[v[0]], p1 = scene.positions[v[1]],
                    p2 = scene.positions[v[2]];
        const Vec3f n = cross(p1 - p0, p2 - p0);
        const float area2 = length(n);
        if (!(area2 > 0.0f) || !std::isfinite(area2)) continue;
        ObjectFrame& f = frames[scene.tri_object[t]];
        if (!f.seen) {
            f.seen = true;
            f.origin = p0;
        }
        // Area-weighted: n n^T / |n| = area2 (n/|n|)(n/|n|)^T.
        const double x = n.x, y = n.y, z = n.z, w = 1.0 / area2;
        auto& cv = covariance[scene.tri_object[t]];
        cv[0] += x * x * w;
        cv[1] += y * y * w;
        cv[2] += z * z * w;
        cv[3] += x * y * w;
        cv[4] += x * z * w;
        cv[5] += y * z * w;
        auto& ce = centroid[scene.tri_object[t]];
        const Vec3f m = (p0 + p1 + p2) / 3.0f;
        ce[0] += m.x * static_cast<double>(area2);
        ce[1] += m.y * static_cast<double>(area2);
        ce[2] += m.z * static_cast<double>(area2);
        ce[3] += area2;
    }
    const HatchDirection& dir = c.settings.direction;
    for (std::size_t o = 0; o < objects; ++o) {
        ObjectFrame& f = frames[o];
        if (!f.seen) continue;
        Vec3f e1, e2;
        switch (dir.kind) {
            case Kind::Curvature: {
                const auto& cv = covariance[o];
                double a[3][3] = {
                    {cv[0], cv[3], cv[4]}, {cv[3], cv[1], cv[5]}, {cv[4], cv[5], cv[2]}};
                double v[3][3], w[3];
                symmetric_eigen(a, v, w);
                int lo = 0, hi = 0;
                for (int i = 1; i < 3; ++i) {
                    if (w[i] < w[lo]) lo = i;
                    if (w[i] > w[hi]) hi = i;
                }
                if (lo == hi) hi = (lo + 1) % 3;
                e1 = signed_unit(v[0][lo], v[1][lo], v[2][lo]);
                e2 = signed_unit(v[0][hi], v[1][hi], v[2][hi]);
                // Orthogonal to the float rounding of e1.
                e2 = normalize(e2 - e1 * dot(e1, e2));
                break;
            }
            case Kind::Light: {
                Vec3f l(0, 1, 0);
                if (!c.lights.empty()) {
                    const Light& light = c.lights[0];
                    const auto& ce = centroid[o];
                    const Vec3f middle(static_cast<float>(ce[0] / ce[3]),
                                       static_cast<float>(ce[1] / ce[3]),
                                       static_cast<float>(ce[2] / ce[3]));
                    const Vec3f v = light.kind == Light::Kind::Directional ? light.vector
                                                                           : middle - light.vector;
                    if (length(v) > 0.0f) l = normalize(v);
                }
                e1 = l;
                e2 = perpendicular(l);
                break;
            }
            case Kind::Axis:
                e1 = normalize(dir.axis);
                e2 = perpendicular(e1);
                break;
            case Kind::Screen: {
                const float a = c.settings.angle * std::numbers::pi_v<float> / 180.0f;
                const float cs = portable::cos(a), sn = portable::sin(a);
                // The normal of strokes at angle a on the image (y down) in the world.
                e1 = normalize(c.plane.right * sn - c.plane.up * cs);
                e2 = normalize(c.plane.right * cs + c.plane.up * sn);
                break;
            }
        }
        f.e[0] = e1;
        f.e[1] = e2;
        f.e[2] = normalize(cross(e1, e2));
    }
    return frames;
}

// The plane normal of family k in a frame (before any fallback).
Vec3f family_normal(const ObjectFrame& f, int k) {
    if (k < 2) return f.e[k];
    return normalize(f.e[0] + f.e[1] * (k == 2 ? 1.0f : -1.0f) + f.e[2]);
}

// The image normal of screen family k: strokes at the tone angle, the crossing one 90 degrees
// on, then the diagonals.
Point2 screen_normal(float angle_degrees, int k) {
    static constexpr float kTurn[kHatchFamilies] = {0.0f, 90.0f, 45.0f, -45.0f};
    const float a = (angle_degrees + kTurn[k]) * std::numbers::pi_v<float> / 180.0f;
    // Strokes along (cos a, -sin a) on the image (y down): their normal.
    return {portable::sin(a), portable::cos(a)};
}

// ---- Per triangle --------------------------------------------------------------------------

// A triangle being sliced: its corners, welded ids, and what the image gradient of u needs.
struct TriangleView {
    std::uint32_t prim = 0;
    Vec3f p[3];
    std::uint32_t welded[3];
    Vec3f normal, b1, b2;  // unit: the face normal and an orthonormal basis of its plane
    Point2 image[3];
};

// Pixels between samples along a slice: where it is drawn changes with the band and smoothly
// with the surface's slope, each change bisected.
constexpr float kToneStep = 2.0f;
// Triangles at most this wide on the image are small: their diffuse term is interpolated from
// their corners when bands follow corners (ToneShading::bands_follow_corners; a point light's
// diffuse term on a larger face may peak inside it), and the slope of the surface on the image
// changes little across them.
constexpr float kSmallTriangle = 64.0f;
// Along a slice on a larger triangle the band is found every this many samples, and between two
// that differ: a band narrower than that between two of one band is not seen. Without toon
// shadows bands are the diffuse term's, whose boundaries are smooth curves: farther apart.
constexpr int kCoarseBandShadows = 4, kCoarseBand = 16;
constexpr float kTonePrecision = 1.0f / 16;  // pixels: where a slice's presence changes
// Below this in-plane share of a family's normal a face is taken as parallel to its planes
// (a box's faces along its axes), and the family slices it across the frame's third axis.
constexpr float kParallel = 0.01f;

struct Slicer {
    const ToneContext& c;
    const ScreenProjection& view;
    float g;      // spacing in pixels
    double s;     // plane spacing in u
    bool screen;  // screen-anchored: u is an image coordinate

    // |grad u| on the image at p (world per pixel), for u along `along` on the triangle's
    // plane; 0 where the triangle is seen edge on.
    [[nodiscard]] float gradient(const TriangleView& tri, const Vec3f& along,
                                 const Vec3f& p) const {
        const Vec3f d = p - view.eye();
        const float sn = dot(d, view.normal());
        if (!(sn > 0.0f)) return std::numeric_limits<float>::infinity();
        const float k = view.plane_distance() / sn;
        auto image_step = [&](const Vec3f& v) {
            const Vec3f dr = (v - d * (dot(v, view.normal()) / sn)) * k;
            return Point2{dot(dr, view.dual_x()), dot(dr, view.dual_y())};
        };
        const Point2 j1 = image_step(tri.b1), j2 = image_step(tri.b2);
        const float g1 = dot(along, tri.b1), g2 = dot(along, tri.b2);
        const float det = j1.x * j2.y - j1.y * j2.x;
        if (det == 0.0f) return std::numeric_limits<float>::infinity();
        const float gx = (j2.y * g1 - j1.y * g2) / det, gy = (-j2.x * g1 + j1.x * g2) / det;
        return portable::hypot(gx, gy);
    }

    // q at p for a share f of the family: the largest rank drawn there.
    [[nodiscard]] double reach(float share, const TriangleView& tri, const Vec3f& along,
                               const Vec3f& p) const {
        if (!(share > 0.0f)) return 0.0;
        if (screen) return share;
        const float grad = gradient(tri, along, p);
        if (!(grad > 0.0f) || !std::isfinite(grad)) return 0.0;
        return static_cast<double>(share) * s / (static_cast<double>(g) * grad);
    }
};

// The slicing of family k on a triangle: screen families are the image's; object families are
// the object's frame's, unless the face is parallel to their planes.
Slicing triangle_slicing(const ToneContext& c, const ObjectFrame& frame, const TriangleView& tri,
                         int k, Vec3f& along) {
    Slicing sl;
    if (c.settings.anchored() == ToneAnchor::Screen) {
        const ScreenProjection& v = c.view;
        const Point2 m = screen_normal(c.settings.angle, k);
        const Vec3f mm = v.dual_x() * m.x + v.dual_y() * m.y;
        sl.origin = v.eye();
        sl.along = v.normal() * dot(v.eye() - v.upper_left(), mm) + mm * v.plane_distance();
        sl.depth = v.normal();
        sl.depth0 = 0.0f;
        sl.screen = true;
        sl.tag = static_cast<std::uint32_t>(k) << 28;
        along = Vec3f(0.0f);
        return sl;
    }
    Vec3f a = family_normal(frame, k);
    bool fallback = false;
    if (length(a - tri.normal * dot(a, tri.normal)) < kParallel) {
        a = frame.e[2];
        fallback = true;
        if (length(a - tri.normal * dot(a, tri.normal)) < kParallel) a = frame.e[k == 0 ? 1 : 0];
    }
    sl.origin = frame.origin;
    sl.along = a;
    sl.tag = static_cast<std::uint32_t>(k) << 28 | (fallback ? 1u << 31 : 0u);
    along = a;
    return sl;
}

// The crossing of the slice `value` with the triangle's edges: its two ends (points, their
// barycentrics and keys), when it crosses it.
struct SliceSegment {
    Vec3f p[2];
    Vec2f bary[2];
    EndpointKey key[2];
};

bool slice_triangle(const TriangleView& tri, const double num[3], const double den[3], double value,
                    std::uint32_t tag, SliceSegment& out) {
    static constexpr Vec2f kCornerBary[3] = {{0.0f, 0.0f}, {1.0f, 0.0f}, {0.0f, 1.0f}};
    double h[3];
    for (int i = 0; i < 3; ++i) h[i] = num[i] - value * den[i];
    int found = 0;
    for (int e = 0; e < 3; ++e) {
        int a = e, b = (e + 1) % 3;
        if ((h[a] >= 0) == (h[b] >= 0)) continue;
        // From the lower welded id, so that both triangles of an edge find the same bits.
        if (tri.welded[b] < tri.welded[a]) std::swap(a, b);
        const float t = static_cast<float>(h[a] / (h[a] - h[b]));
        out.p[found] = tri.p[a] + (tri.p[b] - tri.p[a]) * t;
        out.bary[found] = {kCornerBary[a].x + (kCornerBary[b].x - kCornerBary[a].x) * t,
                           kCornerBary[a].y + (kCornerBary[b].y - kCornerBary[a].y) * t};
        out.key[found] = {tri.welded[a], tri.welded[b], tag};
        if (++found == 2) break;
    }
    return found == 2 && out.p[0] != out.p[1];
}

// The triangle's corners and image, or false when it cannot be seen (behind the eye, off the
// image, degenerate).
bool view_triangle(const ToneContext& c, std::span<const std::int8_t> outward, std::uint32_t t,
                   float margin, TriangleView& tri) {
    const Scene& scene = c.scene;
    const ScreenProjection& view = c.view;
    tri.prim = t;
    for (int i = 0; i < 3; ++i) {
        tri.p[i] = scene.positions[scene.tri_positions[t][i]];
        tri.welded[i] = c.mesh.tri_vertices[t][i];
    }
    const Vec3f e1 = tri.p[1] - tri.p[0];
    const Vec3f n = cross(e1, tri.p[2] - tri.p[0]);
    const float len = length(n), len1 = length(e1);
    if (!(len > 0.0f) || !std::isfinite(len) || !(len1 > 0.0f)) return false;
    tri.normal = n / len;
    // Turned away on a closed solid: behind its front.
    const std::uint32_t object = scene.tri_object[t];
    if (object < outward.size() && outward[object] != 0 &&
        dot(tri.normal, view.eye() - tri.p[0]) * static_cast<float>(outward[object]) < 0.0f)
        return false;
    float lo_x = std::numeric_limits<float>::infinity(), lo_y = lo_x, hi_x = -lo_x, hi_y = -lo_x;
    for (int i = 0; i < 3; ++i) {
        if (!(view.depth(tri.p[i]) > view.near_depth())) return false;
        tri.image[i] = view.project(tri.p[i]);
        lo_x = std::min(lo_x, tri.image[i].x);
        hi_x = std::max(hi_x, tri.image[i].x);
        lo_y = std::min(lo_y, tri.image[i].y);
        hi_y = std::max(hi_y, tri.image[i].y);
    }
    if (!(hi_x >= -margin && lo_x <= static_cast<float>(c.width) + margin && hi_y >= -margin &&
          lo_y <= static_cast<float>(c.height) + margin))
        return false;
    tri.b1 = e1 / len1;
    tri.b2 = cross(tri.normal, tri.b1);
    return true;
}

// 2^m for m in [0, 1023], exactly, without a call to ldexp.
double power_of_two(int m) {
    return std::bit_cast<double>(static_cast<std::uint64_t>(1023 + m) << 52);
}

// The exponent of the power of two at most q (q > 0): q in [2^e, 2^(e+1)).
int floor_log2(double q) {
    int e = 0;
    static_cast<void>(std::frexp(q, &e));  // q = m 2^e, m in [0.5, 1)
    return e - 1;
}

// The plane spacing of object-anchored slices: far below a pixel anywhere in the scene (a
// power of two 2^-24 of its size), so that q stays below 1; the strokes drawn do not depend on
// it (tone.h).
double object_plane_spacing(const Scene& scene) {
    const BBox b = scene.bounds();
    const Vec3f d = b.hi - b.lo;
    const double size = std::max(
        {static_cast<double>(d.x), static_cast<double>(d.y), static_cast<double>(d.z), 1e-30});
    if (!std::isfinite(size)) return 1.0;
    return std::ldexp(1.0, floor_log2(size) - 24);
}

}  // namespace

std::vector<FeatureSegment> hatch_segments(const ToneContext& c, int threads) {
    const Scene& scene = c.scene;
    const bool screen = c.settings.anchored() == ToneAnchor::Screen;
    const float g = std::max(c.settings.spacing * static_cast<float>(c.height) / 720.0f, 0.25f);
    const Slicer slicer{c, c.view, g, screen ? static_cast<double>(g) : object_plane_spacing(scene),
                        screen};
    const std::vector<ObjectFrame> frames = screen ? std::vector<ObjectFrame>{} : object_frames(c);
    // The largest share of each family any band of each pen asks for.
    std::vector<std::array<float, kHatchFamilies>> most(c.pens.size());
    for (std::size_t i = 0; i < c.pens.size(); ++i)
        for (const auto& band : c.pens[i].share)
            for (int k = 0; k < kHatchFamilies; ++k)
                most[i][static_cast<std::size_t>(k)] = std::max(
                    most[i][static_cast<std::size_t>(k)], band[static_cast<std::size_t>(k)]);
    const int count = static_cast<int>(scene.triangle_count());
    const bool follow = c.shading.bands_follow_corners();
    const int coarse_stride = follow ? kCoarseBand : kCoarseBandShadows;
    const std::vector<std::int8_t> outward = outward_objects(scene, c.closed, c.view.eye());
    return gather_chunks<
        FeatureSegment>(count, 64, threads, [&](int t0, int t1, std::vector<FeatureSegment>& out) {
        TriangleView tri;
        std::vector<std::uint8_t> states, coarse, drawn_at;
        std::vector<float> cuts;
        for (int ti = t0; ti < t1; ++ti) {
            const auto t = static_cast<std::uint32_t>(ti);
            const std::uint16_t pen_index = c.pen_of_triangle[t];
            const TonePen& pen = c.pens[pen_index];
            if (!pen.draw) continue;
            if (!view_triangle(c, outward, t, g, tri)) continue;
            static const ObjectFrame kScreen;
            const ObjectFrame& frame = screen ? kScreen : frames[scene.tri_object[t]];
            float diameter = 0.0f;
            for (int i = 0; i < 3; ++i)
                diameter =
                    std::max(diameter, portable::hypot(tri.image[i].x - tri.image[(i + 1) % 3].x,
                                                       tri.image[i].y - tri.image[(i + 1) % 3].y));
            const bool small = diameter <= kSmallTriangle;
            // When bands follow the diffuse term: each corner's normal as shading interpolates
            // it (its vertex normal, else the face's), turned with the face toward the eye, and
            // the diffuse term from it. A small triangle's diffuse term is interpolated from its
            // corners; a large one's found where it is needed. One band throughout where a small
            // triangle's corners agree, whose shares alone are drawn (most triangles of a lit
            // surface draw nothing).
            const bool interpolated = follow && small;
            Vec3f corner_normal[3];
            float corner[3] = {};
            int uniform = -1;
            if (follow) {
                const auto& tn = scene.tri_normals[t];
                bool smooth = true;
                for (std::uint32_t n : tn)
                    smooth = smooth && n != kNoIndex && n < scene.normals.size();
                const bool flip = dot(tri.normal, c.view.eye() - tri.p[0]) < 0.0f;
                std::uint8_t band[3];
                for (int i = 0; i < 3; ++i) {
                    Vec3f& n = corner_normal[i];
                    n = smooth ? normalize(scene.normals[tn[i]]) : tri.normal;
                    if (flip) n = -n;
                    corner[i] = diffuse_light(c.lights, tri.p[i], n);
                    band[i] = band_of(c.band_thresholds, corner[i]);
                }
                if (small && band[0] == band[1] && band[1] == band[2] && band[0] < pen.share.size())
                    uniform = band[0];
            }
            for (int k = 0; k < kHatchFamilies; ++k) {
                const float top =
                    uniform >= 0
                        ? pen.share[static_cast<std::size_t>(uniform)][static_cast<std::size_t>(k)]
                        : most[pen_index][static_cast<std::size_t>(k)];
                if (!(top > 0.0f)) continue;
                Vec3f along;
                const Slicing sl = triangle_slicing(c, frame, tri, k, along);
                double num[3], den[3], lo = std::numeric_limits<double>::infinity(), hi = -lo;
                for (int i = 0; i < 3; ++i) {
                    sl.values(tri.p[i], num[i], den[i]);
                    const double u = num[i] / den[i];
                    lo = std::min(lo, u);
                    hi = std::max(hi, u);
                }
                // The largest rank drawn anywhere on the triangle, from its corners and centre
                // (a quarter more for the slope's change between them on a small triangle,
                // twice on a large one, whose slices are then checked one by one).
                // On a small triangle q's inverse slope is interpolated from its corners.
                double bound = 0.0;
                double slope[3] = {};  // share-free q at the corners
                for (int i = 0; i < (small ? 3 : 4); ++i) {
                    const Vec3f p = i < 3 ? tri.p[i] : (tri.p[0] + tri.p[1] + tri.p[2]) / 3.0f;
                    const double q = slicer.reach(1.0f, tri, along, p);
                    if (i < 3) slope[i] = q;
                    bound = std::max(bound, top * q);
                }
                if (!screen) bound *= small ? 1.25 : 2.0;
                if (!(bound > 0.0)) continue;
                // Planes with rank below `bound` are multiples of 2^m: r(K) >= 2^-(m+1) for K
                // with m trailing zeros. Counted up to about four per spacing of the triangle's
                // image, coarser where the bound would ask for more (faces almost parallel to
                // the planes).
                int m = bound >= 1.0 ? 0 : std::max(0, -floor_log2(bound) - 1);
                const double cap = 4.0 * diameter / g + 8.0;
                double step = slicer.s * power_of_two(m);
                while ((hi - lo) / step > cap && m < 60) {
                    ++m;
                    step *= 2.0;
                }
                if (!std::isfinite(lo / step) || std::abs(hi / step) > 0x1p52) continue;
                const auto j0 = static_cast<std::int64_t>(std::ceil(lo / step));
                const auto j1 = static_cast<std::int64_t>(std::floor(hi / step));
                for (std::int64_t j = j0; j <= j1; ++j) {
                    const std::int64_t plane = j * (std::int64_t{1} << m);
                    const double rank = plane_rank(plane);
                    if (rank >= bound) continue;
                    SliceSegment seg;
                    if (!slice_triangle(tri, num, den, static_cast<double>(plane) * slicer.s,
                                        sl.tag | (static_cast<std::uint32_t>(plane) & 0x0fffffffu),
                                        seg))
                        continue;
                    // Sampled evenly on the image: depth is linear along the segment, its
                    // inverse along the image.
                    const float za = c.view.depth(seg.p[0]), zb = c.view.depth(seg.p[1]);
                    const Point2 ia = c.view.project(seg.p[0]), ib = c.view.project(seg.p[1]);
                    const float image_length = portable::hypot(ib.x - ia.x, ib.y - ia.y);
                    auto t_of = [&](float s) { return s * za / ((1.0f - s) * zb + s * za); };
                    // Drawn nowhere along it, by the largest q at its ends and middle (the
                    // slope changes little along one slice of a triangle; a quarter more for it).
                    if (!small && !screen) {
                        // q's inverse slope interpolated from the corners, with room to spare
                        // for perspective across a large triangle.
                        double q = 0.0;
                        for (const Vec2f& b : {seg.bary[0], seg.bary[1]})
                            q = std::max(q, top * (slope[0] * (1.0 - b.x - b.y) + slope[1] * b.x +
                                                   slope[2] * b.y));
                        if (rank >= 2.0 * q) continue;
                    }
                    // Whether the plane is drawn at s (the band there given, or found).
                    auto band_at = [&](float s) -> int {
                        const float along_t = t_of(s);
                        const Vec2f b{seg.bary[0].x + (seg.bary[1].x - seg.bary[0].x) * along_t,
                                      seg.bary[0].y + (seg.bary[1].y - seg.bary[0].y) * along_t};
                        if (interpolated)
                            return band_of(
                                c.band_thresholds,
                                corner[0] * (1.0f - b.x - b.y) + corner[1] * b.x + corner[2] * b.y);
                        const Vec3f p = seg.p[0] + (seg.p[1] - seg.p[0]) * along_t;
                        if (follow) {
                            const Vec3f n = corner_normal[0] * (1.0f - b.x - b.y) +
                                            corner_normal[1] * b.x + corner_normal[2] * b.y;
                            const float len = length(n);
                            return band_of(
                                c.band_thresholds,
                                diffuse_light(c.lights, p, len > 0.0f ? n / len : tri.normal));
                        }
                        return c.shading.band(t, b.x, b.y, p);
                    };
                    auto drawn_in = [&](float s, int band) {
                        if (band < 0 || static_cast<std::size_t>(band) >= pen.share.size())
                            return false;
                        const float share =
                            pen.share[static_cast<std::size_t>(band)][static_cast<std::size_t>(k)];
                        if (!(share > 0.0f)) return false;
                        if (small && !screen) {
                            const float along_t = t_of(s);
                            const float b1 = seg.bary[0].x +
                                             (seg.bary[1].x - seg.bary[0].x) * along_t,
                                        b2 = seg.bary[0].y +
                                             (seg.bary[1].y - seg.bary[0].y) * along_t;
                            const double q =
                                slope[0] * (1.0 - b1 - b2) + slope[1] * b1 + slope[2] * b2;
                            return rank < share * q;
                        }
                        return rank < slicer.reach(share, tri, along,
                                                   seg.p[0] + (seg.p[1] - seg.p[0]) * t_of(s));
                    };
                    auto drawn = [&](float s) {
                        return drawn_in(s, uniform >= 0 ? uniform : band_at(s));
                    };
                    const int n =
                        std::max(1, static_cast<int>(std::ceil(image_length / kToneStep)));
                    auto sample_s = [&](int i) {
                        return (static_cast<float>(i) + 0.5f) / static_cast<float>(n);
                    };
                    // The band at every coarse_stride-th sample (and the last); a sample between
                    // two of the same band is that band, between two others it is found.
                    if (uniform < 0) {  // (cheap for interpolated triangles, needed for large ones)
                        coarse.resize(static_cast<std::size_t>((n - 1) / coarse_stride + 2));
                        for (std::size_t j = 0; j < coarse.size(); ++j)
                            coarse[j] = band_at(
                                sample_s(std::min(static_cast<int>(j) * coarse_stride, n - 1)));
                    }
                    auto sample_band = [&](int i) -> int {
                        if (uniform >= 0) return uniform;
                        const auto j = static_cast<std::size_t>(i / coarse_stride);
                        if (i % coarse_stride == 0) return coarse[j];
                        return coarse[j] == coarse[j + 1] ? coarse[j] : band_at(sample_s(i));
                    };
                    // The samples' states: at every coarse_stride-th sample (and the last), and
                    // between two of them wherever they differ in band or state (where neither
                    // differs the slope changes too little between them to matter).
                    drawn_at.assign(static_cast<std::size_t>(n), 0);
                    for (int i0 = 0; i0 < n; i0 += coarse_stride) {
                        const int i1 = std::min(i0 + coarse_stride, n - 1);
                        if (i0 == 0) drawn_at[0] = drawn_in(sample_s(0), sample_band(0));
                        drawn_at[static_cast<std::size_t>(i1)] =
                            drawn_in(sample_s(i1), sample_band(i1));
                        const auto j = static_cast<std::size_t>(i0 / coarse_stride);
                        const bool same = (uniform >= 0 || coarse[j] == coarse[j + 1]) &&
                                          drawn_at[static_cast<std::size_t>(i0)] ==
                                              drawn_at[static_cast<std::size_t>(i1)];
                        for (int i = i0 + 1; i < i1; ++i)
                            drawn_at[static_cast<std::size_t>(i)] =
                                same ? drawn_at[static_cast<std::size_t>(i0)]
                                     : drawn_in(sample_s(i), sample_band(i));
                    }
                    // Runs of one state from the samples, each change bisected: run r is
                    // [cuts[r], cuts[r + 1]] with state states[r].
                    cuts.assign(1, 0.0f);
                    states.clear();
                    bool previous = false, any = false;
                    for (int i = 0; i < n; ++i) {
                        const bool state = drawn_at[static_cast<std::size_t>(i)] != 0;
                        any = any || state;
                        if (i > 0 && state != previous) {
                            float a = sample_s(i - 1), b = sample_s(i);
                            while ((b - a) * image_length > kTonePrecision) {
                                const float mid = 0.5f * (a + b);
                                if (mid <= a || mid >= b) break;
                                (drawn(mid) == previous ? a : b) = mid;
                            }
                            cuts.push_back(0.5f * (a + b));
                            states.push_back(previous ? 1 : 0);
                        }
                        previous = state;
                    }
                    if (!any) continue;
                    states.push_back(previous ? 1 : 0);
                    cuts.push_back(1.0f);
                    for (std::size_t r = 0; r < states.size(); ++r) {
                        if (!states[r]) continue;
                        const bool first = r == 0, last = r + 1 == states.size();
                        FeatureSegment f;
                        f.type = EdgeType::Tone;
                        f.faces = {t, kNoIndex};
                        f.p0 = first ? seg.p[0] : seg.p[0] + (seg.p[1] - seg.p[0]) * t_of(cuts[r]);
                        f.p1 =
                            last ? seg.p[1] : seg.p[0] + (seg.p[1] - seg.p[0]) * t_of(cuts[r + 1]);
                        if (first) f.key0 = seg.key[0];
                        if (last) f.key1 = seg.key[1];
                        if (f.p0 != f.p1) out.push_back(f);
                    }
                }
            }
        }
    });
}

namespace {

// The share of a g x g cell a disc of radius rho g centred in it covers (its own disc only:
// within its cell no neighbour's disc reaches farther than its own).
double disc_in_cell(double rho) {
    constexpr double pi = std::numbers::pi;
    if (rho <= 0.5) return pi * rho * rho;
    if (rho * rho >= 0.5) return 1.0;
    // The four caps beyond the sides at distance 1/2: each r^2 acos(h/r) - h sqrt(r^2 - h^2),
    // acos found by bisection on the portable cosine.
    const double h = 0.5 / rho;
    double lo = 0.0, hi = pi / 2;
    for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        (portable::cos(mid) > h ? lo : hi) = mid;
    }
    const double angle = 0.5 * (lo + hi);
    const double cap = rho * rho * angle - 0.5 * std::sqrt(rho * rho - 0.25);
    return pi * rho * rho - 4.0 * cap;
}

// The radius (in cell sides) of the dot covering `darkness` of its cell.
double dot_radius_in_cells(double darkness) {
    if (!(darkness > 0.0)) return 0.0;
    double lo = 0.0, hi = std::sqrt(0.5);
    for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        (disc_in_cell(mid) < darkness ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

}  // namespace

std::vector<ToneDot> screentone_dots(const ToneContext& c, int threads) {
    const Scene& scene = c.scene;
    const float g = std::max(c.settings.spacing * static_cast<float>(c.height) / 720.0f, 0.25f);
    // Per pen and band: the darkness each dot covers.
    std::vector<std::vector<float>> darkness(c.pens.size());
    for (std::size_t i = 0; i < c.pens.size(); ++i)
        for (const auto& band : c.pens[i].share) {
            // Shares of the families back to darkness: 1 - prod (1 - c_k), c_k = share_k * w / g.
            const float coverage = c.pens[i].width / g;
            float left = 1.0f;
            for (float share : band) left *= 1.0f - std::min(share * coverage, 1.0f);
            darkness[i].push_back(1.0f - left);
        }
    if (c.settings.anchored() == ToneAnchor::Screen) {
        std::vector<std::vector<float>> radius(c.pens.size());
        for (std::size_t i = 0; i < c.pens.size(); ++i)
            for (float d : darkness[i])
                radius[i].push_back(static_cast<float>(dot_radius_in_cells(d)) * g);
        const float a = c.settings.angle * std::numbers::pi_v<float> / 180.0f;
        const Point2 d1{portable::cos(a), -portable::sin(a)},
            d2{portable::sin(a), portable::cos(a)};
        const Point2 centre{static_cast<float>(c.width) * 0.5f,
                            static_cast<float>(c.height) * 0.5f};
        const int reach = static_cast<int>(std::ceil(portable::hypot(static_cast<float>(c.width),
                                                                     static_cast<float>(c.height)) /
                                                     (2.0f * g))) +
                          1;
        const int rows = 2 * reach + 1;
        return gather_chunks<ToneDot>(
            rows, 4, threads, [&](int r0, int r1, std::vector<ToneDot>& out) {
                for (int r = r0; r < r1; ++r)
                    for (int i = -reach; i <= reach; ++i) {
                        const float fi = static_cast<float>(i) * g,
                                    fj = static_cast<float>(r - reach) * g;
                        const Point2 x{centre.x + d1.x * fi + d2.x * fj,
                                       centre.y + d1.y * fi + d2.y * fj};
                        if (!(x.x >= -g && x.x <= static_cast<float>(c.width) + g && x.y >= -g &&
                              x.y <= static_cast<float>(c.height) + g))
                            continue;
                        const Vec3f dir = c.plane.pixel_point(x.x, x.y) - c.plane.eye;
                        Hit hit;
                        if (!c.accel.intersect(
                                Ray{c.plane.eye, dir, std::numeric_limits<float>::infinity()}, hit))
                            continue;
                        const std::uint16_t pen_index = c.pen_of_triangle[hit.prim];
                        if (!c.pens[pen_index].draw) continue;
                        const std::uint8_t band =
                            c.shading.band(hit.prim, hit.u, hit.v, c.plane.eye + dir * hit.t);
                        if (band >= radius[pen_index].size()) continue;
                        const float rad = radius[pen_index][band];
                        if (rad > 0.0f) out.push_back({x, rad, hit.prim});
                    }
            });
    }
    // Object-anchored: where the planes of families 0 and 1 cross on each triangle.
    const double s = object_plane_spacing(scene);
    const Slicer slicer{c, c.view, g, s, false};
    const std::vector<ObjectFrame> frames = object_frames(c);
    const std::vector<std::int8_t> outward = outward_objects(scene, c.closed, c.view.eye());
    const int count = static_cast<int>(scene.triangle_count());
    return gather_chunks<
        ToneDot>(count, 64, threads, [&](int t0, int t1, std::vector<ToneDot>& out) {
        TriangleView tri;
        for (int ti = t0; ti < t1; ++ti) {
            const auto t = static_cast<std::uint32_t>(ti);
            const std::uint16_t pen_index = c.pen_of_triangle[t];
            if (!c.pens[pen_index].draw || darkness[pen_index].empty()) continue;
            if (!view_triangle(c, outward, t, g, tri)) continue;
            const ObjectFrame& frame = frames[scene.tri_object[t]];
            Vec3f along[2];
            double u[2][3], lo[2], hi[2], bound[2];
            std::int64_t first[2], last[2];
            int m[2];
            float diameter = 0.0f;
            for (int i = 0; i < 3; ++i)
                diameter =
                    std::max(diameter, portable::hypot(tri.image[i].x - tri.image[(i + 1) % 3].x,
                                                       tri.image[i].y - tri.image[(i + 1) % 3].y));
            bool empty = false;
            for (int k = 0; k < 2 && !empty; ++k) {
                const Slicing sl = triangle_slicing(c, frame, tri, k, along[k]);
                lo[k] = std::numeric_limits<double>::infinity();
                hi[k] = -lo[k];
                for (int i = 0; i < 3; ++i) {
                    double den = 1.0;
                    sl.values(tri.p[i], u[k][i], den);
                    lo[k] = std::min(lo[k], u[k][i]);
                    hi[k] = std::max(hi[k], u[k][i]);
                }
                bound[k] = 0.0;
                for (int i = 0; i < 4; ++i) {
                    const Vec3f p = i < 3 ? tri.p[i] : (tri.p[0] + tri.p[1] + tri.p[2]) / 3.0f;
                    bound[k] = std::max(bound[k], 2.0 * slicer.reach(1.0f, tri, along[k], p));
                }
                if (!(bound[k] > 0.0)) {
                    empty = true;
                    break;
                }
                m[k] = bound[k] >= 1.0 ? 0 : std::max(0, -floor_log2(bound[k]) - 1);
                const double cap = 4.0 * diameter / g + 8.0;
                double step = s * power_of_two(m[k]);
                while ((hi[k] - lo[k]) / step > cap && m[k] < 60) {
                    ++m[k];
                    step *= 2.0;
                }
                if (!std::isfinite(lo[k] / step) || std::abs(hi[k] / step) > 0x1p52) {
                    empty = true;
                    break;
                }
                first[k] = static_cast<std::int64_t>(std::ceil(lo[k] / step));
                last[k] = static_cast<std::int64_t>(std::floor(hi[k] / step));
            }
            if (empty) continue;
            for (std::int64_t j0 = first[0]; j0 <= last[0]; ++j0) {
                const std::int64_t k0 = j0 * (std::int64_t{1} << m[0]);
                const double r0 = plane_rank(k0);
                if (r0 >= bound[0]) continue;
                for (std::int64_t j1 = first[1]; j1 <= last[1]; ++j1) {
                    const std::int64_t k1 = j1 * (std::int64_t{1} << m[1]);
                    const double r1 = plane_rank(k1);
                    if (r1 >= bound[1]) continue;
                    // Barycentrics (b1, b2) where u0 = k0 s and u1 = k1 s.
                    const double a00 = u[0][1] - u[0][0], a01 = u[0][2] - u[0][0];
                    const double a10 = u[1][1] - u[1][0], a11 = u[1][2] - u[1][0];
                    const double r0v = static_cast<double>(k0) * s - u[0][0];
                    const double r1v = static_cast<double>(k1) * s - u[1][0];
                    const double det = a00 * a11 - a01 * a10;
                    if (det == 0.0) continue;
                    const double b1 = (r0v * a11 - a01 * r1v) / det,
                                 b2 = (a00 * r1v - a10 * r0v) / det;
                    if (!(b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0)) continue;
                    const auto fb1 = static_cast<float>(b1), fb2 = static_cast<float>(b2);
                    const Vec3f p = tri.p[0] * (1.0f - fb1 - fb2) + tri.p[1] * fb1 + tri.p[2] * fb2;
                    const double q0 = slicer.reach(1.0f, tri, along[0], p),
                                 q1 = slicer.reach(1.0f, tri, along[1], p);
                    if (!(r0 < q0 && r1 < q1)) continue;
                    const std::uint8_t band = c.shading.band(t, fb1, fb2, p);
                    if (band >= darkness[pen_index].size()) continue;
                    const float d = darkness[pen_index][band];
                    if (!(d > 0.0f)) continue;
                    // The cell: g by g between the families' traces, over the sine of their angle
                    // on the image.
                    const Vec3f e = p - c.view.eye();
                    const Point2 centre = c.view.project(p);
                    Hit hit;
                    if (c.accel.intersect(Ray{c.view.eye(), e, 1.0f - 1e-4f}, hit) && hit.prim != t)
                        continue;  // hidden
                    // The traces' directions on the image: a small step along each on the face.
                    const float small = static_cast<float>(s) * 1024.0f;
                    const Point2 step0 =
                        c.view.project(p + normalize(cross(tri.normal, along[0])) * small);
                    const Point2 step1 =
                        c.view.project(p + normalize(cross(tri.normal, along[1])) * small);
                    const float x0 = step0.x - centre.x, y0 = step0.y - centre.y;
                    const float x1 = step1.x - centre.x, y1 = step1.y - centre.y;
                    const float l0 = portable::hypot(x0, y0), l1 = portable::hypot(x1, y1);
                    float sine =
                        l0 > 0.0f && l1 > 0.0f ? std::abs(x0 * y1 - y0 * x1) / (l0 * l1) : 1.0f;
                    sine = std::max(sine, 0.2f);
                    // Each family's own spacing here: half the gaps to the planes drawn on
                    // either side (thinned by rank, the gaps are one or two steps of the
                    // coarsest planes every rank below q keeps), in pixels.
                    auto width = [&](std::int64_t plane, double q, const Vec3f& a) {
                        const std::int64_t step = std::int64_t{1}
                                                  << std::max(0, -floor_log2(q) - 1);
                        double gap = 0.0;
                        for (int side : {-1, 1})
                            for (std::int64_t j = 1; j <= 2; ++j)
                                if (plane_rank(plane + side * j * step) < q || j == 2) {
                                    gap += static_cast<double>(j * step);
                                    break;
                                }
                        const float grad = slicer.gradient(tri, a, p);
                        return static_cast<float>(0.5 * gap * s) / grad;
                    };
                    const float area = d * width(k0, q0, along[0]) * width(k1, q1, along[1]) / sine;
                    out.push_back({centre, std::sqrt(area / std::numbers::pi_v<float>), t});
                }
            }
        }
    });
}

}  // namespace toonray::ink
