#include "toonray/ink/light_lines.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include "toonray/core/portable_math.h"
#include "toonray/ink/chunks.h"
#include "toonray/ink/hash.h"
#include "toonray/ink/visibility.h"

namespace toonray::ink {

float light_cosine(const Light& light, const Vec3f& p, const Vec3f& n) {
    if (light.kind == Light::Kind::Point) {
        // As render/shading.h's light_point computes it.
        const Vec3f to_light = light.vector - p;
        const float distance = length(to_light);
        return distance > 0.0f ? dot(to_light, n) / distance : 1.0f;
    }
    return dot(-normalize(light.vector), n);
}

float diffuse_light(std::span<const Light> lights, const Vec3f& p, const Vec3f& n) {
    float diffuse = 0.0f;
    for (const Light& light : lights)
        diffuse += light.intensity * std::max(0.0f, light_cosine(light, p, n));
    return diffuse;
}

std::uint8_t band_of(std::span<const float> thresholds, float diffuse) {
    const float d = std::min(diffuse, 1.0f);
    std::size_t i = 0;
    while (i < thresholds.size() && d >= thresholds[i]) ++i;
    return static_cast<std::uint8_t>(i);
}

namespace {

Vec3f corner(const Scene& scene, std::uint32_t t, int k) {
    return scene.positions[scene.tri_positions[t][k]];
}

// The unit face normal, or zero for a degenerate triangle.
Vec3f face_normal(const Scene& scene, std::uint32_t t) {
    return unit_face_normal(corner(scene, t, 0), corner(scene, t, 1), corner(scene, t, 2));
}

// Where g (given at the corners) crosses zero on the triangle's edges: the segment between the
// two crossings, each computed from its edge's lower welded id, so that both triangles of an
// edge with the same corner values find the same bits.
bool zero_segment(const Scene& scene, const WeldedMesh& mesh, std::uint32_t t, const float g[3],
                  std::uint32_t tag, FeatureSegment& seg) {
    int found = 0;
    for (int k = 0; k < 3; ++k) {
        int u = k, v = (k + 1) % 3;
        if ((g[u] >= 0) == (g[v] >= 0)) continue;
        std::uint32_t wu = mesh.tri_vertices[t][u], wv = mesh.tri_vertices[t][v];
        if (wv < wu) {
            std::swap(u, v);
            std::swap(wu, wv);
        }
        const Vec3f pu = corner(scene, t, u), pv = corner(scene, t, v);
        const Vec3f q = pu + (pv - pu) * (g[u] / (g[u] - g[v]));
        (found == 0 ? seg.p0 : seg.p1) = q;
        (found == 0 ? seg.key0 : seg.key1) = {wu, wv, tag};
        if (++found == 2) break;
    }
    return found == 2 && seg.p0 != seg.p1;
}

}  // namespace

std::vector<FeatureSegment> band_segments(const Scene& scene, const WeldedMesh& mesh,
                                          const Vec3f& eye, const LightingModel& lighting,
                                          std::span<const std::int8_t> outward, int threads) {
    // The boundaries: each threshold in (0, 1] of the clamped diffuse sum, then each light's
    // terminator.
    std::vector<float> thresholds;
    for (float t : lighting.thresholds)
        if (t > 0.0f && t <= 1.0f) thresholds.push_back(t);
    const std::size_t boundaries = thresholds.size() + lighting.lights.size();
    if (boundaries == 0) return {};
    const int count = static_cast<int>(scene.triangle_count());
    return gather_chunks<
        FeatureSegment>(count, 256, threads, [&](int t0, int t1, std::vector<FeatureSegment>& out) {
        for (int ti = t0; ti < t1; ++ti) {
            const auto t = static_cast<std::uint32_t>(ti);
            const Vec3f face = face_normal(scene, t);
            if (face == Vec3f(0.0f)) continue;
            const auto& tn = scene.tri_normals[t];
            bool smooth = true;
            for (std::uint32_t n : tn) smooth = smooth && n != kNoIndex && n < scene.normals.size();
            // Normals turned with the face toward the eye, as shading turns them to the viewer;
            // on a closed solid outward, and its faces turned away left out (hidden).
            const float facing = dot(face, eye - corner(scene, t, 0));
            const std::uint32_t object = scene.tri_object[t];
            const int out_sign = object < outward.size() ? outward[object] : 0;
            if (out_sign != 0 && facing * static_cast<float>(out_sign) < 0.0f) continue;
            const bool flip = out_sign != 0 ? out_sign < 0 : facing < 0.0f;
            Vec3f p[3], n[3];
            for (int k = 0; k < 3; ++k) {
                p[k] = corner(scene, t, k);
                n[k] = smooth ? normalize(scene.normals[tn[k]]) : face;
                if (flip) n[k] = -n[k];
            }
            // Keys: the same on both triangles of an edge exactly when their values there are
            // (the same normals, turned the same way); flat triangles keep theirs to themselves.
            const std::uint32_t which =
                smooth ? static_cast<std::uint32_t>(hash_words(tn[0] ^ tn[1] ^ tn[2], flip, 0))
                       : t * 2654435761u;
            float diffuse[3];
            for (int k = 0; k < 3; ++k) diffuse[k] = diffuse_light(lighting.lights, p[k], n[k]);
            for (std::size_t b = 0; b < boundaries; ++b) {
                float g[3];
                for (int k = 0; k < 3; ++k)
                    g[k] = b < thresholds.size()
                               ? diffuse[k] - thresholds[b]
                               : light_cosine(lighting.lights[b - thresholds.size()], p[k], n[k]);
                FeatureSegment seg;
                seg.type = EdgeType::Band;
                seg.faces = {t, kNoIndex};
                seg.smooth = smooth;
                if (zero_segment(scene, mesh, t, g, static_cast<std::uint32_t>(b) | (which << 8),
                                 seg))
                    out.push_back(seg);
            }
        }
    });
}

namespace {

// One side of a usable triangle along a welded edge (lo < hi).
struct Side {
    std::uint32_t lo, hi, tri;
    bool forward;  // lo -> hi in the triangle's winding
};

// The wedge a casting edge sweeps away from a light, in the plane through the edge and the
// light: the points where three linear functions are >= 0. Each function's zero is a ray from
// the light through one end of the edge (`end`: that end's welded id) or the edge's own line
// (kNoIndex).
struct Wedge {
    Vec3f normal, origin;  // the plane: dot(normal, x - origin) = 0
    Vec3f w[3];
    float w0[3];
    std::uint32_t end[3];
    Vec3f from[3];  // a side's ray: from + s along[...], for its point on a receiver
    Vec3f along[3];

