#include "toonray/ink/feature_edges.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <tuple>

#include "ink/ink_scenes.h"
#include "toonray/ink/mesh_topology.h"

namespace toonray {
namespace {

using ink::EdgeType;
using ink::FeatureSegment;
using test_support::add_box;
using test_support::add_quad;
using test_support::add_sphere;
using test_support::build_accel;

std::vector<FeatureSegment> edges_of(const Scene& s, const Vec3f& eye,
                                     const ink::FeatureEdgeSettings& settings = {},
                                     int threads = 1) {
    const TriangleAccel accel = build_accel(s);
    return ink::find_feature_edges(s, ink::weld_vertices(s), accel.bvh(), eye, settings, threads);
}

std::map<EdgeType, int> count_types(const std::vector<FeatureSegment>& segments) {
    std::map<EdgeType, int> n;
    for (const auto& s : segments) ++n[s.type];
    return n;
}

TEST(WeldVertices, JoinsEqualPositionsWithinAnObjectOnly) {
    Scene s;
    add_box(s, Vec3f(0.0f), Vec3f(1.0f), 0);  // 24 vertices, 8 positions
    add_box(s, Vec3f(0.0f), Vec3f(1.0f), 1);  // the same positions in another object
    const ink::WeldedMesh mesh = ink::weld_vertices(s);
    EXPECT_EQ(mesh.vertex_count(), 16u);
    // Every corner of a box touches 3 faces, 6 triangles at most; 4 or 5 with this split.
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
        const auto n = mesh.ring_offsets[v + 1] - mesh.ring_offsets[v];
        EXPECT_GE(n, 3u);
        EXPECT_LE(n, 6u);
    }
}

// One object: ids are numbered by first use over the triangles' corners, one per canonical
// position (the lowest index of the positions with its coordinates), with repeated positions
// (a box with split vertices) and without (the same box's triangles reversed over 8 positions).
TEST(WeldVertices, OneObjectNumbersPositionsByFirstUse) {
    Scene split;
    add_box(split, Vec3f(0.0f), Vec3f(1.0f), 0);  // 24 vertices, 8 positions
    Scene shared = split;
    // The same triangles over the 8 distinct positions, in reverse order.
    std::vector<Vec3f> distinct;
    for (auto& tri : shared.tri_positions)
        for (std::uint32_t& p : tri) {
            const Vec3f position = shared.positions[p];
            const auto at = std::find(distinct.begin(), distinct.end(), position);
            p = static_cast<std::uint32_t>(at - distinct.begin());
            if (at == distinct.end()) distinct.push_back(position);
        }
    shared.positions = distinct;
    std::reverse(shared.tri_positions.begin(), shared.tri_positions.end());
    for (const Scene* s : {&split, &shared}) {
        std::vector<std::uint32_t> canonical(s->positions.size()),
            id_of(s->positions.size(), kNoIndex);
        for (std::size_t i = 0; i < s->positions.size(); ++i)
            canonical[i] = static_cast<std::uint32_t>(
                std::find(s->positions.begin(), s->positions.end(), s->positions[i]) -
                s->positions.begin());
        std::vector<std::uint32_t> first_use;
        for (const auto& tri : s->tri_positions)
            for (std::uint32_t p : tri)
                if (id_of[canonical[p]] == kNoIndex) {
                    id_of[canonical[p]] = static_cast<std::uint32_t>(first_use.size());
                    first_use.push_back(canonical[p]);
                }
        for (bool one_object : {false, true}) {  // one object either way
            const ink::WeldedMesh mesh = ink::weld_vertices(*s, one_object);
            ASSERT_EQ(mesh.vertex_position, first_use);
            ASSERT_EQ(mesh.tri_vertices.size(), s->tri_positions.size());
            for (std::size_t t = 0; t < s->tri_positions.size(); ++t)
                for (int k = 0; k < 3; ++k)
                    EXPECT_EQ(mesh.tri_vertices[t][k], id_of[canonical[s->tri_positions[t][k]]]);
        }
    }
    EXPECT_EQ(ink::weld_vertices(split).vertex_count(), 8u);
}

TEST(FeatureEdges, BoxWithSplitVerticesHasCreasesAndSilhouettesButNoBorders) {
    Scene s;
    add_box(s, Vec3f(-1.0f), Vec3f(1.0f));
    // From a general direction three faces are seen: 6 silhouette edges, 3 visible creases and
    // 3 creases between back faces.
    const auto n = count_types(edges_of(s, Vec3f(5.0f, 4.0f, 3.0f)));
    EXPECT_EQ(n.count(EdgeType::Border), 0u);
    EXPECT_EQ(n.at(EdgeType::Silhouette), 6);
    EXPECT_EQ(n.at(EdgeType::Crease), 6);
    // The diagonals of the faces are flat: no line.
    EXPECT_EQ(n.size(), 2u);
}

TEST(FeatureEdges, CreaseAngleIsAThreshold) {
    // Two quads folded by 30 degrees along x = 0.
    Scene s;
    const float a = 30.0f * std::numbers::pi_v<float> / 180.0f;
    add_quad(s, Vec3f(-1, 0, 0), Vec3f(0, 0, 0), Vec3f(0, 1, 0), Vec3f(-1, 1, 0));
    const std::uint32_t base = static_cast<std::uint32_t>(s.positions.size());
    s.positions.push_back(Vec3f(std::cos(a), 0, std::sin(a)));
    s.positions.push_back(Vec3f(std::cos(a), 1, std::sin(a)));
    s.add_triangle({1, base, base + 1}, 0, 0);
    s.add_triangle({1, base + 1, 2}, 0, 0);
    const Vec3f eye(0, 0.5f, 5);
    ink::FeatureEdgeSettings settings;
    settings.crease_angle = 40.0f;
    EXPECT_EQ(count_types(edges_of(s, eye, settings)).count(EdgeType::Crease), 0u);
    settings.crease_angle = 20.0f;
    EXPECT_EQ(count_types(edges_of(s, eye, settings)).at(EdgeType::Crease), 1);
    EXPECT_EQ(count_types(edges_of(s, eye, settings)).at(EdgeType::Border), 6);
}

TEST(FeatureEdges, MaterialBoundaryBetweenFlatFaces) {
    Scene s;
    s.materials.emplace_back("red");
    const std::uint32_t a = test_support::add_vertex(s, Vec3f(0, 0, 0)),
                        b = test_support::add_vertex(s, Vec3f(1, 0, 0)),
                        c = test_support::add_vertex(s, Vec3f(1, 1, 0)),
                        d = test_support::add_vertex(s, Vec3f(0, 1, 0));
    s.add_triangle({a, b, c}, 0, 0);
    s.add_triangle({a, c, d}, 1, 0);
    const auto segments = edges_of(s, Vec3f(0.5f, 0.5f, 3.0f));
    const auto n = count_types(segments);
    EXPECT_EQ(n.at(EdgeType::Material), 1);
    EXPECT_EQ(n.at(EdgeType::Border), 4);
    for (const auto& seg : segments)
        if (seg.type == EdgeType::Material) {
            EXPECT_EQ(seg.faces[0], 0u);
            EXPECT_EQ(seg.faces[1], 1u);
        }
}

TEST(FeatureEdges, SmoothContourOfASphereLiesOnTheTrueContour) {
    Scene s;
    add_sphere(s, Vec3f(0.0f), 1.0f, 48, 96);
    const Vec3f eye(0.3f, 0.5f, 4.0f);
    const auto segments = edges_of(s, eye);
    // Smooth shading everywhere: no polygonal silhouettes, only smooth contours.
    int smooth = 0;
    for (const auto& seg : segments) {
        ASSERT_EQ(seg.type, EdgeType::Silhouette);
        ASSERT_TRUE(seg.smooth);
        ++smooth;
        // The exact sphere's contour: p . (p - eye) = 0 for |p| = 1; a facet is off by less
        // than its size (about 2 pi / 96).
        for (const Vec3f& p : {seg.p0, seg.p1})
            EXPECT_LT(std::abs(dot(normalize(p), normalize(p - eye))), 0.05f);
        EXPECT_NE(seg.key0, seg.key1);
    }
    EXPECT_GT(smooth, 96);
    // The contour is closed: every endpoint key is used by exactly two segments.
    std::map<ink::EndpointKey, int> uses;
    for (const auto& seg : segments) {
        ++uses[seg.key0];
        ++uses[seg.key1];
    }
    for (const auto& [key, n] : uses) EXPECT_EQ(n, 2);
}

TEST(FeatureEdges, PolygonalSilhouetteWithoutVertexNormals) {
    Scene s;
    add_sphere(s, Vec3f(0.0f), 1.0f, 12, 24);
    for (auto& n : s.tri_normals) n = {kNoIndex, kNoIndex, kNoIndex};
    const auto segments = edges_of(s, Vec3f(0.3f, 0.5f, 4.0f));
    int silhouettes = 0;
    for (const auto& seg : segments) {
        EXPECT_FALSE(seg.smooth);
        if (seg.type == EdgeType::Silhouette) ++silhouettes;
    }
    EXPECT_GE(silhouettes, 24);
}

TEST(IntersectTriangles, CrossingTrianglesGiveTheOverlapOfTheirSpans) {
    const std::array<Vec3f, 3> a{Vec3f(-1, -1, 0), Vec3f(1, -1, 0), Vec3f(0, 1, 0)};  // z = 0
    const std::array<Vec3f, 3> b{Vec3f(0, -2, -1), Vec3f(0, 2, -1), Vec3f(0, 0, 1)};  // x = 0
    ink::TriangleCrossing c;
    ASSERT_TRUE(ink::intersect_triangles(a, b, c));
    // On the line x = z = 0: a spans y in [-1, 1]; b at z = 0 spans y in [-1, 1].
    for (const Vec3f& p : c.p) {
        EXPECT_NEAR(p.x, 0.0f, 1e-6f);
        EXPECT_NEAR(p.z, 0.0f, 1e-6f);
    }
    EXPECT_NEAR(std::min(c.p[0].y, c.p[1].y), -1.0f, 1e-6f);
    EXPECT_NEAR(std::max(c.p[0].y, c.p[1].y), 1.0f, 1e-6f);
    // Touching (a corner on the plane, nothing across it) and parallel pairs do not cross.
    const std::array<Vec3f, 3> touching{Vec3f(0, 0, 0), Vec3f(1, 0, 1), Vec3f(0, 1, 1)};
    EXPECT_FALSE(ink::intersect_triangles(a, touching, c));
    const std::array<Vec3f, 3> above{Vec3f(-1, -1, 1), Vec3f(1, -1, 1), Vec3f(0, 1, 1)};
    EXPECT_FALSE(ink::intersect_triangles(a, above, c));
}

TEST(FeatureEdges, IntersectionLinesBetweenObjectsAndChainableKeys) {
    // A box pushed half-way through a large quad: the quad cuts it along a square loop. (The
    // quad's diagonal misses the box's corners: a loop through the corner where two triangles
    // of each meet has endpoints that do not chain.)
    Scene s;
    add_box(s, Vec3f(-0.5f), Vec3f(0.5f), 1);
    add_quad(s, Vec3f(-2, -2.3f, 0.1f), Vec3f(2, -2, 0.1f), Vec3f(2, 2.3f, 0.1f),
             Vec3f(-2, 2, 0.1f), 0, 2);
    ink::FeatureEdgeSettings settings;
    const auto segments = edges_of(s, Vec3f(1, 2, 5), settings);
    std::map<ink::EndpointKey, int> uses;
    float total = 0;
    for (const auto& seg : segments) {
        if (seg.type != EdgeType::Intersection) continue;
        EXPECT_NEAR(seg.p0.z, 0.1f, 1e-6f);
        EXPECT_NEAR(seg.p1.z, 0.1f, 1e-6f);
        total += length(seg.p1 - seg.p0);
        ++uses[seg.key0];
        ++uses[seg.key1];
    }
    EXPECT_NEAR(total, 4.0f, 1e-4f);  // the square's perimeter
    for (const auto& [key, n] : uses) EXPECT_EQ(n, 2) << key.a << " " << key.b << " " << key.c;
}

// Every pair of usable triangles sharing no corner position, tested directly: the intersection
// lines find_feature_edges must find, as (t, u) with t < u, and their ends.
std::map<std::pair<std::uint32_t, std::uint32_t>, std::array<Vec3f, 2>> brute_force_crossings(
    const Scene& s) {
    const ink::WeldedMesh mesh = ink::weld_vertices(s);
    auto corners = [&](std::uint32_t t) {
        const auto& v = s.tri_positions[t];
        return std::array<Vec3f, 3>{s.positions[v[0]], s.positions[v[1]], s.positions[v[2]]};
    };
    auto usable = [&](std::uint32_t t) {
        const auto p = corners(t);
        const float len = length(cross(p[1] - p[0], p[2] - p[0]));
        return len > 0.0f && std::isfinite(len);
    };
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::array<Vec3f, 2>> out;
    const auto n = static_cast<std::uint32_t>(s.triangle_count());
    for (std::uint32_t t = 0; t < n; ++t) {
        if (!usable(t)) continue;
        for (std::uint32_t u = t + 1; u < n; ++u) {
            if (!usable(u)) continue;
            bool share = false;
            for (std::uint32_t a : mesh.tri_vertices[t])
                for (std::uint32_t b : mesh.tri_vertices[u])
                    share = share || mesh.vertex_position[a] == mesh.vertex_position[b];
            ink::TriangleCrossing c;
            if (!share && ink::intersect_triangles(corners(t), corners(u), c))
                out[{t, u}] = {c.p[0], c.p[1]};
        }
    }
    return out;
}

std::map<std::pair<std::uint32_t, std::uint32_t>, std::array<Vec3f, 2>> intersection_lines(
    const std::vector<FeatureSegment>& segments, bool visible_only = false) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::array<Vec3f, 2>> out;
    for (const auto& seg : segments)
        if (seg.type == EdgeType::Intersection && !(visible_only && seg.certainly_hidden))
            out[{seg.faces[0], seg.faces[1]}] = {seg.p0, seg.p1};
    return out;
}

