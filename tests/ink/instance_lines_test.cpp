// Ink lines on instances: culling by the plane tree, normal cones and the view changes no
// segment; the mesh edges are those of the flattened scene; intersection lines between
// instances; strokes styled by their instance's object; per-mesh work kept across frames.

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <cmath>
#include <map>
#include <memory>
#include <numbers>
#include <set>
#include <tuple>
#include <vector>

#include "toonray/accel/scene_accel.h"
#include "toonray/ink/ink.h"
#include "toonray/ink/instance_lines.h"
#include "toonray/ink/strokes.h"
#include "support/instance_scenes.h"
#include "ink/ink_scenes.h"

using namespace toonray;
using namespace toonray::ink;

namespace {

std::array<std::uint32_t, 3> bits(const Vec3f& v) {
    return std::bit_cast<std::array<std::uint32_t, 3>>(v);
}

bool same_segment(const FeatureSegment& a, const FeatureSegment& b) {
    return bits(a.p0) == bits(b.p0) && bits(a.p1) == bits(b.p1) && a.key0 == b.key0 &&
           a.key1 == b.key1 && a.type == b.type && a.faces == b.faces &&
           a.face_instance == b.face_instance && a.smooth == b.smooth &&
           a.certainly_hidden == b.certainly_hidden;
}

// Four rows of the test scene's instances (more than one chunk of instances), which cross
// each other and the ground.
Scene four_rows() {
    Scene scene = test_support::instanced_test_scene();
    const std::size_t row = scene.instances.size();
    for (int k = 1; k < 4; ++k)
        for (std::size_t i = 0; i < row; ++i) {
            Affine3 moved = scene.instances[i].to_world;
            moved.m[2][3] -= 14.0 * k;
            scene.add_instance(scene.instances[i].mesh, moved, scene.instances[i].object);
        }
    return scene;
}

std::vector<FeatureSegment> instance_lines(const Scene& scene, const TriangleAccel& accel,
                                           const CameraSpec& camera, InstanceLineCache& cache,
                                           const InstanceLineOptions& options = {},
                                           FeatureEdgeSettings settings = {}, int w = 320,
                                           int h = 200) {
    const ViewPlane plane = make_view_plane(camera, w, h);
    const ScreenProjection view(plane, w, h);
    const WeldedMesh own = weld_vertices(scene);
    std::vector<FeatureSegment> out;
    add_instance_segments(scene, accel, own, plane, view, 4.0f, settings, 2, cache, out, options);
    return out;
}

TEST(InstanceLines, CullingChangesNoSegment) {
    const Scene scene = test_support::instanced_test_scene();
    const TriangleAccel accel = build_scene_accel(scene);
    const WeldedMesh own = weld_vertices(scene);
    InstanceLineCache a, b, c;  // the meshes' work is kept across views
    int culled_views = 0;
    for (int turn = 0; turn < 360; turn += 90) {
        for (const Vec3f& target : {Vec3f(0, 1, 0), Vec3f(-6, 0.5f, -3), Vec3f(6, 0, -8)}) {
            const CameraSpec around = test_support::orbit_camera(
                test_support::instanced_test_camera(), static_cast<float>(turn));
            const CameraSpec camera = test_support::looking_at(around.eye, target);
            for (const bool hidden : {false, true}) {
                FeatureEdgeSettings settings;
                settings.certainly_hidden = hidden;
                const auto culled = instance_lines(scene, accel, camera, a, {}, settings);
                const auto all = instance_lines(scene, accel, camera, b, {false, false}, settings);
                // Culling may drop only segments that visibility would clip away.
                std::vector<FeatureSegment> kept;
                const ScreenProjection view(make_view_plane(camera, 320, 200), 320, 200);
                VisibilitySettings visibility;
                visibility.max_invisibility = 1;
                std::vector<std::uint8_t> shows(all.size(), 0);
                for (const EdgePiece& piece : split_by_visibility(
                         all, VisibilityContext{scene, own, accel, view, &b}, visibility, 2))
                    shows[piece.segment] = 1;
                for (std::size_t i = 0; i < all.size(); ++i)
                    if (shows[i]) kept.push_back(all[i]);
                culled_views += culled.size() < all.size();
                // Every segment that shows is among the culled ones, in the same order.
                std::size_t j = 0;
                for (const FeatureSegment& s : kept) {
                    while (j < culled.size() && !same_segment(culled[j], s)) ++j;
                    ASSERT_LT(j, culled.size())
                        << "a segment in view was culled (turn " << turn << ")";
                }
                // And the cones never drop a segment of an instance in full view.
                const auto no_cones =
                    instance_lines(scene, accel, camera, c, {false, true}, settings);
                ASSERT_EQ(no_cones.size(), culled.size());
                for (std::size_t i = 0; i < culled.size(); ++i)
                    ASSERT_TRUE(same_segment(no_cones[i], culled[i])) << i;
            }
        }
    }
    EXPECT_GT(culled_views, 5);  // the test saw culling at work
}

TEST(InstanceLines, ConesChangeNoSegmentCloseToASurface) {
    // A wavy sheet seen from just above it, at grazing angles: silhouettes on the crests near
    // the eye and far away, from the plane tree's nodes at every distance (the sheet has no
    // smooth triangles, so no cone is tested).
    Scene scene;
    scene.materials.emplace_back("sheet");
    auto sheet = std::make_shared<TriangleMesh>();
    constexpr int kCells = 96;
    auto id = [](int i, int k) { return static_cast<std::uint32_t>(i * (kCells + 1) + k); };
    for (int i = 0; i <= kCells; ++i)
        for (int k = 0; k <= kCells; ++k) {
            const float x = 12.0f * static_cast<float>(i) / kCells - 6.0f;
            const float z = 12.0f * static_cast<float>(k) / kCells - 6.0f;
            sheet->positions.emplace_back(x, 0.25f * std::sin(1.7f * x) * std::cos(1.3f * z), z);
        }
    for (int i = 0; i < kCells; ++i)
        for (int k = 0; k < kCells; ++k) {
            sheet->add_triangle({id(i, k), id(i, k + 1), id(i + 1, k + 1)}, 0, 0);
            sheet->add_triangle({id(i, k), id(i + 1, k + 1), id(i + 1, k)}, 0, 0);
        }
    scene.add_instance(scene.add_mesh(sheet),
                       test_support::placed(0, 1, 0, 0.3, Vec3f(1.0f), Vec3f(0.5f, 0.0f, -0.2f)),
                       "sheet");
    const TriangleAccel accel = build_scene_accel(scene);
    InstanceLineCache a, b;
    int views = 0;
    for (const Vec3f& eye : {Vec3f(-5.5f, 0.3f, -5.0f), Vec3f(0.2f, 0.28f, 0.1f),
                             Vec3f(2.9f, 0.33f, -1.7f), Vec3f(-1.3f, 0.6f, 2.2f)})
        for (const Vec3f& target : {Vec3f(6, 0, 6), Vec3f(-6, -0.5f, 4), Vec3f(0, -1, 0)}) {
            const CameraSpec camera = test_support::looking_at(eye, target);
            const auto with_cones = instance_lines(scene, accel, camera, a);
            const auto without = instance_lines(scene, accel, camera, b, {false, true});
            ASSERT_EQ(with_cones.size(), without.size());
            for (std::size_t i = 0; i < with_cones.size(); ++i)
                ASSERT_TRUE(same_segment(with_cones[i], without[i])) << i;
            views += !with_cones.empty();
        }
    EXPECT_GE(views, 10);  // the views have lines to keep
}

TEST(InstanceLines, AnEyeInAFacesPlaneKeepsTheSilhouetteBesideIt) {
    // A flat strip (in y = 0) bent up by 20 degrees along x = 0. From an eye in the flat part's
    // plane, n . (eye - p) is exactly 0 for the flat faces, which do not face the eye, and
    // positive for the bent ones; from an eye below the strip and a hair (1e-4) above the bent
    // part's plane, it is negative for the flat faces and just positive for the bent ones. The
    // bend is a silhouette from both, and the plane tree's bound for the node holding it is 0
    // at one end: culling must keep it (testing the low end against -margin instead of
    // +margin drops the first, the high end against +margin instead of -margin the second).
    Scene scene;
    scene.materials.emplace_back("strip");
    auto strip = std::make_shared<TriangleMesh>();
    const float slope = std::tan(20.0f * std::numbers::pi_v<float> / 180.0f);
    for (const float x : {-2.0f, 0.0f, 2.0f})
        for (const float z : {-1.0f, 1.0f})
            strip->positions.emplace_back(x, x > 0 ? x * slope : 0, z);
    for (std::uint32_t i = 0; i < 2; ++i) {
        const std::uint32_t a = 2 * i, b = 2 * i + 1, c = 2 * i + 3, d = 2 * i + 2;
        strip->add_triangle({a, b, c}, 0, 0);
        strip->add_triangle({a, c, d}, 0, 0);
    }
    scene.add_instance(scene.add_mesh(strip), Affine3{}, "strip");
    const TriangleAccel accel = build_scene_accel(scene);
    for (const Vec3f& eye : {Vec3f(-6, 0, 0.3f), Vec3f(-6, -6 * slope + 1e-4f, 0.3f)}) {
        const CameraSpec camera = test_support::looking_at(eye, Vec3f(1, 0.2f, 0));
        InstanceLineCache a, b;
        const auto with_cones = instance_lines(scene, accel, camera, a);
        const auto without = instance_lines(scene, accel, camera, b, {false, true});
        ASSERT_EQ(with_cones.size(), without.size());
        for (std::size_t i = 0; i < with_cones.size(); ++i)
            ASSERT_TRUE(same_segment(with_cones[i], without[i])) << i;
        const auto bend = std::find_if(with_cones.begin(), with_cones.end(), [](const auto& s) {
            return s.type == EdgeType::Silhouette && s.p0.x == 0.0f && s.p1.x == 0.0f;
        });
        EXPECT_NE(bend, with_cones.end()) << eye.y;
    }
}

// The flattened scene's segments of the instances' mesh edges (its own triangles are the
// ground; everything else came from instances) against the instanced ones, by their ends.
TEST(InstanceLines, MeshEdgesAreTheFlattenedScenes) {
    const Scene scene = test_support::instanced_test_scene();
    const Scene flat = flatten_instances(scene);
    const TriangleAccel accel = build_scene_accel(scene), flat_accel = build_scene_accel(flat);
    const CameraSpec camera = test_support::instanced_test_camera();
    FeatureEdgeSettings settings;
    settings.intersections = false;
    InstanceLineCache cache;
    const auto inst = instance_lines(scene, accel, camera, cache, {false, false}, settings);
    const WeldedMesh welded = weld_vertices(flat);
    const auto flat_segments =
        find_feature_edges(flat, welded, flat_accel.bvh(), camera.eye, settings, 2);
    using Key = std::tuple<std::array<std::uint32_t, 3>, std::array<std::uint32_t, 3>, int>;
    std::set<Key> a, b;
    for (const FeatureSegment& s : inst)
        if (!s.smooth) a.insert({bits(s.p0), bits(s.p1), static_cast<int>(s.type)});
    for (const FeatureSegment& s : flat_segments)
        if (!s.smooth && flat.tri_object[s.faces[0]] != 1)  // not the ground
            b.insert({bits(s.p0), bits(s.p1), static_cast<int>(s.type)});
    std::vector<Key> common;
    std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(common));
    // Silhouettes are classified from object-space normals, creases judged in object space:
    // a few grazing or borderline edges may go the other way.
    EXPECT_GE(common.size() * 100, a.size() * 99) << common.size() << " of " << a.size();
    EXPECT_GE(common.size() * 100, b.size() * 99) << common.size() << " of " << b.size();
    // Smooth contours: as many on each side, within a few.
    const auto smooth = [](const auto& v) {
        return std::count_if(v.begin(), v.end(), [](const FeatureSegment& s) { return s.smooth; });
    };
    EXPECT_NEAR(double(smooth(inst)), double(smooth(flat_segments)), 0.02 * double(smooth(inst)));
    EXPECT_GT(smooth(inst), 50);
}

