#pragma once
/// Feature edges of a triangle scene seen from an eye: the lines of `--edges ink`, found on the
/// geometry rather than in pixel buffers.

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "toonray/accel/bvh.h"
#include "toonray/core/math.h"
#include "toonray/scene/light.h"
#include "toonray/scene/scene.h"

namespace toonray::ink {

/// What makes a segment a line. One type per segment: where an edge is several at once, the
/// first in this order wins (a silhouette crease is drawn as silhouette).
enum class EdgeType : std::uint8_t {
    Silhouette,    ///< polygonal contour (front face next to back face) or smooth contour
    Border,        ///< an edge with one face (or more than two: non-manifold)
    Crease,        ///< geometric normals of the two faces differ by more than the crease angle
    Material,      ///< the two faces have different materials
    Intersection,  ///< where two triangles cross
    Polyline,      ///< a polyline of the scene (OBJ `l`), drawn as it is (ink/polylines.h)
    Band,          ///< a boundary between cel bands on a surface, the terminator included
    Shadow,        ///< the boundary of a cast shadow on the surface receiving it
    Tone,          ///< a hatch stroke or screentone dot of a tone look (ink/tone.h)
};
inline constexpr int kEdgeTypeCount = 9;
/// "silhouette", "border", "crease", "material", "intersection", "polyline", "band", "shadow",
/// "tone".
const char* edge_type_name(EdgeType type);

/// Identifies a segment's endpoint so that segments meeting there can be chained without
/// comparing floats: a welded vertex {v, kNoIndex, kNoIndex}; a point on the welded edge
/// (a < b) {a, b, kNoIndex} (smooth contours); a point where the welded edge (a < b) of one
/// triangle crosses triangle t {a, b, t} (intersection lines). With instances, `instance` is
/// the instance whose mesh's welded vertices a and b are and `c_instance` the instance of
/// triangle c (kNoIndex: the scene's own triangles), so that instances of one mesh never
/// share a key.
struct EndpointKey {
    std::uint32_t a = kNoIndex, b = kNoIndex, c = kNoIndex;
    std::uint32_t instance = kNoIndex, c_instance = kNoIndex;
    auto operator<=>(const EndpointKey&) const = default;
};

struct FeatureSegment {
    Vec3f p0, p1;
    EndpointKey key0, key1;
    EdgeType type = EdgeType::Silhouette;
    /// Triangles the segment lies on (kNoIndex for none): their own surface must not hide it.
    std::array<std::uint32_t, 2> faces{kNoIndex, kNoIndex};
    /// The instance whose mesh each face is of (kNoIndex: the scene's own triangles).
    std::array<std::uint32_t, 2> face_instance{kNoIndex, kNoIndex};
    /// Smooth contours lie inside a triangle of a polygonal approximation of a smooth surface,
    /// where the facets around it may graze the line of sight: the triangles sharing a vertex
    /// with `faces[0]` are ignored as occluders too (see visibility.h).
    bool smooth = false;
    /// Both faces turn away from the eye on a closed, consistently wound object that does not
    /// surround the eye: a line of sight from here starts inside the solid, so at least one
    /// surface hides the segment, and visibility need not trace it to tell it is hidden.
    bool certainly_hidden = false;
};

struct FeatureEdgeSettings {
    float crease_angle = 40.0f;  ///< degrees between the faces' geometric normals
    bool silhouettes = true;
    bool borders = true;
    bool creases = true;
    bool materials = true;
    bool intersections = true;
    /// Smooth contours (Hertzmann & Zorin 2000) on triangles with a normal at every corner,
    /// instead of polygonal silhouettes on the edges where shading is smooth.
    bool smooth_contours = true;
    /// Also the intersection lines on a triangle turned away from the eye on a closed solid
    /// (FeatureSegment::certainly_hidden). Without them the visible lines are the same, and
    /// finding the intersection lines skips those triangles.
    bool certainly_hidden = true;
    /// Band lines along mesh edges whose faces do not shade smoothly into each other and fall
    /// in different bands at the edge's middle (each face's normal there, turned to the eye),
    /// under these lights and thresholds (light_lines.h has those inside triangles).
    bool bands = false;
    std::span<const Light> lights;
    std::span<const float> band_thresholds;
};

/// Vertices welded by exact position within each object: two triangle corners share a welded
/// vertex when they belong to the same object and their positions are bitwise equal (-0 = +0).
/// Split normals and texture seams then make no false borders. Ids are numbered in order of
/// first use by the triangles.
struct WeldedMesh {
    std::vector<std::array<std::uint32_t, 3>> tri_vertices;  ///< welded ids per corner
    /// Per welded id, the lowest index of the positions with its bits: vertices of different
    /// objects at the same place have the same one.
    std::vector<std::uint32_t> vertex_position;
    /// Triangles around each welded vertex: ring_offsets has one more entry than vertices.
    std::vector<std::uint32_t> ring_offsets, ring_triangles;