// A scene with crossings of every kind: a dense random soup, closed solids pushed through each
// other and through the soup (a sphere, boxes with split vertices), a box sharing a corner
// position with another object, and a degenerate triangle.
Scene crossing_scene() {
    Scene s = test_support::random_scene(400, 11);
    add_sphere(s, Vec3f(0.1f, 0.2f, 0.0f), 0.6f, 12, 24, 1);
    add_box(s, Vec3f(-0.3f, -0.9f, -0.4f), Vec3f(0.5f, 0.4f, 0.3f), 2);
    add_box(s, Vec3f(0.5f, 0.4f, 0.3f), Vec3f(1.2f, 1.1f, 0.9f), 3);  // touches box 2 at a corner
    const std::uint32_t v = test_support::add_vertex(s, Vec3f(0.2f, 0.2f, 0.2f));
    s.add_triangle({v, v, v}, 0, 4);
    return s;
}

TEST(FeatureEdges, IntersectionLinesAreEveryCrossingOfTestingAllPairs) {
    const Scene s = crossing_scene();
    const auto expected = brute_force_crossings(s);
    ASSERT_GT(expected.size(), 100u);
    ink::FeatureEdgeSettings settings;
    const Vec3f eye(3, 2, 4);
    const auto all = intersection_lines(edges_of(s, eye, settings));
    EXPECT_EQ(all, expected);
    // Without the lines on faces turned away from the eye on closed solids: the others, all of
    // them, and the solids' back faces do cross the soup.
    settings.certainly_hidden = false;
    const auto segments = edges_of(s, eye, settings);
    EXPECT_EQ(intersection_lines(segments), intersection_lines(edges_of(s, eye), true));
    EXPECT_LT(intersection_lines(segments).size() + 20, expected.size());
}