// Each instance's mesh edges come in the mesh's edge order, by welded ends (as the flattened
// scene lists them), however the plane tree found them: here hundreds of silhouettes an
// instance, of a faceted sphere (no vertex normals, so every silhouette is a mesh edge).
TEST(InstanceLines, EachInstancesMeshEdgesComeInEdgeOrder) {
    const auto smooth_ball = test_support::sphere_mesh(40, 80, 0);
    auto ball = std::make_shared<TriangleMesh>();
    ball->positions = smooth_ball->positions;
    for (const auto& tri : smooth_ball->tri_positions) ball->add_triangle(tri, 0, 0);
    Scene scene;
    scene.materials.emplace_back("ball");
    const std::uint32_t mesh = scene.add_mesh(ball);
    for (int i = 0; i < 3; ++i)
        scene.add_instance(mesh,
                           test_support::placed(0, 1, 0, 0.4 * i, Vec3f(1.0f),
                                                Vec3f(3.0f * static_cast<float>(i - 1), 0, 0)),
                           "ball." + std::to_string(i));
    const TriangleAccel accel = build_scene_accel(scene);
    FeatureEdgeSettings settings;
    settings.intersections = false;
    for (const Vec3f& eye : {Vec3f(2, 3, 9), Vec3f(-7, -2, 4)}) {
        InstanceLineCache cache;
        const auto lines = instance_lines(scene, accel, test_support::looking_at(eye, Vec3f(0)),
                                          cache, {}, settings);
        std::map<std::uint32_t, std::vector<std::pair<std::uint32_t, std::uint32_t>>> ends;
        for (const FeatureSegment& s : lines)
            if (!s.smooth) ends[s.key0.instance].push_back({s.key0.a, s.key1.a});
        ASSERT_EQ(ends.size(), 3u);
        for (const auto& [instance, edges] : ends) {
            EXPECT_GT(edges.size(), 100u) << instance;
            EXPECT_TRUE(std::is_sorted(edges.begin(), edges.end())) << instance;
            EXPECT_EQ(std::adjacent_find(edges.begin(), edges.end()), edges.end()) << instance;
        }
    }
}

