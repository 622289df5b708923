#pragma once
/// Internal to the ink module (feature_edges.cpp, instance_lines.cpp): the mesh edges of a
/// welded mesh and the intersection search, shared by the scene's own triangles and the meshes
/// of its instances.

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <fmt/format.h>

#include "toonray/accel/bvh.h"
#include "toonray/core/error.h"
#include "toonray/ink/feature_edges.h"
#include "toonray/scene/scene.h"

namespace toonray::ink {

// A side of a usable triangle, from welded vertex lo to hi (lo < hi), kept in lo's range of
// the sides (MeshTopology::vertex_sides): 8 bytes, as a million triangles have three million
// sides. Whether it runs forward and which corner of the triangle starts it share a word with
// the triangle; whether it starts an edge of exactly two sides shares a word with hi (welded
// vertices number at most three per triangle, below 2^31).
struct Side {
    // hi (the low 31 bits), and kPair when this side and the next are the edge's only two.
    std::uint32_t hi_pair;
    // The triangle (the low kCornerShift bits), the corner k whose side (k -> k + 1 in the
    // triangle's winding) this is, and kForward when lo -> hi is its winding.
    std::uint32_t tri_corner_forward;

    static constexpr std::uint32_t kPair = 0x80000000u;
    static constexpr std::uint32_t kForward = 0x80000000u;
    static constexpr int kCornerShift = 29;
    static constexpr std::uint32_t kTriangles = 1u << kCornerShift;  // triangle ids are below
    Side() = default;
    Side(std::uint32_t hi_, std::uint32_t tri_, std::uint32_t corner_, bool forward_)
        : hi_pair(hi_),
          tri_corner_forward(tri_ | (corner_ << kCornerShift) | (forward_ ? kForward : 0u)) {}
    [[nodiscard]] std::uint32_t hi() const { return hi_pair & ~kPair; }
    [[nodiscard]] bool starts_pair() const { return (hi_pair & kPair) != 0; }
    [[nodiscard]] std::uint32_t tri() const { return tri_corner_forward & (kTriangles - 1); }
    [[nodiscard]] std::uint32_t corner() const { return (tri_corner_forward >> kCornerShift) & 3; }
    [[nodiscard]] bool forward() const { return (tri_corner_forward & kForward) != 0; }
};
static_assert(sizeof(Side) == 8);

struct MeshTopology {
    // What it was made from, besides the welded triangles (IntersectionCache::welded), when
    // asked to keep it (for frames that follow: `same`).
    std::vector<std::uint32_t> tri_object;
    std::vector<std::uint8_t> usable;
    std::size_t objects = 0;
    /// Every side of a usable triangle, in order of (lo, hi, triangle, corner): the sides from
    /// welded vertex lo are [vertex_sides[lo], vertex_sides[lo + 1]), and an edge is a run of
    /// them with the same hi (found as they are read, rather than listed: 4 bytes an edge; the
    /// first of an edge's two sides is marked, Side::kPair).
    std::unique_ptr<Side[]> sides;  // every one written: not cleared first
    std::vector<std::uint32_t> vertex_sides;
    /// Per object: not closed, for an edge without exactly two sides in opposite directions,
    /// or a triangle that is not usable or has two corners welded together.
    std::vector<std::uint8_t> open;