bool same_segments(const std::vector<FeatureSegment>& a, const std::vector<FeatureSegment>& b) {
    auto bits = [](const FeatureSegment& s) {
        return std::make_tuple(std::bit_cast<std::array<std::uint32_t, 3>>(s.p0),
                               std::bit_cast<std::array<std::uint32_t, 3>>(s.p1), s.key0, s.key1,
                               s.type, s.faces, s.smooth, s.certainly_hidden);
    };
    return std::equal(a.begin(), a.end(), b.begin(), b.end(),
                      [&](const auto& x, const auto& y) { return bits(x) == bits(y); });
}

TEST(FeatureEdges, WhatIsKeptFromTheLastFrameGivesTheSegmentsFoundAnew) {
    Scene s = crossing_scene();
    const Vec3f eye(3, 2, 4);
    ink::IntersectionCache cache;
    const ink::FeatureEdgeSettings settings;
    auto find = [&](ink::IntersectionCache* with) {
        const TriangleAccel accel = build_accel(s);
        return ink::find_feature_edges(s, ink::weld_vertices(s), accel.bvh(), eye, settings, 2,
                                       with);
    };
    auto check_frame = [&] {
        const auto kept = find(&cache);
        EXPECT_TRUE(same_segments(kept, find(nullptr)));
        EXPECT_EQ(intersection_lines(kept), brute_force_crossings(s));
    };
    // The first frame keeps no corners (a single frame would not read them); the second does.
    check_frame();
    EXPECT_TRUE(cache.corners.empty() && cache.tested.empty());
    check_frame();
    EXPECT_EQ(cache.corners.size(), s.triangle_count());
    EXPECT_EQ(cache.tested.size(), s.triangle_count());
    // The sphere moves through the soup and the boxes; the rest stays (the mesh edges are
    // the same, the intersection lines of the sphere are found again).
    for (std::size_t t = 0; t < s.triangle_count(); ++t)
        if (s.tri_object[t] == 1)
            for (std::uint32_t& v : s.tri_positions[t]) {
                s.positions.push_back(s.positions[v] + Vec3f(0.15f, -0.1f, 0.05f));
                v = static_cast<std::uint32_t>(s.positions.size() - 1);
            }
    check_frame();
    check_frame();  // nothing moved
    // A triangle of box 2 collapses to a line: the box is no longer closed, its mesh edges
    // change (new borders), and so do the certainly hidden lines.
    const std::size_t box_triangle = static_cast<std::size_t>(
        std::find(s.tri_object.begin(), s.tri_object.end(), 2u) - s.tri_object.begin());
    s.tri_positions[box_triangle][2] = s.tri_positions[box_triangle][1];
    check_frame();
    // And back.
    s = crossing_scene();
    check_frame();
}