TEST(InstanceLines, IntersectionsAreTheFlattenedScenes) {
    const Scene scene = test_support::instanced_test_scene();
    const Scene flat = flatten_instances(scene);
    const TriangleAccel accel = build_scene_accel(scene), flat_accel = build_scene_accel(flat);
    const CameraSpec camera = test_support::instanced_test_camera();
    InstanceLineCache cache;
    const auto inst = instance_lines(scene, accel, camera, cache, {false, false});
    const auto flat_segments =
        find_feature_edges(flat, weld_vertices(flat), flat_accel.bvh(), camera.eye, {}, 2);
    // By their ends, and whether they join two instances (two objects, flattened).
    using Ends = std::tuple<std::array<std::uint32_t, 3>, std::array<std::uint32_t, 3>, bool>;
    std::set<Ends> a, b;
    int between = 0;
    for (const FeatureSegment& s : inst) {
        if (s.type != EdgeType::Intersection) continue;
        const bool two = s.face_instance[0] != s.face_instance[1];
        a.insert({bits(s.p0), bits(s.p1), two});
        between += two;
    }
    for (const FeatureSegment& s : flat_segments)
        if (s.type == EdgeType::Intersection)
            b.insert({bits(s.p0), bits(s.p1),
                      flat.tri_object[s.faces[0]] != flat.tri_object[s.faces[1]]});
    EXPECT_GT(between, 20);      // pot.1 and pot.2 cross
    EXPECT_GT(a.size(), 1000u);  // and the teapot's spout and handle cross its body
    std::vector<Ends> only_a, only_b;
    std::set_difference(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(only_a));
    std::set_difference(b.begin(), b.end(), a.begin(), a.end(), std::back_inserter(only_b));
    // Between instances the crossings are found from the same world corners: the same
    // segments. Within a mesh the pairs are found in object space and crossed again in the
    // world: a pair that only touches may be found on one side and not the other.
    EXPECT_LE(200 * (only_a.size() + only_b.size()), a.size())
        << only_a.size() << " only instanced, " << only_b.size() << " only flattened";
    for (const Ends& e : only_a) EXPECT_FALSE(std::get<2>(e));
    for (const Ends& e : only_b) EXPECT_FALSE(std::get<2>(e));
}