    /// `object_of` has each triangle's object (< objects_). With `keep_sources`, the objects
    /// and usability are kept for `same`.
    MeshTopology(std::span<const std::uint32_t> object_of, const WeldedMesh& mesh,
                 std::span<const std::uint8_t> usable_, std::size_t objects_,
                 bool keep_sources = false)
        : objects(objects_), open(objects_, 0) {
        if (keep_sources) {
            tri_object.assign(object_of.begin(), object_of.begin() + usable_.size());
            usable.assign(usable_.begin(), usable_.end());
        }
        const std::span<const std::uint32_t> tri_object = object_of;
        const std::span<const std::uint8_t> usable = usable_;
        const auto& tri_vertices = mesh.tri_vertices;
        const std::size_t n = usable.size(), vertices = mesh.vertex_count();
        if (n > Side::kTriangles)
            throw Error(
                fmt::format("ink lines: a mesh of {} triangles (at most {})", n, Side::kTriangles));
        // A counting sort by lo over the triangles in order puts each vertex's sides in
        // (triangle, corner) order; a stable sort by hi within each vertex then gives the
        // whole order. Vertex v's count goes to offsets[v + 2], so that after the sums
        // offsets[v + 1] is where its sides start: the cursor its sides are written at, which
        // then ends where the next vertex's start (offsets[v] is v's start after the fill, and
        // the offsets, less the last, are vertex_sides).
        std::vector<std::uint32_t>& offsets = vertex_sides;
        offsets.assign(vertices + 2, 0);
        for (std::size_t t = 0; t < n; ++t) {
            const auto& w = tri_vertices[t];
            if (!usable[t] || w[0] == w[1] || w[1] == w[2] || w[2] == w[0]) open[tri_object[t]] = 1;
            if (!usable[t]) continue;
            for (int k = 0; k < 3; ++k)
                if (w[k] != w[(k + 1) % 3]) ++offsets[std::min(w[k], w[(k + 1) % 3]) + 2];
        }
        for (std::size_t v = 2; v < vertices + 2; ++v) offsets[v] += offsets[v - 1];
        const std::size_t side_count = offsets[vertices + 1];
        sides = std::make_unique_for_overwrite<Side[]>(side_count);
        for (std::size_t t = 0; t < n; ++t) {
            if (!usable[t]) continue;
            const auto& w = tri_vertices[t];
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t u = w[k], v = w[(k + 1) % 3];
                if (u == v) continue;
                const std::uint32_t lo = std::min(u, v);
                sides[offsets[lo + 1]++] = {std::max(u, v), static_cast<std::uint32_t>(t),
                                            static_cast<std::uint32_t>(k), u < v};
            }
        }
        offsets.pop_back();
        for (std::size_t v = 0; v < vertices; ++v) {
            Side* const first = sides.get() + offsets[v];
            Side* const last = sides.get() + offsets[v + 1];
            // By insertion, as a vertex has few sides (but not at the centre of a large fan).
            if (last - first > 32) {
                std::stable_sort(first, last, [](const Side& a, const Side& b) {
                    return a.hi_pair < b.hi_pair;
                });
            } else {
                for (Side* i = first + 1; i < last; ++i) {
                    const Side side = *i;
                    Side* j = i;
                    for (; j > first && (j - 1)->hi_pair > side.hi_pair; --j) *j = *(j - 1);
                    *j = side;
                }
            }
            // The sides' kPair bits are still clear here: hi_pair is hi.
            for (Side* i = first; i < last;) {
                Side* j = i + 1;
                while (j < last && j->hi_pair == i->hi_pair) ++j;
                if (j - i == 2) i->hi_pair |= Side::kPair;
                if (j - i != 2 || i[0].forward() == i[1].forward()) open[tri_object[i->tri()]] = 1;
                i = j;
            }
        }
    }

    [[nodiscard]] std::size_t side_count() const { return vertex_sides.back(); }

    /// Calls f(i, j, lo) for every edge in order: its sides [i, j) and its lower welded vertex.
    template <class F>
    void for_each_edge(F&& f) const {
        // Locals, which f cannot be taken to change.
        const Side* const s = sides.get();
        const std::uint32_t* const first = vertex_sides.data();
        const std::size_t vertices = vertex_sides.size() - 1;
        for (std::uint32_t lo = 0; lo < vertices; ++lo) {
            const std::uint32_t last = first[lo + 1];
            for (std::uint32_t i = first[lo]; i < last;) {
                // Most edges have two sides, marked as they were found.
                std::uint32_t j = i + 2;
                if (!s[i].starts_pair()) {
                    const std::uint32_t hi = s[i].hi();
                    for (j = i + 1; j < last && s[j].hi() == hi;) ++j;
                }
                f(i, j, lo);
                i = j;
            }
        }
    }

    /// Per triangle t < n and corner k, the triangle across its side k (corner k to k + 1)
    /// when that edge has two sides in opposite directions (consistently wound neighbours);
    /// else kNoIndex.
    [[nodiscard]] std::vector<std::array<std::uint32_t, 3>> triangles_across(std::size_t n) const {
        std::vector<std::array<std::uint32_t, 3>> across(n, {kNoIndex, kNoIndex, kNoIndex});
        const Side* const s = sides.get();
        // The edges of two sides are marked at their first: no vertex's range is needed.
        const std::size_t count = side_count();
        for (std::size_t i = 0; i < count; ++i) {
            if (!s[i].starts_pair() || s[i].forward() == s[i + 1].forward()) continue;
            across[s[i].tri()][s[i].corner()] = s[i + 1].tri();
            across[s[i + 1].tri()][s[i + 1].corner()] = s[i].tri();
        }
        return across;
    }