    [[nodiscard]] float side(int j, const Vec3f& x) const { return dot(w[j], x) + w0[j]; }
};

bool make_wedge(const Light& light, const Vec3f& e0, const Vec3f& e1, std::uint32_t lo,
                std::uint32_t hi, Wedge& wedge) {
    if (light.kind == Light::Kind::Point) {
        const Vec3f l = light.vector, a = e0 - l, b = e1 - l;
        const Vec3f n = cross(a, b);
        const float n2 = dot(n, n);
        if (!(n2 > 0.0f) || !std::isfinite(n2)) return false;
        // x - l = alpha a + beta b in the plane: alpha, beta from the dual basis.
        const Vec3f da = cross(b, n) / n2, db = cross(n, a) / n2;
        wedge.normal = n;
        wedge.origin = l;
        wedge.w[0] = da;  // alpha >= 0: zero along the ray through e1
        wedge.w0[0] = -dot(da, l);
        wedge.end[0] = hi;
        wedge.from[0] = l;
        wedge.along[0] = b;
        wedge.w[1] = db;  // beta >= 0: zero along the ray through e0
        wedge.w0[1] = -dot(db, l);
        wedge.end[1] = lo;
        wedge.from[1] = l;
        wedge.along[1] = a;
        wedge.w[2] = da + db;  // alpha + beta >= 1: beyond the edge
        wedge.w0[2] = -dot(da + db, l) - 1.0f;
        wedge.end[2] = kNoIndex;
        return true;
    }
    const Vec3f d = normalize(light.vector), e = e1 - e0;
    const Vec3f n = cross(e, d);
    const float n2 = dot(n, n);
    if (!(n2 > 0.0f) || !std::isfinite(n2)) return false;
    // x - e0 = alpha e + beta d.
    const Vec3f de = cross(d, n) / n2, dd = cross(n, e) / n2;
    wedge.normal = n;
    wedge.origin = e0;
    wedge.w[0] = de;  // alpha >= 0: zero along the ray from e0
    wedge.w0[0] = -dot(de, e0);
    wedge.end[0] = lo;
    wedge.from[0] = e0;
    wedge.along[0] = d;
    wedge.w[1] = -de;  // alpha <= 1: zero along the ray from e1
    wedge.w0[1] = dot(de, e0) + 1.0f;
    wedge.end[1] = hi;
    wedge.from[1] = e1;
    wedge.along[1] = d;
    wedge.w[2] = dd;  // beta >= 0: away from the light
    wedge.w0[2] = -dot(dd, e0);
    wedge.end[2] = kNoIndex;
    return true;
}

// Whether a box may meet the wedge: it straddles its plane and reaches each side's positive
// half-space.
bool box_meets_wedge(const BBox& box, const Wedge& wedge) {
    auto range = [&](const Vec3f& w, float w0, float& lo, float& hi) {
        const Vec3f c = (box.lo + box.hi) * 0.5f, h = (box.hi - box.lo) * 0.5f;
        const float mid = dot(w, c) + w0;
        const float reach = std::abs(w.x) * h.x + std::abs(w.y) * h.y + std::abs(w.z) * h.z;
        lo = mid - reach;
        hi = mid + reach;
    };
    float lo = 0.0f, hi = 0.0f;
    range(wedge.normal, -dot(wedge.normal, wedge.origin), lo, hi);
    if (!(lo <= 0.0f && hi >= 0.0f)) return false;
    for (int j = 0; j < 3; ++j) {
        range(wedge.w[j], wedge.w0[j], lo, hi);
        if (!(hi >= 0.0f)) return false;
    }
    return true;
}

constexpr float kShadowStep = 1.0f;            // pixels between samples along a candidate
constexpr float kShadowPrecision = 1.0f / 16;  // pixels: where a boundary starts or ends
constexpr std::uint32_t kSideTag = 0x80000000u;

}  // namespace

std::vector<FeatureSegment> shadow_segments(const Scene& scene, const WeldedMesh& mesh,
                                            const TriangleAccel& accel,
                                            const ScreenProjection& view,
                                            const LightingModel& lighting, int threads) {
    const std::size_t n = scene.triangle_count();
    const Bvh& bvh = accel.bvh();
    if (n == 0 || bvh.nodes.empty()) return {};
    std::vector<Vec3f> normal(n);
    for (std::uint32_t t = 0; t < n; ++t) normal[t] = face_normal(scene, t);
    // Every side of a usable triangle, sorted so that the sides of an edge are together.
    std::vector<Side> sides;
    sides.reserve(3 * n);
    for (std::uint32_t t = 0; t < n; ++t) {
        if (normal[t] == Vec3f(0.0f)) continue;
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t u = mesh.tri_vertices[t][k], v = mesh.tri_vertices[t][(k + 1) % 3];
            if (u != v) sides.push_back({std::min(u, v), std::max(u, v), t, u < v});
        }
    }
    std::sort(sides.begin(), sides.end(), [](const Side& a, const Side& b) {
        return std::tie(a.lo, a.hi, a.tri) < std::tie(b.lo, b.hi, b.tri);
    });
    std::vector<std::uint32_t> edge_first;
    for (std::size_t i = 0; i < sides.size();) {
        std::size_t j = i + 1;
        while (j < sides.size() && sides[j].lo == sides[i].lo && sides[j].hi == sides[i].hi) ++j;
        edge_first.push_back(static_cast<std::uint32_t>(i));
        i = j;
    }
    edge_first.push_back(static_cast<std::uint32_t>(sides.size()));
    const BBox bounds = scene.bounds();
    const float far = 4.0f * std::max(length(bounds.hi - bounds.lo), 1e-6f);
    auto position = [&](std::uint32_t welded) {
        return scene.positions[mesh.vertex_position[welded]];
    };
    auto to_light = [&](const Light& light, const Vec3f& p) {
        return light.kind == Light::Kind::Point ? light.vector - p : -light.vector;
    };
    // The casting edges: silhouettes seen from each light, and borders.
    struct Caster {
        std::uint32_t light, edge;
    };
    std::vector<Caster> casters;
    const std::size_t lights = std::min<std::size_t>(lighting.lights.size(), 32);
    for (std::uint32_t l = 0; l < lights; ++l) {
        const Light& light = lighting.lights[l];
        for (std::uint32_t e = 0; e + 1 < edge_first.size(); ++e) {
            const std::uint32_t i = edge_first[e], j = edge_first[e + 1];
            if (j - i > 2) continue;  // non-manifold
            if (j - i == 2) {
                const Side& s0 = sides[i];
                const Side& s1 = sides[i + 1];
                const Vec3f mid = (position(s0.lo) + position(s0.hi)) * 0.5f;
                const Vec3f n1 = s0.forward != s1.forward ? normal[s1.tri] : -normal[s1.tri];
                const Vec3f towards = to_light(light, mid);
                if ((dot(normal[s0.tri], towards) > 0.0f) == (dot(n1, towards) > 0.0f)) continue;
            }
            casters.push_back({l, e});
        }
    }
    const Vec3f eye = view.eye();
    return gather_chunks<FeatureSegment>(
        static_cast<int>(casters.size()), 16, threads,
        [&](int c0, int c1, std::vector<FeatureSegment>& out) {
            std::vector<std::uint32_t> stack, ring, ignored;
            std::vector<float> cuts;
            std::vector<std::uint8_t> states;
            for (int ci = c0; ci < c1; ++ci) {
                const Caster& caster = casters[static_cast<std::size_t>(ci)];
                const Light& light = lighting.lights[caster.light];
                const Side& side = sides[edge_first[caster.edge]];
                const std::uint32_t lo = side.lo, hi = side.hi;
                Wedge wedge;
                if (!make_wedge(light, position(lo), position(hi), lo, hi, wedge)) continue;
                const std::uint32_t edge_tag = caster.light << 26 | (caster.edge & 0x3ffffffu);
                // The triangles around the casting edge's ends do not hide its shadow's boundary:
                // rays from it to the light graze them.
                ring.clear();
                for (std::uint32_t v : {lo, hi})
                    ring.insert(ring.end(), mesh.ring_triangles.begin() + mesh.ring_offsets[v],
                                mesh.ring_triangles.begin() + mesh.ring_offsets[v + 1]);
                std::sort(ring.begin(), ring.end());
                stack.assign(1, 0u);
                while (!stack.empty()) {
                    const BvhNode& node = bvh.nodes[stack.back()];
                    stack.pop_back();
                    if (!box_meets_wedge(node.bounds, wedge)) continue;
                    if (!node.is_leaf()) {
                        stack.push_back(node.first + 1);
                        stack.push_back(node.first);
                        continue;
                    }
                    for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
                        const std::uint32_t t = bvh.prim_indices[k];
                        if (normal[t] == Vec3f(0.0f) ||
                            std::binary_search(ring.begin(), ring.end(), t))
                            continue;
                        // Receivers face the light on the side the eye sees.
                        const Vec3f p0 = corner(scene, t, 0);
                        const Vec3f seen = dot(normal[t], eye - p0) < 0.0f ? -normal[t] : normal[t];
                        if (!(dot(seen, to_light(light, p0)) > 0.0f)) continue;
                        float g[3];
                        for (int c = 0; c < 3; ++c)
                            g[c] = dot(wedge.normal, corner(scene, t, c) - wedge.origin);
                        FeatureSegment seg;
                        if (!zero_segment(scene, mesh, t, g, edge_tag, seg)) continue;
                        // Clipped to the wedge: each side's function is linear along the segment.
                        float ta = 0.0f, tb = 1.0f;
                        int clip_a = -1, clip_b = -1;
                        for (int j = 0; j < 3; ++j) {
                            const float fa = wedge.side(j, seg.p0), fb = wedge.side(j, seg.p1);
                            if (fa < 0.0f && fb < 0.0f) {
                                ta = 1.0f;
                                tb = 0.0f;
                                break;
                            }
                            if (fa < 0.0f) {
                                const float at = fa / (fa - fb);
                                if (at > ta) {
                                    ta = at;
                                    clip_a = j;
                                }
                            } else if (fb < 0.0f) {
                                const float at = fa / (fa - fb);
                                if (at < tb) {
                                    tb = at;
                                    clip_b = j;
                                }
                            }
                        }
                        if (!(ta < tb)) continue;
                        // A clipped end on a side ray is that ray's point on the receiver's plane,
                        // the same bits for the wedges of both edges at that end.
                        auto clipped_end = [&](int j, float at, Vec3f& p, EndpointKey& key) {
                            p = seg.p0 + (seg.p1 - seg.p0) * at;
                            key = {};
                            if (wedge.end[j] == kNoIndex) return;
                            const float s =
                                dot(normal[t], p0 - wedge.from[j]) / dot(normal[t], wedge.along[j]);
                            if (!std::isfinite(s)) return;
                            p = wedge.from[j] + wedge.along[j] * s;
                            key = {wedge.end[j], t, kSideTag | caster.light};
                        };
                        Vec3f a = seg.p0, b = seg.p1;
                        EndpointKey key_a = seg.key0, key_b = seg.key1;
                        if (clip_a >= 0) clipped_end(clip_a, ta, a, key_a);
                        if (clip_b >= 0) clipped_end(clip_b, tb, b, key_b);
                        if (a == b) continue;
                        // Only what the view shows.
                        const float za = view.depth(a), zb = view.depth(b);
                        if (!(za > view.near_depth() && zb > view.near_depth())) continue;
                        const Point2 ia = view.project(a), ib = view.project(b);
                        const float margin = 4.0f;
                        if (std::max(ia.x, ib.x) < -margin ||
                            std::min(ia.x, ib.x) > view.width() + margin ||
                            std::max(ia.y, ib.y) < -margin ||
                            std::min(ia.y, ib.y) > view.height() + margin)
                            continue;
                        // Where a ray to the light meets nothing else, the boundary is seen.
                        ignored.assign(ring.begin(), ring.end());
                        ignored.insert(std::upper_bound(ignored.begin(), ignored.end(), t), t);
                        VisibilitySettings rays;
                        rays.max_invisibility = 1;
                        auto lit = [&](float s) {
                            // Evenly on the image: depth is linear along the segment, its inverse
                            // along the image.
                            const float u = s * za / ((1.0f - s) * zb + s * za);
                            const Vec3f x = a + (b - a) * u;
                            const Vec3f target = light.kind == Light::Kind::Point
                                                     ? light.vector
                                                     : x - normalize(light.vector) * far;
                            return count_occluders(accel, x, target, ignored, rays) == 0;
                        };
                        const float image_length = portable::hypot(ib.x - ia.x, ib.y - ia.y);
                        const int samples =
                            std::max(1, static_cast<int>(std::ceil(image_length / kShadowStep)));
                        auto sample_s = [&](int i) {
                            return (static_cast<float>(i) + 0.5f) / static_cast<float>(samples);
                        };
                        cuts.assign(1, 0.0f);
                        states.clear();
                        bool previous = false;
                        for (int i = 0; i < samples; ++i) {
                            const bool state = lit(sample_s(i));
                            if (i > 0 && state != previous) {
                                float x0 = sample_s(i - 1), x1 = sample_s(i);
                                while ((x1 - x0) * image_length > kShadowPrecision) {
                                    const float mid = 0.5f * (x0 + x1);
                                    if (mid <= x0 || mid >= x1) break;
                                    (lit(mid) == previous ? x0 : x1) = mid;
                                }
                                cuts.push_back(0.5f * (x0 + x1));
                                states.push_back(previous ? 1 : 0);
                            }
                            previous = state;
                        }
                        states.push_back(previous ? 1 : 0);
                        cuts.push_back(1.0f);
                        for (std::size_t r = 0; r < states.size(); ++r) {
                            if (!states[r]) continue;
                            const bool first = r == 0, last = r + 1 == states.size();
                            auto at = [&](float s) {
                                return a + (b - a) * (s * za / ((1.0f - s) * zb + s * za));
                            };
                            FeatureSegment piece;
                            piece.type = EdgeType::Shadow;
                            piece.faces = {t, kNoIndex};
                            piece.p0 = first ? a : at(cuts[r]);
                            piece.p1 = last ? b : at(cuts[r + 1]);
                            if (first) piece.key0 = key_a;
                            if (last) piece.key1 = key_b;
                            if (piece.p0 != piece.p1) out.push_back(piece);
                        }
                    }
                }
            }
        });
}

}  // namespace toonray::ink
