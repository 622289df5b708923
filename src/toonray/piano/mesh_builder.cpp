#include "toonray/piano/mesh_builder.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "toonray/core/error.h"
#include "toonray/core/portable_math.h"

namespace toonray {
namespace {

constexpr float kPi = 3.14159265358979f;

Vec3f any_perpendicular(const Vec3f& a) {
    Vec3f t = std::abs(a.x) < 0.9f ? Vec3f(1.0f, 0.0f, 0.0f) : Vec3f(0.0f, 1.0f, 0.0f);
    return normalize(cross(t, a));
}

/// Outward 2D normal of the segment a -> b: to the right of travel.
Vec2f segment_normal(const ProfilePoint& a, const ProfilePoint& b) {
    float du = b.u - a.u, dv = b.v - a.v;
    float len = std::sqrt(du * du + dv * dv);
    if (len == 0.0f) return {0.0f, 0.0f};
    return {dv / len, -du / len};
}

Vec2f normalized(Vec2f n) {
    float len = std::sqrt(n.x * n.x + n.y * n.y);
    return len > 0.0f ? Vec2f{n.x / len, n.y / len} : Vec2f{0.0f, 0.0f};
}

float cross2(const ProfilePoint& o, const ProfilePoint& a, const ProfilePoint& b) {
    return (a.u - o.u) * (b.v - o.v) - (a.v - o.v) * (b.u - o.u);
}

float signed_area(std::span<const ProfilePoint> poly) {
    double area = 0.0;
    for (std::size_t i = 0, n = poly.size(); i < n; ++i) {
        const ProfilePoint& a = poly[i];
        const ProfilePoint& b = poly[(i + 1) % n];
        area += static_cast<double>(a.u) * b.v - static_cast<double>(b.u) * a.v;
    }
    return static_cast<float>(0.5 * area);
}

}  // namespace

Frame Frame::along(const Vec3f& origin, const Vec3f& axis) {
    Frame f;
    f.origin = origin;
    f.ey = normalize(axis);
    f.ex = any_perpendicular(f.ey);
    f.ez = cross(f.ex, f.ey);
    return f;
}

Vec3f rotate_about(const Vec3f& v, const Vec3f& axis, float angle) {
    float c = portable::cos(angle), s = portable::sin(angle);
    return v * c + cross(axis, v) * s + axis * (dot(axis, v) * (1.0f - c));
}

Frame Frame::rotated(const Vec3f& pivot, const Vec3f& axis, float angle) const {
    Vec3f a = normalize(axis);
    Frame f;
    f.origin = pivot + rotate_about(origin - pivot, a, angle);
    f.ex = rotate_about(ex, a, angle);
    f.ey = rotate_about(ey, a, angle);
    f.ez = rotate_about(ez, a, angle);
    return f;
}

Frame Frame::compose(const Frame& local) const {
    Frame f;
    f.origin = point(local.origin);
    f.ex = direction(local.ex);
    f.ey = direction(local.ey);
    f.ez = direction(local.ez);
    return f;
}

Frame Frame::translated(const Vec3f& offset) const {
    Frame f = *this;
    f.origin += offset;
    return f;
}

void append_arc(std::vector<ProfilePoint>& out, float cu, float cv, float radius, float a0,
                float a1, int segments, bool smooth_ends) {
    for (int i = 0; i <= segments; ++i) {
        float a = a0 + (a1 - a0) * static_cast<float>(i) / static_cast<float>(segments);
        bool end = i == 0 || i == segments;
        out.push_back(
            {cu + radius * portable::cos(a), cv + radius * portable::sin(a), !end || smooth_ends});
    }
}

std::vector<std::array<std::uint32_t, 3>> triangulate_polygon(std::span<const ProfilePoint> poly) {
    std::vector<std::array<std::uint32_t, 3>> tris;
    const std::size_t n = poly.size();
    if (n < 3) return tris;
    std::vector<std::uint32_t> idx(n);
    for (std::size_t i = 0; i < n; ++i) idx[i] = static_cast<std::uint32_t>(i);
    if (signed_area(poly) < 0.0f) std::reverse(idx.begin(), idx.end());

    auto inside = [&](const ProfilePoint& p, const ProfilePoint& a, const ProfilePoint& b,
                      const ProfilePoint& c) {
        return cross2(a, b, p) >= 0.0f && cross2(b, c, p) >= 0.0f && cross2(c, a, p) >= 0.0f;
    };
    std::size_t guard = 0;
    while (idx.size() > 3) {
        bool clipped = false;
        const std::size_t m = idx.size();
        for (std::size_t i = 0; i < m; ++i) {
            std::uint32_t ia = idx[(i + m - 1) % m], ib = idx[i], ic = idx[(i + 1) % m];
            const ProfilePoint &a = poly[ia], &b = poly[ib], &c = poly[ic];
            if (cross2(a, b, c) <= 0.0f) continue;  // reflex or degenerate corner
            bool ear = true;
            for (std::uint32_t j : idx) {
                if (j == ia || j == ib || j == ic) continue;
                const ProfilePoint& p = poly[j];
                // Points coinciding with a corner (repeated vertices) do not block an ear.
                if ((p.u == a.u && p.v == a.v) || (p.u == c.u && p.v == c.v)) continue;
                if (inside(p, a, b, c)) {
                    ear = false;
                    break;
                }
            }
            if (!ear) continue;
            tris.push_back({ia, ib, ic});
            idx.erase(idx.begin() + static_cast<std::ptrdiff_t>(i));
            clipped = true;
            break;
        }
        if (!clipped) {
            // Only collinear runs remain (zero-area corners): drop one and go on.
            if (++guard > n) throw Error("triangulate_polygon: polygon is not simple");
            idx.erase(idx.begin());
        }
    }
    if (cross2(poly[idx[0]], poly[idx[1]], poly[idx[2]]) > 0.0f)
        tris.push_back({idx[0], idx[1], idx[2]});
    return tris;
}

std::uint32_t MeshBuilder::add_material(std::string name, const Vec3f& kd) {
    Material m(std::move(name));
    m.kd = kd;
    m.illum = 1;
    scene_.materials.push_back(std::move(m));
    return static_cast<std::uint32_t>(scene_.materials.size() - 1);
}

std::uint32_t MeshBuilder::begin_object(std::string name) {
    scene_.objects.push_back(std::move(name));
    object_ = static_cast<std::uint32_t>(scene_.objects.size() - 1);
    return object_;
}

std::uint32_t MeshBuilder::vertex(const Vec3f& p) {
    scene_.positions.push_back(frame_.point(p));
    return static_cast<std::uint32_t>(scene_.positions.size() - 1);
}

std::uint32_t MeshBuilder::normal(const Vec3f& n) {
    scene_.normals.push_back(normalize(frame_.direction(n)));
    return static_cast<std::uint32_t>(scene_.normals.size() - 1);
}

void MeshBuilder::triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c,
                           const Vec3f& outward) {
    const auto& P = scene_.positions;
    Vec3f n = cross(P[b] - P[a], P[c] - P[a]);
    if (dot(n, outward) < 0.0f) std::swap(b, c);
    scene_.add_triangle({a, b, c}, material_, object_);
}