// A grid over [0, 1]^2 placed by at(u, v), wound so that its normals follow du x dv.
template <class At>
void add_grid(Scene& s, int nu, int nv, At at, std::uint32_t object) {
    const auto base = static_cast<std::uint32_t>(s.positions.size());
    for (int j = 0; j <= nv; ++j)
        for (int i = 0; i <= nu; ++i)
            s.positions.push_back(at(static_cast<float>(i) / static_cast<float>(nu),
                                     static_cast<float>(j) / static_cast<float>(nv)));
    auto id = [&](int i, int j) { return base + static_cast<std::uint32_t>(j * (nu + 1) + i); };
    for (int j = 0; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            s.add_triangle({id(i, j), id(i + 1, j), id(i + 1, j + 1)}, 0, object);
            s.add_triangle({id(i, j), id(i + 1, j + 1), id(i, j + 1)}, 0, object);
        }
}

// Open surfaces whose normals all point up (+z), at `n` cells across: a ramp winding a little
// more than once around the z axis, whose start passes through its end; two sheets of one
// object, one passing through the other, twice; and a bumpy sheet that crosses nothing. Seen along z,
// each is made of triangles wound the same way: only their borders tell the ones that cross
// themselves from the one that cannot.
Scene upward_surfaces(int n) {
    Scene s;
    const float pi = std::numbers::pi_v<float>;
    add_grid(
        s, n, 5 * n,
        [&](float u, float v) {
            const float r = 1.0f + u, theta = 2.3f * pi * v;
            return Vec3f(r * std::cos(theta), r * std::sin(theta),
                         0.5f * (r - 1.513f) * (theta - 1.15f * pi));
        },
        0);
    s.objects.push_back("sheets");
    add_grid(
        s, 2 * n, 2 * n, [](float u, float v) { return Vec3f(3 + 2 * u, -1 + 2 * v, 0); }, 1);
    add_grid(
        s, 2 * n, 2 * n,
        [](float u, float v) {
            return Vec3f(3 + 2 * u, -1 + 2 * v, 0.2f * (u - 0.47f) + 0.01f * std::sin(7 * v));
        },
        1);
    // A small sheet through the middle of a larger one: their borders are apart, one inside
    // the other.
    s.objects.push_back("nested");
    add_grid(
        s, 2 * n, 2 * n, [](float u, float v) { return Vec3f(-1 + 2 * u, 3 + 2 * v, 0); }, 2);
    add_grid(
        s, n, n,
        [](float u, float v) {
            return Vec3f(-0.4f + 0.8f * u, 3.6f + 0.8f * v, 0.3f * (u - 0.53f));
        },
        2);
    s.objects.push_back("bumps");
    add_grid(
        s, 2 * n, 2 * n,
        [](float u, float v) {
            return Vec3f(-5 + 2 * u, -1 + 2 * v, 0.1f * std::sin(5 * u) * std::cos(4 * v));
        },
        3);
    return s;
}