TEST(InstanceLines, StrokesTakeTheirInstancesObject) {
    const Scene scene = test_support::instanced_test_scene();
    const TriangleAccel accel = build_scene_accel(scene);
    InkSettings settings;
    settings.styles = parse_line_styles("match object=pot.3 color=#ff0000\n", "test.style");
    InkLines lines;
    draw_ink_lines(scene, accel, test_support::instanced_test_camera(), 320, 200, settings, 2,
                   lines);
    int red = 0;
    for (const Stroke& s : lines.strokes) red += lines.styles[s.style].colour == Vec3f(1, 0, 0);

    EXPECT_GT(red, 0);
    for (const FeatureSegment& s : lines.segments) {
        const auto [object, material] = style_source(scene, s);
        if (s.face_instance[0] == 3 && s.face_instance[1] == 3) {
            EXPECT_EQ(scene.objects[object], "pot.3");
        }
        (void)material;
    }
    // Keys of different instances never meet: a stroke's pieces are of one instance.
    std::map<EndpointKey, std::set<std::uint32_t>> owners;
    for (const FeatureSegment& s : lines.segments)
        for (const EndpointKey& k : {s.key0, s.key1})
            if (k.a != kNoIndex) owners[k].insert(s.face_instance[0]);
    for (const auto& [key, instances] : owners)
        if (key.c == kNoIndex) {
            EXPECT_EQ(instances.size(), 1u);
        }
}