void MeshBuilder::triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t na,
                           std::uint32_t nb, std::uint32_t nc) {
    const auto& P = scene_.positions;
    const auto& N = scene_.normals;
    Vec3f n = cross(P[b] - P[a], P[c] - P[a]);
    if (dot(n, N[na] + N[nb] + N[nc]) < 0.0f) {
        std::swap(b, c);
        std::swap(nb, nc);
    }
    scene_.add_triangle({a, b, c}, material_, object_, {na, nb, nc});
}

void MeshBuilder::polygon(std::initializer_list<std::uint32_t> corners, const Vec3f& outward) {
    polygon(std::span<const std::uint32_t>(corners.begin(), corners.size()), outward);
}

void MeshBuilder::polygon(std::span<const std::uint32_t> c, const Vec3f& outward) {
    for (std::size_t i = 1; i + 1 < c.size(); ++i) triangle(c[0], c[i], c[i + 1], outward);
}

void MeshBuilder::quad(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d,
                       std::uint32_t na, std::uint32_t nb, std::uint32_t nc, std::uint32_t nd) {
    triangle(a, b, c, na, nb, nc);
    triangle(a, c, d, na, nc, nd);
}

void MeshBuilder::box(const Vec3f& lo, const Vec3f& hi) {
    const Vec3f pts[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z},
                          {lo.x, hi.y, lo.z}, {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z},
                          {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
    convex_solid(
        pts, {{0, 1, 2, 3}, {4, 5, 6, 7}, {0, 1, 5, 4}, {3, 2, 6, 7}, {0, 3, 7, 4}, {1, 2, 6, 5}});
}

void MeshBuilder::chamfer_box(const Vec3f& lo, const Vec3f& hi, float c) {
    // Three points per corner, one on each of the faces meeting there, inset by c.
    // Index: corner s = sx + 2 sy + 4 sz; point on the x face = 3 s, y face = 3 s + 1,
    // z face = 3 s + 2.
    std::array<Vec3f, 24> pts;
    for (int s = 0; s < 8; ++s) {
        int sx = s & 1, sy = (s >> 1) & 1, sz = (s >> 2) & 1;
        float X = sx ? hi.x : lo.x, Y = sy ? hi.y : lo.y, Z = sz ? hi.z : lo.z;
        float Xi = sx ? hi.x - c : lo.x + c, Yi = sy ? hi.y - c : lo.y + c,
              Zi = sz ? hi.z - c : lo.z + c;
        pts[3 * s + 0] = {X, Yi, Zi};
        pts[3 * s + 1] = {Xi, Y, Zi};
        pts[3 * s + 2] = {Xi, Yi, Z};
    }
    auto S = [](int sx, int sy, int sz) { return sx + 2 * sy + 4 * sz; };
    auto px = [&](int sx, int sy, int sz) { return 3 * S(sx, sy, sz) + 0; };
    auto py = [&](int sx, int sy, int sz) { return 3 * S(sx, sy, sz) + 1; };
    auto pz = [&](int sx, int sy, int sz) { return 3 * S(sx, sy, sz) + 2; };

    std::vector<std::uint32_t> v(24);
    for (int i = 0; i < 24; ++i) v[i] = vertex(pts[i]);
    Vec3f centre = frame_.point((lo + hi) * 0.5f);
    auto face = [&](std::initializer_list<int> ids) {
        std::vector<std::uint32_t> c;
        Vec3f mid(0.0f);
        for (int i : ids) {
            c.push_back(v[i]);
            mid += scene_.positions[v[i]];
        }
        mid = mid / static_cast<float>(ids.size());
        polygon(c, mid - centre);
    };
    for (int s = 0; s < 2; ++s) {
        face({px(s, 0, 0), px(s, 1, 0), px(s, 1, 1), px(s, 0, 1)});
        face({py(0, s, 0), py(1, s, 0), py(1, s, 1), py(0, s, 1)});
        face({pz(0, 0, s), pz(1, 0, s), pz(1, 1, s), pz(0, 1, s)});
    }
    for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) {
            face({px(a, b, 0), px(a, b, 1), py(a, b, 1), py(a, b, 0)});  // edges along z
            face({px(a, 0, b), px(a, 1, b), pz(a, 1, b), pz(a, 0, b)});  // edges along y
            face({py(0, a, b), py(1, a, b), pz(1, a, b), pz(0, a, b)});  // edges along x
        }
    for (int s = 0; s < 8; ++s) face({3 * s, 3 * s + 1, 3 * s + 2});
}