TEST(FeatureEdges, SurfacesFacingOneWayThatCrossThemselvesKeepTheirIntersectionLines) {
    const Scene s = upward_surfaces(8);
    const auto expected = brute_force_crossings(s);
    ASSERT_GT(expected.size(), 40u);
    EXPECT_EQ(intersection_lines(edges_of(s, Vec3f(0.3f, -0.2f, 9.0f))), expected);
}

TEST(FeatureEdges, APatchFoldedUnderItsOwnBorderKeepsItsIntersectionLines) {
    // A disc whose profile folds back under itself and out again, one fold passing through the
    // other: its border is one circle, simple, but its normals turn over, so its triangles are
    // not all wound one way seen along any axis.
    Scene s;
    const float pi = std::numbers::pi_v<float>;
    add_grid(
        s, 24, 48,
        [&](float u, float v) {
            float rho = 0, z = 0;
            if (u <= 1.0f / 3) {
                rho = 2.4f * u;
            } else if (u <= 2.0f / 3) {
                const float t = 3 * u - 1;
                rho = 0.8f - 0.4f * t;
                z = 0.2f * t;
            } else {
                const float w = 0.6f * (3 * u - 2);
                rho = 0.4f + w;
                z = 0.2f - w + 2 * w * w;
            }
            const float theta = v < 1.0f ? 2 * pi * v : 0.0f;  // the seam's corners weld
            return Vec3f(rho * std::cos(theta), rho * std::sin(theta), z);
        },
        0);
    const auto expected = brute_force_crossings(s);
    ASSERT_GT(expected.size(), 40u);
    EXPECT_EQ(intersection_lines(edges_of(s, Vec3f(0.3f, -0.2f, 9.0f))), expected);
}