bool same_piece(const EdgePiece& a, const EdgePiece& b) {
    return a.segment == b.segment &&
           std::bit_cast<std::uint32_t>(a.t0) == std::bit_cast<std::uint32_t>(b.t0) &&
           std::bit_cast<std::uint32_t>(a.t1) == std::bit_cast<std::uint32_t>(b.t1) &&
           bits(a.p0) == bits(b.p0) && bits(a.p1) == bits(b.p1) && a.key0 == b.key0 &&
           a.key1 == b.key1 && a.type == b.type && a.invisibility == b.invisibility &&
           std::memcmp(&a.s0, &b.s0, sizeof a.s0) == 0 &&
           std::memcmp(&a.s1, &b.s1, sizeof a.s1) == 0;
}

// Visibility run chunk by chunk as the instances' segments are found gives the pieces that
// visibility over all of them gives, with only the segments a piece lies on, numbered after
// the segments already in the list.
TEST(InstanceLines, ChainingInPartsOfWholeInstancesGivesTheSameStrokes) {
    // The pieces of the own triangles' lines, then of the instances' lines and crossings,
    // chained all at once and in parts of at least 16 pieces.
    const Scene scene = four_rows();
    const TriangleAccel accel = build_scene_accel(scene);
    const WeldedMesh own = weld_vertices(scene);
    int crossings = 0;
    for (const Vec3f& eye : {Vec3f(9, 9, 16), Vec3f(-14, 5, 6), Vec3f(2, 3, -15)}) {
        const CameraSpec camera = test_support::looking_at(eye, Vec3f(0, 1, 0));
        const ViewPlane plane = make_view_plane(camera, 320, 200);
        const ScreenProjection view(plane, 320, 200);
        for (const bool hidden : {false, true}) {
            VisibilitySettings visibility;
            visibility.keep_hidden = hidden;
            visibility.max_invisibility = 1;
            std::vector<FeatureSegment> segments =
                find_feature_edges(scene, own, accel.bvh(), eye, FeatureEdgeSettings{}, 2);
            const std::size_t first = segments.size();
            InstanceLineCache cache;
            InstanceVisibility found{visibility, {}};
            add_instance_segments(scene, accel, own, plane, view, 4.0f, {}, 2, cache, segments, {},
                                  &found);
            const VisibilityContext context{scene, own, accel, view, &cache};
            std::vector<EdgePiece> pieces = split_by_visibility(
                std::span<const FeatureSegment>(segments).first(first), context, visibility, 2);
            pieces.insert(pieces.end(), found.pieces.begin(), found.pieces.end());
            ChainSettings chain;
            chain.hidden = hidden;
            const auto cuts = instance_chain_cuts(pieces, segments, first, segments.size(), 16);
            ASSERT_GT(cuts.size(), 4u);
            const auto whole = chain_pieces(pieces, chain, {});
            const auto parts = chain_pieces_in_parts(pieces, cuts, chain, {}, 2);
            ASSERT_EQ(parts.size(), whole.size());
            for (std::size_t i = 0; i < whole.size(); ++i) {
                EXPECT_EQ(parts[i].points, whole[i].points) << i;
                EXPECT_EQ(parts[i].segment, whole[i].segment) << i;
                EXPECT_EQ(parts[i].visible, whole[i].visible) << i;
            }
            crossings +=
                static_cast<int>(std::count_if(whole.begin(), whole.end(), [&](const Stroke& s) {
                    return s.type == EdgeType::Intersection && s.segment >= first;
                }));
        }
    }
    EXPECT_GT(crossings, 0);  // the instances' crossings were among the parts
}