void MeshBuilder::convex_solid(std::span<const Vec3f> points,
                               std::initializer_list<std::initializer_list<int>> faces) {
    std::vector<std::uint32_t> v;
    v.reserve(points.size());
    Vec3f centre(0.0f);
    for (const Vec3f& p : points) {
        v.push_back(vertex(p));
        centre += scene_.positions.back();
    }
    centre = centre / static_cast<float>(points.size());
    std::vector<std::uint32_t> c;
    for (const auto& f : faces) {
        c.clear();
        Vec3f mid(0.0f);
        for (int i : f) {
            c.push_back(v[static_cast<std::size_t>(i)]);
            mid += scene_.positions[v[static_cast<std::size_t>(i)]];
        }
        mid = mid / static_cast<float>(f.size());
        polygon(c, mid - centre);
    }
}

void MeshBuilder::extrude(std::span<const ProfilePoint> poly_in, const Vec3f& u_dir,
                          const Vec3f& v_dir, const Vec3f& w_dir, float w0, float w1) {
    std::vector<ProfilePoint> poly(poly_in.begin(), poly_in.end());
    if (signed_area(poly) < 0.0f) std::reverse(poly.begin(), poly.end());
    const std::size_t n = poly.size();
    auto local = [&](const ProfilePoint& p, float w) {
        return u_dir * p.u + v_dir * p.v + w_dir * w;
    };
    std::vector<std::uint32_t> bottom(n), top(n);
    for (std::size_t i = 0; i < n; ++i) {
        bottom[i] = vertex(local(poly[i], w0));
        top[i] = vertex(local(poly[i], w1));
    }
    // Segment normals (counter-clockwise polygon: outside to the right of travel) and the
    // averaged normals at smooth points.
    std::vector<Vec2f> seg(n), avg(n);
    for (std::size_t i = 0; i < n; ++i) seg[i] = segment_normal(poly[i], poly[(i + 1) % n]);
    for (std::size_t i = 0; i < n; ++i) {
        const Vec2f& a = seg[(i + n - 1) % n];
        avg[i] = normalized({a.x + seg[i].x, a.y + seg[i].y});
    }
    auto dir3 = [&](Vec2f m) { return u_dir * m.x + v_dir * m.y; };
    for (std::size_t i = 0; i < n; ++i) {
        std::size_t j = (i + 1) % n;
        if (poly[i].smooth || poly[j].smooth) {
            Vec2f mi = poly[i].smooth ? avg[i] : seg[i];
            Vec2f mj = poly[j].smooth ? avg[j] : seg[i];
            std::uint32_t ni = normal(dir3(mi)), nj = normal(dir3(mj));
            quad(bottom[i], bottom[j], top[j], top[i], ni, nj, nj, ni);
        } else {
            Vec3f out = frame_.direction(dir3(seg[i]));
            polygon({bottom[i], bottom[j], top[j], top[i]}, out);
        }
    }
    const float sign = w1 >= w0 ? 1.0f : -1.0f;
    const Vec3f w_world = frame_.direction(w_dir) * sign;
    for (const auto& t : triangulate_polygon(poly)) {
        triangle(top[t[0]], top[t[1]], top[t[2]], w_world);
        triangle(bottom[t[0]], bottom[t[1]], bottom[t[2]], -w_world);
    }
}