TEST(FindCrossings, SkippingPatchesThatCannotCrossThemselvesFindsTheSamePairs) {
    const Scene s = upward_surfaces(24);
    const auto n = static_cast<std::uint32_t>(s.triangle_count());
    const ink::WeldedMesh mesh = ink::weld_vertices(s);
    const TriangleAccel accel = build_accel(s);
    const ink::IndexedCorners corners_of{s.positions, s.tri_positions};
    std::vector<ink::RoundedNormal> normals(n);
    std::vector<std::uint8_t> usable(n);
    for (std::uint32_t t = 0; t < n; ++t) {
        const auto p = corners_of(t);
        const Vec3f c = cross(p[1] - p[0], p[2] - p[0]);
        usable[t] = length(c) > 0.0f;
        normals[t] = ink::round_normal(usable[t] ? normalize(c) : Vec3f(0.0f));
    }
    const ink::MeshTopology topology(s.tri_object, mesh, usable, s.objects.size());
    const auto across = topology.triangles_across(n);
    const ink::SurfacePatches patches{normals, across};
    auto found = [&](const ink::SurfacePatches* with) {
        std::map<std::pair<std::uint32_t, std::uint32_t>, std::array<Vec3f, 2>> out;
        for (const ink::PairCrossing& c :
             ink::find_crossings(accel.bvh(), corners_of, mesh, usable, nullptr, 2, with))
            out[{c.t, c.u}] = {c.crossing.p[0], c.crossing.p[1]};
        return out;
    };
    const auto all = found(nullptr);
    ASSERT_GT(all.size(), 150u);
    EXPECT_EQ(found(&patches), all);
}

// Triangles of every kind for the four-at-a-time pass: ordinary (of two sizes), degenerate (a repeated
// corner, collinear corners), so small that the normal underflows, with the eye in their plane,
// and (`overflowing`) so large that the normal overflows.
struct RandomTriangles {
    std::vector<Vec3f> positions;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    RandomTriangles(std::size_t n, const Vec3f& eye, bool overflowing) {
        std::mt19937 rng(7);
        std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
        std::uniform_int_distribution<int> kind(0, 9);
        for (std::size_t t = 0; t < n; ++t) {
            const auto first = static_cast<std::uint32_t>(positions.size());
            const int k = kind(rng);
            // Kind 4's volumes are 2^40 below the others': their sum rounds, by its order.
            const float scale = k == 7 && overflowing ? 3e19f
                                : k == 8              ? 1e-22f
                                : k == 4              ? 1e-3f
                                                      : 10.0f;
            for (int c = 0; c < 3; ++c)
                positions.push_back(Vec3f(unit(rng), unit(rng), unit(rng)) * scale);
            if (k == 5) positions[first + 2] = positions[first + 1];  // repeated corner
            if (k == 6)                                               // collinear
                positions[first + 2] =
                    positions[first] + (positions[first + 1] - positions[first]) * 2.0f;
            if (k == 9)  // in the plane y = eye.y: the eye is in the triangle's plane
                for (int c = 0; c < 3; ++c)
                    positions[first + static_cast<std::uint32_t>(c)].y = eye.y;
            triangles.push_back({first, first + 1, first + 2});
        }
    }
};