    [[nodiscard]] std::size_t vertex_count() const { return vertex_position.size(); }
    [[nodiscard]] bool has_rings() const { return ring_offsets.size() == vertex_count() + 1; }
};

[[nodiscard]] WeldedMesh weld_vertices(const TriangleMesh& scene);
/// The same with every triangle taken as one object (an instanced mesh, whose instance is
/// the object) when `one_object`.
[[nodiscard]] WeldedMesh weld_vertices(const TriangleMesh& scene, bool one_object);
/// The same without the vertex rings (12 bytes a triangle), which only the visibility of smooth
/// lines and the band and shadow lines read: add_vertex_rings adds them when needed.
[[nodiscard]] WeldedMesh weld_vertices_without_rings(const TriangleMesh& scene, bool one_object);
void add_vertex_rings(WeldedMesh& mesh);

/// The segment where triangles (a0, a1, a2) and (b0, b1, b2) cross, if they do properly (each
/// has corners strictly on both sides of the other's plane; coplanar or touching pairs give
/// none). Each endpoint is where an edge of one crosses the other; `edge` gets that edge's
/// corner numbers (0-2) and `on_b` whether the edge belongs to b.
struct TriangleCrossing {
    Vec3f p[2];
    int edge[2][2];
    bool on_b[2];
};
[[nodiscard]] bool intersect_triangles(const std::array<Vec3f, 3>& a, const std::array<Vec3f, 3>& b,
                                       TriangleCrossing& out);

/// Where two triangles t < u cross (intersect_triangles(corners of t, corners of u)).
struct PairCrossing {
    std::uint32_t t = 0, u = 0;
    TriangleCrossing crossing;
};

/// The mesh edges of a welded mesh: which triangles' sides make each edge (feature_edges.cpp).
struct MeshTopology;

/// Intersection lines kept from one frame to the next: whether and where two triangles cross
/// depends only on their corners, so a pair of triangles that both took part in the last frame
/// and did not move (corners equal bit for bit) gives the same crossing; only pairs with another
/// triangle are tested again. Between two frames of the piano most triangles do not move.
struct IntersectionCache {
    /// Each triangle's corners in the last frame; empty after the cache's first frame.
    std::vector<std::array<Vec3f, 3>> corners;
    /// Per triangle: it took part in the last frame (without hidden lines, triangles turned
    /// away from the eye on closed solids do not), so its pairs with others that did are in
    /// `crossings`.
    std::vector<std::uint8_t> tested;
    std::vector<PairCrossing> crossings;  ///< of those pairs, by (t, u)
    /// The frames drawn with the cache: from the second on, the mesh edges are kept.
    std::uint64_t frames = 0;
    /// The last frame's mesh edges (from the cache's second frame on), the same while the
    /// welded triangles, their objects and which of them are usable (not degenerate) stay the
    /// same.
    std::shared_ptr<const MeshTopology> topology;
    /// Per object, whether the last frame's mesh edges leave it open (MeshTopology::open).
    std::vector<std::uint8_t> open;
    /// The welded triangles (WeldedMesh::tri_vertices) `topology` was found for, which
    /// draw_ink_lines moves here from the last frame's mesh before it welds the next (rather
    /// than the topology keeping a copy: 12 bytes a triangle at the frame's peak). Left empty,
    /// the topology is found again each frame.
    std::vector<std::array<std::uint32_t, 3>> welded;
};

/// Per object, whether the mesh edges of the cache's last frame make it closed (every edge has
/// two faces wound in opposite directions along it): a triangle of a closed object turned away
/// from the eye is behind its front. Empty before find_feature_edges has filled the cache.
[[nodiscard]] std::vector<std::uint8_t> closed_objects(const IntersectionCache& cache);

/// Per object, which way its outward normals point against its triangles' winding when it is a
/// closed solid (`closed`, as closed_objects gives it) with a volume that does not hold the eye:
/// 1 with it, -1 inside out (by the sign of its volume); else 0. A triangle of such an object
/// turned away from the eye is hidden behind its front.
[[nodiscard]] std::vector<std::int8_t> outward_objects(const Scene& scene,
                                                       std::span<const std::uint8_t> closed,
                                                       const Vec3f& eye);

/// All feature segments of the scene seen from `eye`, in a fixed order (mesh edges by welded
/// vertex pair, then smooth contours by triangle, then intersection lines by triangle pair),
/// whatever the thread count. `bvh` is a BVH over the scene's triangles (TriangleAccel::bvh())
/// for the intersection lines. With a cache, the intersection lines of triangles that did not
/// move since the cache's last frame are taken from it (the same segments), and the cache is
/// updated. The cache keeps the triangles' corners only from its second frame on (when it
/// already holds mesh edges): a single frame does not pay for a copy it will not read (36
/// bytes a triangle), and an animation's second frame searches in full.
[[nodiscard]] std::vector<FeatureSegment> find_feature_edges(
    const Scene& scene, const WeldedMesh& mesh, const Bvh& bvh, const Vec3f& eye,
    const FeatureEdgeSettings& settings, int threads, IntersectionCache* cache = nullptr);

}  // namespace toonray::ink