    /// Whether the triangles' objects and usability are those it was made from (false when
    /// they were not kept).
    [[nodiscard]] bool same(const TriangleMesh& scene, std::span<const std::uint8_t> usable_,
                            std::size_t objects_) const {
        return objects_ == objects && usable_.size() == usable.size() &&
               std::equal(usable.begin(), usable.end(), usable_.begin()) &&
               std::equal(tri_object.begin(), tri_object.end(), scene.tri_object.begin());
    }
};

/// The corners of triangle t, as find_crossings reads them: stored per triangle...
struct StoredCorners {
    std::span<const std::array<Vec3f, 3>> corners;
    [[nodiscard]] const std::array<Vec3f, 3>& operator()(std::uint32_t t) const {
        return corners[t];
    }
    void prefetch(std::uint32_t t) const {
        __builtin_prefetch(&corners[t]);
        __builtin_prefetch(reinterpret_cast<const char*>(&corners[t]) + 32);
    }
};
/// ...or through the triangles' position indices (a mesh's own arrays: nothing is copied).
struct IndexedCorners {
    std::span<const Vec3f> positions;
    std::span<const std::array<std::uint32_t, 3>> triangles;
    [[nodiscard]] std::array<Vec3f, 3> operator()(std::uint32_t t) const {
        const auto& v = triangles[t];
        return {positions[v[0]], positions[v[1]], positions[v[2]]};
    }
    void prefetch(std::uint32_t t) const { __builtin_prefetch(&triangles[t]); }
};

/// A unit normal rounded to whole 127ths per axis (zero stays zero): 3 bytes rather than 12.
using RoundedNormal = std::array<std::int8_t, 3>;
[[nodiscard]] inline RoundedNormal round_normal(const Vec3f& unit) {
    RoundedNormal r;
    for (int a = 0; a < 3; ++a) {
        const float n = unit[a] * 127.0f;  // a unit normal's: within 127
        r[static_cast<std::size_t>(a)] = static_cast<std::int8_t>(n + (n < 0.0f ? -0.5f : 0.5f));
    }
    return r;
}

/// Which side of a triangle's plane the eye is on (0: in it, or the triangle is degenerate).
inline constexpr std::uint8_t kEyeInFront = 1, kEyeBehind = 2;

/// What find_feature_edges's per-triangle pass writes for each triangle.
struct TriangleFacts {
    Vec3f* normal;           ///< unit_face_normal of its corners
    RoundedNormal* rounded;  ///< round_normal of that (null: not wanted)
    std::uint8_t* usable;    ///< 1 where the normal is not zero
    std::uint8_t* eye_side;  ///< kEyeInFront, kEyeBehind or 0, from dot(normal, eye - corner 0)
};

/// The per-triangle pass over triangles [0, 4 * (n / 4)) of one object, four at a time: their
/// facts with the scalar pass's bits, their corners added to `box` and each dot(p0, cross(p1,
/// p2)) to `volume` in triangle order. The box can differ from the scalar pass's in the sign of
/// a zero bound, and a NaN volume in its payload, which no comparison sees. Returns the number
/// of triangles done (the rest are left to the scalar pass).
std::size_t facts_by_four(const IndexedCorners& corners_of, const Vec3f& eye, std::size_t n,
                          const TriangleFacts& out, BBox& box, double& volume);

/// What lets the intersection search skip whole subtrees whose triangles cannot cross one
/// another: per triangle, its unit normal (unit_face_normal) rounded, and the triangles across its
/// sides (MeshTopology::triangles_across).
struct SurfacePatches {
    std::span<const RoundedNormal> normals;
    std::span<const std::array<std::uint32_t, 3>> across;
};

/// Every pair of triangles that take part (`live`) and cross, as intersect_triangles finds them,
/// with (when `stale` is given) at least one stale triangle; in no particular order. `bvh` is
/// built over the triangles whose corners `corners_of` gives (StoredCorners or IndexedCorners);
/// triangles sharing a corner position (mesh.vertex_position) are not tested. With `patches`,
/// subtrees whose live triangles make a patch that provably does not cross itself are not
/// searched (the pairs found are the same).
template <class CornersOf>
std::vector<PairCrossing> find_crossings(const Bvh& bvh, const CornersOf& corners_of,
                                         const WeldedMesh& mesh,
                                         const std::vector<std::uint8_t>& live,
                                         const std::vector<std::uint8_t>* stale, int threads,
                                         const SurfacePatches* patches = nullptr);

}  // namespace toonray::ink