void MeshBuilder::lathe(std::span<const ProfilePoint> profile, int segments, bool cap_bottom,
                        bool cap_top) {
    const std::size_t n = profile.size();
    if (n < 2 || segments < 3) return;
    std::vector<float> cs(segments), sn(segments);
    for (int k = 0; k < segments; ++k) {
        float a = 2.0f * kPi * static_cast<float>(k) / static_cast<float>(segments);
        cs[k] = portable::cos(a);
        sn[k] = portable::sin(a);
    }
    auto local = [&](float r, float h, int k) { return Vec3f(r * cs[k], h, -r * sn[k]); };
    auto ldir = [&](Vec2f m, int k) { return Vec3f(m.x * cs[k], m.y, -m.x * sn[k]); };

    // Position rings; a point on the axis is a single pole vertex.
    std::vector<std::uint32_t> ring_start(n);
    std::vector<bool> pole(n);
    for (std::size_t i = 0; i < n; ++i) {
        pole[i] = profile[i].u <= 0.0f;
        ring_start[i] = static_cast<std::uint32_t>(scene_.positions.size());
        if (pole[i]) {
            vertex({0.0f, profile[i].v, 0.0f});
        } else {
            for (int k = 0; k < segments; ++k) vertex(local(profile[i].u, profile[i].v, k));
        }
    }
    auto pos = [&](std::size_t i, int k) {
        return pole[i] ? ring_start[i] : ring_start[i] + static_cast<std::uint32_t>(k % segments);
    };

    std::vector<Vec2f> seg(n - 1);
    for (std::size_t i = 0; i + 1 < n; ++i) seg[i] = segment_normal(profile[i], profile[i + 1]);
    // Smooth points share one normal ring between their segments, made on first use.
    std::vector<std::uint32_t> smooth_ring(n, kNoIndex);
    auto make_ring = [&](Vec2f m) {
        std::uint32_t first = static_cast<std::uint32_t>(scene_.normals.size());
        for (int k = 0; k < segments; ++k) normal(ldir(m, k));
        return first;
    };
    auto point_ring = [&](std::size_t i, std::size_t s) {
        if (!profile[i].smooth) return kNoIndex;
        if (smooth_ring[i] == kNoIndex) {
            Vec2f m;
            if (pole[i]) {
                m = {0.0f, seg[s].y >= 0.0f ? 1.0f : -1.0f};
            } else {
                Vec2f a = i > 0 ? seg[i - 1] : seg[i];
                Vec2f b = i + 1 < n ? seg[i] : seg[i - 1];
                m = normalized({a.x + b.x, a.y + b.y});
            }
            smooth_ring[i] = make_ring(m);
        }
        return smooth_ring[i];
    };

    for (std::size_t i = 0; i + 1 < n; ++i) {
        const std::size_t j = i + 1;
        if (pole[i] && pole[j]) continue;
        const Vec2f m = seg[i];
        if (m.x == 0.0f && m.y == 0.0f) continue;  // repeated point
        const bool flat_ring = std::abs(m.x) < 1e-6f && !profile[i].smooth && !profile[j].smooth;
        if (flat_ring) {
            Vec3f out = frame_.direction({0.0f, m.y, 0.0f});
            for (int k = 0; k < segments; ++k) {
                std::uint32_t a = pos(i, k), b = pos(i, k + 1), c = pos(j, k + 1), d = pos(j, k);
                if (pole[i]) triangle(a, c, d, out);
                else if (pole[j]) triangle(a, b, c, out);
                else polygon({a, b, c, d}, out);
            }
            continue;
        }
        std::uint32_t ri = point_ring(i, i), rj = point_ring(j, i);
        std::uint32_t rs = kNoIndex;
        if (ri == kNoIndex || rj == kNoIndex) rs = make_ring(m);
        if (ri == kNoIndex) ri = rs;
        if (rj == kNoIndex) rj = rs;
        for (int k = 0; k < segments; ++k) {
            const std::uint32_t k1 = static_cast<std::uint32_t>((k + 1) % segments);
            const std::uint32_t kk = static_cast<std::uint32_t>(k);
            std::uint32_t a = pos(i, k), b = pos(i, k + 1), c = pos(j, k + 1), d = pos(j, k);
            // A pole corner takes the normal of the ring it faces (its own ring, when smooth,
            // points along the axis).
            std::uint32_t na = ri + kk, nb = ri + k1, nc = rj + k1, nd = rj + kk;
            if (pole[i]) {
                triangle(a, c, d, profile[i].smooth ? ri : rs + kk, nc, nd);
            } else if (pole[j]) {
                triangle(a, b, c, na, nb, profile[j].smooth ? rj : rs + kk);
            } else {
                quad(a, b, c, d, na, nb, nc, nd);
            }
        }
    }

    auto cap = [&](std::size_t i, float dir) {
        if (pole[i]) return;
        std::uint32_t centre = vertex({0.0f, profile[i].v, 0.0f});
        Vec3f out = frame_.direction({0.0f, dir, 0.0f});
        for (int k = 0; k < segments; ++k) triangle(centre, pos(i, k), pos(i, k + 1), out);
    };
    if (cap_bottom) cap(0, -1.0f);
    if (cap_top) cap(n - 1, 1.0f);
}