// The four-at-a-time per-triangle pass gives the scalar pass's bits: normals, rounded normals,
// usability and the eye's side on triangles of every kind, and the volume summed in triangle
// order and the box.
TEST(FeatureEdges, TheTrianglePassByFourGivesTheScalarPassesBits) {
    using Bits = std::array<std::uint32_t, 3>;
    const Vec3f eye(0.3f, 2.0f, 5.0f);
    const std::size_t n = 4003;  // the last three are left to the scalar pass
    for (const bool overflowing : {true, false}) {
        const RandomTriangles mesh(n, eye, overflowing);
        const ink::IndexedCorners corners_of{mesh.positions, mesh.triangles};
        std::vector<Vec3f> normal(n);
        std::vector<ink::RoundedNormal> rounded(n);
        std::vector<std::uint8_t> usable(n), side(n);
        BBox box;
        double volume = 0.0;
        const std::size_t done = ink::facts_by_four(
            corners_of, eye, n, {normal.data(), rounded.data(), usable.data(), side.data()}, box,
            volume);
        ASSERT_EQ(done, 4000u);

        BBox expected_box;
        std::vector<double> volumes;
        int zero = 0, in_plane = 0;
        for (std::size_t t = 0; t < done; ++t) {
            const auto p = corners_of(static_cast<std::uint32_t>(t));
            const Vec3f nt = unit_face_normal(p[0], p[1], p[2]);
            EXPECT_EQ(std::bit_cast<Bits>(normal[t]), std::bit_cast<Bits>(nt)) << t;
            EXPECT_EQ(rounded[t], ink::round_normal(nt)) << t;
            EXPECT_EQ(usable[t], nt != Vec3f(0.0f) ? 1 : 0) << t;
            const float facing = dot(nt, eye - p[0]);
            EXPECT_EQ(side[t], facing > 0   ? ink::kEyeInFront
                               : facing < 0 ? ink::kEyeBehind
                                            : 0)
                << t;
            zero += nt == Vec3f(0.0f);
            in_plane += nt != Vec3f(0.0f) && facing == 0;
            volumes.push_back(static_cast<double>(dot(p[0], cross(p[1], p[2]))));
            for (const Vec3f& q : p) expected_box.extend(q);
        }
        // Every kind occurs: degenerate, underflowing and overflowing triangles have no normal.
        EXPECT_GT(zero, overflowing ? 900 : 600);
        EXPECT_GT(in_plane, 100);
        EXPECT_EQ(box.lo, expected_box.lo);
        EXPECT_EQ(box.hi, expected_box.hi);
        if (!overflowing) {
            // The volume, finite here, is summed in triangle order: summed backwards its bits
            // differ.
            double forwards = 0.0, backwards = 0.0;
            for (const double v : volumes) forwards += v;
            for (auto v = volumes.rbegin(); v != volumes.rend(); ++v) backwards += *v;
            ASSERT_TRUE(std::isfinite(forwards));
            ASSERT_NE(std::bit_cast<std::uint64_t>(forwards),
                      std::bit_cast<std::uint64_t>(backwards));
            EXPECT_EQ(std::bit_cast<std::uint64_t>(volume), std::bit_cast<std::uint64_t>(forwards));
        }

        // Without rounded normals (no intersection search), the rest is the same.
        std::vector<Vec3f> normal2(n);
        std::vector<std::uint8_t> usable2(n), side2(n);
        BBox box2;
        double volume2 = 0.0;
        ink::facts_by_four(corners_of, eye, n,
                           {normal2.data(), nullptr, usable2.data(), side2.data()}, box2, volume2);
        for (std::size_t t = 0; t < done; ++t)
            EXPECT_EQ(std::bit_cast<Bits>(normal2[t]), std::bit_cast<Bits>(normal[t])) << t;
        EXPECT_EQ(usable2, usable);
        EXPECT_EQ(side2, side);
        EXPECT_EQ(std::bit_cast<std::uint64_t>(volume2), std::bit_cast<std::uint64_t>(volume));
    }
}