// Short segments' rays are traced together, a batch of segments at a time; each segment's
// pieces must be those it gets traced alone, on the own triangles and through instances, with
// and without hidden pieces, and on any thread count (which cuts the batches differently).
TEST(InstanceLines, ShortSegmentsTracedTogetherGiveThePiecesOfEachAlone) {
    const Scene scene = four_rows();
    const TriangleAccel accel = build_scene_accel(scene);
    const WeldedMesh own = weld_vertices(scene);
    std::size_t short_segments = 0, hidden = 0, visible = 0, dropped = 0;
    for (const Vec3f& eye : {Vec3f(9, 9, 16), Vec3f(-14, 5, 6)}) {
        const CameraSpec camera = test_support::looking_at(eye, Vec3f(0, 1, 0));
        const ViewPlane plane = make_view_plane(camera, 320, 200);
        const ScreenProjection view(plane, 320, 200);
        InstanceLineCache cache;
        std::vector<FeatureSegment> segments =
            find_feature_edges(scene, own, accel.bvh(), eye, FeatureEdgeSettings{}, 2);
        const auto instanced = instance_lines(scene, accel, camera, cache);
        segments.insert(segments.end(), instanced.begin(), instanced.end());
        for (std::size_t i = 0; i < segments.size(); ++i) {
            const Point2 a = view.project(segments[i].p0), b = view.project(segments[i].p1);
            short_segments += std::hypot(a.x - b.x, a.y - b.y) < 3.0f;
        }
        const VisibilityContext context{scene, own, accel, view, &cache};
        for (const bool keep_hidden : {true, false}) {
            VisibilitySettings visibility;
            visibility.keep_hidden = keep_hidden;
            visibility.max_invisibility = 1;
            std::vector<EdgePiece> alone;
            for (std::size_t i = 0; i < segments.size(); ++i) {
                const auto one =
                    split_by_visibility(std::span(segments).subspan(i, 1), context, visibility, 1);
                for (EdgePiece piece : one) {
                    piece.segment = static_cast<std::uint32_t>(i);
                    alone.push_back(piece);
                }
            }
            for (const int threads : {1, 2}) {
                const std::vector<EdgePiece> together =
                    split_by_visibility(segments, context, visibility, threads);
                ASSERT_EQ(together.size(), alone.size()) << keep_hidden << " " << threads;
                for (std::size_t k = 0; k < alone.size(); ++k) {
                    EXPECT_EQ(together[k].segment, alone[k].segment) << k;
                    EXPECT_EQ(together[k].t0, alone[k].t0) << k;
                    EXPECT_EQ(together[k].t1, alone[k].t1) << k;
                    EXPECT_EQ(together[k].invisibility, alone[k].invisibility) << k;
                    EXPECT_EQ(together[k].key0, alone[k].key0) << k;
                    EXPECT_EQ(together[k].key1, alone[k].key1) << k;
                }
            }
            if (keep_hidden) {
                for (const EdgePiece& piece : alone) (piece.visible() ? visible : hidden) += 1;
                dropped += alone.size();
            } else {
                dropped -= alone.size();  // the hidden pieces that were not kept
            }
        }
    }
    // Many batches of short segments, both hidden and seen; without hidden pieces, many fewer.
    EXPECT_GT(short_segments, 2000u);
    EXPECT_GT(hidden, 500u);
    EXPECT_GT(visible, 500u);
    EXPECT_GT(dropped, 500u);
}