void MeshBuilder::sweep(std::span<const Vec3f> path, bool closed, const Vec3f& up_in,
                        std::span<const ProfilePoint> profile, bool caps) {
    const std::size_t np = path.size(), nq = profile.size();
    if (np < 2 || nq < 2) return;
    const Vec3f up = normalize(up_in);
    const std::size_t edges = closed ? np : np - 1;
    std::vector<Vec3f> edge_out(edges), edge_dir(edges);
    for (std::size_t e = 0; e < edges; ++e) {
        Vec3f d = normalize(path[(e + 1) % np] - path[e]);
        edge_dir[e] = d;
        edge_out[e] = normalize(cross(d, up));
    }
    // Mitre vector at each path point: offsets along it keep a constant distance from both
    // edges meeting there.
    std::vector<Vec3f> mitre(np);
    for (std::size_t i = 0; i < np; ++i) {
        bool has_prev = closed || i > 0, has_next = closed || i + 1 < np;
        Vec3f a = has_prev ? edge_out[(i + edges - 1) % edges] : edge_out[i];
        Vec3f b = has_next ? edge_out[i % edges] : a;
        mitre[i] = (a + b) / (1.0f + dot(a, b));
    }
    std::vector<std::uint32_t> ring(np);
    for (std::size_t i = 0; i < np; ++i) {
        ring[i] = static_cast<std::uint32_t>(scene_.positions.size());
        for (const ProfilePoint& q : profile) vertex(path[i] + mitre[i] * q.u + up * q.v);
    }
    std::vector<Vec2f> seg(nq - 1), avg(nq);
    for (std::size_t j = 0; j + 1 < nq; ++j) seg[j] = segment_normal(profile[j], profile[j + 1]);
    for (std::size_t j = 0; j < nq; ++j) {
        Vec2f a = j > 0 ? seg[j - 1] : seg[j];
        Vec2f b = j + 1 < nq ? seg[j] : seg[j - 1];
        avg[j] = normalized({a.x + b.x, a.y + b.y});
    }
    for (std::size_t e = 0; e < edges; ++e) {
        const std::size_t i0 = e, i1 = (e + 1) % np;
        auto dir3 = [&](Vec2f m) { return edge_out[e] * m.x + up * m.y; };
        // One normal per profile point per edge run (the mitre is a crease).
        std::vector<std::uint32_t> nrm(nq, kNoIndex);
        for (std::size_t j = 0; j < nq; ++j)
            if (profile[j].smooth) nrm[j] = normal(dir3(avg[j]));
        for (std::size_t j = 0; j + 1 < nq; ++j) {
            std::uint32_t a = ring[i0] + static_cast<std::uint32_t>(j),
                          b = ring[i1] + static_cast<std::uint32_t>(j),
                          c = ring[i1] + static_cast<std::uint32_t>(j + 1),
                          d = ring[i0] + static_cast<std::uint32_t>(j + 1);
            if (seg[j].x == 0.0f && seg[j].y == 0.0f) continue;
            if (profile[j].smooth || profile[j + 1].smooth) {
                std::uint32_t flat = kNoIndex;
                if (!profile[j].smooth || !profile[j + 1].smooth) flat = normal(dir3(seg[j]));
                std::uint32_t n0 = profile[j].smooth ? nrm[j] : flat;
                std::uint32_t n1 = profile[j + 1].smooth ? nrm[j + 1] : flat;
                quad(a, b, c, d, n0, n0, n1, n1);
            } else {
                polygon({a, b, c, d}, frame_.direction(dir3(seg[j])));
            }
        }
    }
    if (!closed && caps) {
        auto tris = triangulate_polygon(profile);
        for (const auto& t : tris) {
            triangle(ring[0] + t[0], ring[0] + t[1], ring[0] + t[2],
                     frame_.direction(-edge_dir[0]));
            std::uint32_t r = ring[np - 1];
            triangle(r + t[0], r + t[1], r + t[2], frame_.direction(edge_dir[edges - 1]));
        }
    }
}

}  // namespace toonray