// The edges as for_each_edge gives them, and the triangles across each side, against a list
// of every side sorted by its ends: on a mesh with borders, edges of three and four sides,
// neighbours wound both ways, a degenerate triangle and a fan of 40 triangles (whose centre
// has more than 32 sides to sort).
TEST(MeshTopology, EdgesAndTheTrianglesAcrossThemMatchAListOfEverySide) {
    std::mt19937 rng(3);
    std::uniform_int_distribution<std::uint32_t> vertex(1, 30);
    std::vector<std::array<std::uint32_t, 3>> tris;
    for (int t = 0; t < 400; ++t) tris.push_back({vertex(rng), vertex(rng), vertex(rng)});
    for (std::uint32_t k = 0; k < 40; ++k) tris.push_back({0, 31 + k, 31 + (k + 1) % 40});
    ink::WeldedMesh mesh;
    mesh.tri_vertices = tris;
    mesh.vertex_position.resize(71);
    for (std::uint32_t v = 0; v < 71; ++v) mesh.vertex_position[v] = v;
    const std::size_t n = tris.size();
    std::vector<std::uint8_t> usable(n, 1);
    usable[7] = 0;
    const std::vector<std::uint32_t> objects(n, 0);
    const ink::MeshTopology topology(objects, mesh, usable, 1);

    // Every side of a usable triangle: (lo, hi) -> (triangle, corner, forward), in triangle and
    // corner order.
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::array<std::uint32_t, 3>>>
        expected;
    for (std::uint32_t t = 0; t < n; ++t) {
        if (!usable[t]) continue;
        for (std::uint32_t k = 0; k < 3; ++k) {
            const std::uint32_t u = tris[t][k], v = tris[t][(k + 1) % 3];
            if (u != v) expected[{std::min(u, v), std::max(u, v)}].push_back({t, k, u < v});
        }
    }
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::array<std::uint32_t, 3>>>
        found;
    int pairs = 0, larger = 0;
    topology.for_each_edge([&](std::uint32_t i, std::uint32_t j, std::uint32_t lo) {
        auto& sides = found[{lo, topology.sides[i].hi()}];
        EXPECT_TRUE(sides.empty());  // each edge once
        for (std::uint32_t s = i; s < j; ++s) {
            const ink::Side& side = topology.sides[s];
            EXPECT_EQ(side.hi(), topology.sides[i].hi());
            sides.push_back({side.tri(), side.corner(), side.forward() ? 1u : 0u});
        }
        pairs += j - i == 2;
        larger += j - i > 2;
    });
    EXPECT_EQ(found, expected);
    EXPECT_GT(pairs, 100);
    EXPECT_GT(larger, 10);

    const auto across = topology.triangles_across(n);
    std::vector<std::array<std::uint32_t, 3>> expected_across(n, {kNoIndex, kNoIndex, kNoIndex});
    int linked = 0;
    for (const auto& [edge, sides] : expected)
        if (sides.size() == 2 && sides[0][2] != sides[1][2]) {
            expected_across[sides[0][0]][sides[0][1]] = sides[1][0];
            expected_across[sides[1][0]][sides[1][1]] = sides[0][0];
            ++linked;
        }
    EXPECT_EQ(across, expected_across);
    EXPECT_GT(linked, 40);
}

TEST(FeatureEdges, SameForAnyThreadCount) {
    Scene s = test_support::random_scene(600, 7);
    add_sphere(s, Vec3f(0.2f), 0.5f, 16, 32, 1);
    const Vec3f eye(3, 2, 4);
    const auto one = edges_of(s, eye, {}, 1);
    const auto many = edges_of(s, eye, {}, 4);
    ASSERT_EQ(one.size(), many.size());
    int intersections = 0;
    for (std::size_t i = 0; i < one.size(); ++i) {
        EXPECT_EQ(one[i].p0, many[i].p0);
        EXPECT_EQ(one[i].p1, many[i].p1);
        EXPECT_EQ(one[i].type, many[i].type);
        EXPECT_EQ(one[i].key0, many[i].key0);
        intersections += one[i].type == EdgeType::Intersection;
    }
    EXPECT_GT(intersections, 50);  // a dense soup crosses itself a lot
}

}  // namespace
}  // namespace toonray