TEST(InstanceLines, VisibilityAsTheSegmentsAreFoundKeepsTheirPiecesOnly) {
    const Scene scene = four_rows();
    const TriangleAccel accel = build_scene_accel(scene);
    const WeldedMesh own = weld_vertices(scene);
    std::size_t dropped = 0, hidden_pieces = 0;
    for (const Vec3f& eye : {Vec3f(9, 9, 16), Vec3f(-14, 5, 6), Vec3f(2, 3, -15)}) {
        const CameraSpec camera = test_support::looking_at(eye, Vec3f(0, 1, 0));
        const ViewPlane plane = make_view_plane(camera, 320, 200);
        const ScreenProjection view(plane, 320, 200);
        for (const bool keep_hidden : {false, true}) {
            VisibilitySettings visibility;
            visibility.keep_hidden = keep_hidden;
            visibility.max_invisibility = keep_hidden ? 3 : 1;
            // All the segments, then visibility over them.
            InstanceLineCache all_cache;
            const auto all = instance_lines(scene, accel, camera, all_cache);
            ASSERT_FALSE(all.empty());
            const std::vector<EdgePiece> pieces = split_by_visibility(
                all, VisibilityContext{scene, own, accel, view, &all_cache}, visibility, 2);
            // Visibility as they are found, after two segments already in the list.
            InstanceLineCache cache;
            std::vector<FeatureSegment> found(2, all.front());
            InstanceVisibility early{visibility, {}};
            add_instance_segments(scene, accel, own, plane, view, 4.0f, {}, 2, cache, found, {},
                                  &early);
            ASSERT_EQ(early.pieces.size(), pieces.size());
            std::vector<std::uint32_t> number(all.size(), kNoIndex);
            std::uint32_t next = 2;
            for (const EdgePiece& p : pieces)
                if (number[p.segment] == kNoIndex) number[p.segment] = next++;
            ASSERT_EQ(found.size(), next);
            for (std::size_t i = 0; i < all.size(); ++i)
                if (number[i] != kNoIndex) {
                    ASSERT_TRUE(same_segment(found[number[i]], all[i])) << i;
                }
            for (std::size_t k = 0; k < pieces.size(); ++k) {
                EdgePiece expected = pieces[k];
                expected.segment = number[expected.segment];
                ASSERT_TRUE(same_piece(early.pieces[k], expected)) << k;
                hidden_pieces += !expected.visible();
            }
            dropped += all.size() + 2 - found.size();
        }
    }
    EXPECT_GT(dropped, 100u);       // segments without a piece were left out
    EXPECT_GT(hidden_pieces, 10u);  // and hidden pieces kept when asked for
}

TEST(InstanceLines, MeshWorkIsKeptAcrossFrames) {
    Scene scene = test_support::instanced_test_scene();
    const CameraSpec camera = test_support::instanced_test_camera();
    InkLines lines;
    for (int frame = 0; frame < 4; ++frame) {
        // The pots move, the balls stay; the eye moves.
        for (std::size_t i = 0; i < 6; ++i)
            scene.instances[i].to_world.m[0][3] += 0.01 * static_cast<double>(frame);
        const TriangleAccel accel = build_scene_accel(scene);
        draw_ink_lines(scene, accel, test_support::orbit_camera(camera, 5.0f * frame), 320, 200, {},
                       2, lines);
        EXPECT_EQ(lines.instances.mesh_builds, 2u);  // the teapot's and the sphere's, once
    }
    // A fresh cache finds the same segments as the one carried over the frames.
    InkLines fresh;
    const TriangleAccel accel = build_scene_accel(scene);
    draw_ink_lines(scene, accel, test_support::orbit_camera(camera, 15.0f), 320, 200, {}, 2, fresh);
    ASSERT_EQ(fresh.segments.size(), lines.segments.size());
    for (std::size_t i = 0; i < fresh.segments.size(); ++i)
        ASSERT_TRUE(same_segment(fresh.segments[i], lines.segments[i])) << i;
    EXPECT_TRUE(std::equal(fresh.coverage.data(), fresh.coverage.data() + fresh.coverage.size(),
                           lines.coverage.data()));
}

}  // namespace
