#include "toonray/ink/feature_edges.h"

#include <algorithm>
#include <bit>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <cmath>
#include <cstring>
#include <numbers>
#include <tuple>

#include "toonray/core/portable_math.h"
#include "toonray/core/simd_sse.h"
#include "toonray/ink/chunks.h"
#include "toonray/ink/hash.h"
#include "toonray/ink/mesh_topology.h"
#include "toonray/ink/patch_border.h"
#include "toonray/ink/light_lines.h"

namespace toonray::ink {

const char* edge_type_name(EdgeType type) {
    switch (type) {
        case EdgeType::Silhouette: return "silhouette";
        case EdgeType::Border: return "border";
        case EdgeType::Crease: return "crease";
        case EdgeType::Material: return "material";
        case EdgeType::Intersection: return "intersection";
        case EdgeType::Polyline: return "polyline";
        case EdgeType::Band: return "band";
        case EdgeType::Shadow: return "shadow";
        case EdgeType::Tone: return "tone";
    }
    return "?";
}

namespace {

std::uint32_t float_bits(float f) { return std::bit_cast<std::uint32_t>(f + 0.0f); }  // -0 + 0 = +0

// Lexicographic order of positions: orders an edge's ends the same way from either triangle, so
// that a point computed on it is the same bits from both.
bool position_less(const Vec3f& a, const Vec3f& b) {
    return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
}

bool has_corner_normals(const Scene& scene, std::size_t t) {
    if (t >= scene.tri_normals.size()) return false;
    for (std::uint32_t n : scene.tri_normals[t])
        if (n == kNoIndex || n >= scene.normals.size()) return false;
    return true;
}

}  // namespace

WeldedMesh weld_vertices(const TriangleMesh& scene) { return weld_vertices(scene, false); }

WeldedMesh weld_vertices(const TriangleMesh& scene, bool one_object) {
    WeldedMesh mesh = weld_vertices_without_rings(scene, one_object);
    add_vertex_rings(mesh);
    return mesh;
}

WeldedMesh weld_vertices_without_rings(const TriangleMesh& scene, bool one_object) {
    const std::size_t n = scene.triangle_count();
    // Positions with the same bits share a canonical index, the lowest among them: each
    // position, in index order, looks its bits up in an open-addressing table (linear probing,
    // at most two thirds full) and takes the index found there, or enters its own.
    const std::size_t positions = scene.positions.size();
    std::vector<std::uint32_t> canonical(positions);
    using Bits = std::array<std::uint32_t, 3>;
    auto bits = [&](std::uint32_t i) {
        const Vec3f& p = scene.positions[i];
        return Bits{float_bits(p.x), float_bits(p.y), float_bits(p.z)};
    };
    std::size_t table_size = 16;
    while (table_size < positions + positions / 2) table_size *= 2;
    const std::size_t mask = table_size - 1;
    std::vector<std::uint32_t> table(table_size, kNoIndex);
    bool shared_bits = false;
    for (std::uint32_t i = 0; i < positions; ++i) {
        const Bits b = bits(i);
        for (std::size_t slot = hash_words(b[0], b[1], b[2]) & mask;; slot = (slot + 1) & mask) {
            if (table[slot] == kNoIndex) {
                table[slot] = i;
                canonical[i] = i;
                break;
            }
            if (bits(table[slot]) == b) {
                canonical[i] = table[slot];
                shared_bits = true;
                break;
            }
        }
    }
    // Welded ids in order of first use by the triangles: one per (object, canonical position).
    // Most positions belong to one object; the few shared by several look the rest up. When
    // every triangle has the same object, no position's object is kept.
    const bool single =
        one_object || std::adjacent_find(scene.tri_object.begin(), scene.tri_object.begin() + n,
                                         std::not_equal_to<>()) == scene.tri_object.begin() + n;
    WeldedMesh mesh;
    mesh.tri_vertices.resize(n);
    std::vector<std::uint32_t> id_of(scene.positions.size(), kNoIndex);
    if (single) {
        // One object: an id per canonical position, in a loop with nothing else to decide
        // (welding at 1.1M triangles: 155M instructions with the general loop, 85M with this).
        auto weld_one_object = [&](auto shared) {
            const std::array<std::uint32_t, 3>* const corners = scene.tri_positions.data();
            std::array<std::uint32_t, 3>* const out = mesh.tri_vertices.data();
            std::uint32_t* const ids = id_of.data();
            mesh.vertex_position.resize(positions);
            std::uint32_t* const first_position = mesh.vertex_position.data();
            std::uint32_t count = 0;
            for (std::size_t t = 0; t < n; ++t)
                for (int k = 0; k < 3; ++k) {
                    std::uint32_t c = corners[t][k];
                    if constexpr (decltype(shared)::value) c = canonical[c];
                    std::uint32_t id = ids[c];
                    if (id == kNoIndex) {
                        id = ids[c] = count;
                        first_position[count++] = c;
                    }
                    out[t][k] = id;
                }
            mesh.vertex_position.resize(count);
            mesh.vertex_position.shrink_to_fit();  // fewer ids than positions where they repeat
        };
        if (shared_bits) weld_one_object(std::true_type{});
        else weld_one_object(std::false_type{});
        return mesh;
    }
    // Several objects: each canonical position keeps the object of its first use.
    std::vector<std::uint32_t> object_of(scene.positions.size());
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> shared;
    auto new_id = [&](std::uint32_t c) {
        mesh.vertex_position.push_back(c);
        return static_cast<std::uint32_t>(mesh.vertex_position.size() - 1);
    };
    for (std::size_t t = 0; t < n; ++t)
        for (int k = 0; k < 3; ++k) {
            // Every position its own canonical one when none shares its bits with another.
            const std::uint32_t position = scene.tri_positions[t][k],
                                c = shared_bits ? canonical[position] : position,
                                object = scene.tri_object[t];
            std::uint32_t& id = mesh.tri_vertices[t][k];
            if (id_of[c] == kNoIndex) {
                id = id_of[c] = new_id(c);
                object_of[c] = object;
            } else if (object_of[c] == object) {
                id = id_of[c];
            } else {
                auto [it, inserted] = shared.try_emplace({object, c}, 0u);
                if (inserted) it->second = new_id(c);
                id = it->second;
            }
        }
    return mesh;
}

void add_vertex_rings(WeldedMesh& mesh) {
    if (mesh.has_rings()) return;
    const std::size_t n = mesh.tri_vertices.size();
    // Triangles around each vertex, by counting sort (in triangle order; a triangle with a
    // repeated corner counts once at that vertex).
    auto distinct = [&](std::size_t t, int k) {
        const auto& w = mesh.tri_vertices[t];
        for (int i = 0; i < k; ++i)
            if (w[i] == w[k]) return false;
        return true;
    };
    mesh.ring_offsets.assign(mesh.vertex_count() + 1, 0);
    for (std::size_t t = 0; t < n; ++t)
        for (int k = 0; k < 3; ++k)
            if (distinct(t, k)) ++mesh.ring_offsets[mesh.tri_vertices[t][k] + 1];
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
        mesh.ring_offsets[v + 1] += mesh.ring_offsets[v];
    mesh.ring_triangles.resize(mesh.ring_offsets.back());
    std::vector<std::uint32_t> fill(mesh.ring_offsets.begin(), mesh.ring_offsets.end() - 1);
    for (std::size_t t = 0; t < n; ++t)
        for (int k = 0; k < 3; ++k)
            if (distinct(t, k))
                mesh.ring_triangles[fill[mesh.tri_vertices[t][k]]++] =
                    static_cast<std::uint32_t>(t);
}

bool intersect_triangles(const std::array<Vec3f, 3>& a, const std::array<Vec3f, 3>& b,
                         TriangleCrossing& out) {
    const Vec3f na = cross(a[1] - a[0], a[2] - a[0]);
    const Vec3f nb = cross(b[1] - b[0], b[2] - b[0]);
    float da[3], db[3];
    for (int k = 0; k < 3; ++k) {
        da[k] = dot(nb, a[k] - b[0]);
        db[k] = dot(na, b[k] - a[0]);
    }
    auto proper = [](const float* d) {
        const bool pos = d[0] > 0 || d[1] > 0 || d[2] > 0;
        const bool neg = d[0] < 0 || d[1] < 0 || d[2] < 0;
        return pos && neg;
    };
    if (!proper(da) || !proper(db)) return false;
    const Vec3f dir = cross(na, nb);
    // The two points where a triangle's edges cross the other's plane (a corner on the plane
    // counts with the positive side, so exactly two edges change side), as positions along dir.
    struct Crossing {
        Vec3f p;
        float s;
        int e0, e1;
    };
    auto crossings = [&](const std::array<Vec3f, 3>& tri, const float* d, Crossing* c) {
        int n = 0;
        for (int k = 0; k < 3 && n < 2; ++k) {
            int u = k, v = (k + 1) % 3;
            if ((d[u] >= 0) == (d[v] >= 0)) continue;
            if (position_less(tri[v], tri[u])) std::swap(u, v);
            const float t = d[u] / (d[u] - d[v]);
            const Vec3f p = tri[u] + (tri[v] - tri[u]) * t;
            c[n++] = {p, dot(p, dir), std::min(u, v), std::max(u, v)};
        }
        if (n == 2 && c[1].s < c[0].s) std::swap(c[0], c[1]);
        return n == 2;
    };
    Crossing ca[2], cb[2];
    if (!crossings(a, da, ca) || !crossings(b, db, cb)) return false;
    // The segment is the overlap of the two intervals on the common line.
    const Crossing& lo = ca[0].s >= cb[0].s ? ca[0] : cb[0];
    const Crossing& hi = ca[1].s <= cb[1].s ? ca[1] : cb[1];
    if (!(lo.s < hi.s)) return false;
    const bool lo_b = &lo == &cb[0], hi_b = &hi == &cb[1];
    out.p[0] = lo.p;
    out.p[1] = hi.p;
    out.edge[0][0] = lo.e0;
    out.edge[0][1] = lo.e1;
    out.edge[1][0] = hi.e0;
    out.edge[1][1] = hi.e1;
    out.on_b[0] = lo_b;
    out.on_b[1] = hi_b;
    return true;
}

namespace {

// What the intersection search reads per triangle that takes part, in the tree's order (its
// slots), one array per value so that four neighbouring slots are tested at once: the
// triangle, its box, its corners' positions (canonical: equal for equal coordinates, across
// objects) and, when only pairs with a stale triangle are searched, whether it is stale (all
// bits set) or not (zero). kLanes more slots pad the end so that loads of four never read past
// it; their boxes are empty (lo = +inf, hi = -inf), so that they overlap nothing.
constexpr std::uint32_t kLanes = 4;
// Pairs of subtrees of at most this many slots each are tested slot against slot (measured:
// fewer instructions than 8 or 32 on the scan and the piano).
constexpr std::uint32_t kSmallSubtree = 16;
struct Slots {
    std::unique_ptr<std::uint32_t[]> tri;
    std::unique_ptr<float[]> lo[3], hi[3];
    std::unique_ptr<std::uint32_t[]> corner[3];
    std::unique_ptr<std::uint32_t[]> stale;  // null when every triangle is
    // With SurfacePatches only: the unit normal (rounded), and per side k (corner k to k + 1)
    // the slot across it when the neighbour there takes part and is wound consistently (else
    // kNoIndex).
    std::unique_ptr<std::int8_t[]> normal[3];  // rounded to whole 127ths
    std::unique_ptr<std::uint32_t[]> across[3];

    // Values left for the caller to write.
    Slots(std::size_t count, bool with_stale, bool with_patches) {
        tri = std::make_unique_for_overwrite<std::uint32_t[]>(count);
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::make_unique_for_overwrite<float[]>(count);
            hi[a] = std::make_unique_for_overwrite<float[]>(count);
            corner[a] = std::make_unique_for_overwrite<std::uint32_t[]>(count);
            if (with_patches) {
                normal[a] = std::make_unique_for_overwrite<std::int8_t[]>(count);
                across[a] = std::make_unique_for_overwrite<std::uint32_t[]>(count);
            }
        }
        if (with_stale) stale = std::make_unique_for_overwrite<std::uint32_t[]>(count);
    }
};

// Patches tested for crossing themselves: at least this many slots (smaller subtrees cost less
// to search than to test), and normals at least this far into the half-space about the patch's
// axis (a cosine).
constexpr std::uint32_t kPatchMin = 64;
constexpr float kPatchCone = 0.05f;

// Bit k is set when slot j + k may cross slot i: their boxes overlap, they share no corner
// position, and one of them is stale.
int candidate_mask(const Slots& slots, std::uint32_t i, std::uint32_t j) {
    __m128 box = _mm_castsi128_ps(_mm_set1_epi32(-1));
    for (int a = 0; a < 3; ++a)
        box = _mm_and_ps(
            box,
            _mm_and_ps(_mm_cmple_ps(_mm_set1_ps(slots.lo[a][i]), _mm_loadu_ps(&slots.hi[a][j])),
                       _mm_cmpge_ps(_mm_set1_ps(slots.hi[a][i]), _mm_loadu_ps(&slots.lo[a][j]))));
    const int overlap = _mm_movemask_ps(box);
    if (!overlap) return 0;
    __m128i shared = _mm_setzero_si128();
    __m128i other[3];
    for (int c = 0; c < 3; ++c)
        other[c] = _mm_loadu_si128(reinterpret_cast<const __m128i*>(&slots.corner[c][j]));
    for (int c = 0; c < 3; ++c) {
        const __m128i mine = _mm_set1_epi32(static_cast<int>(slots.corner[c][i]));
        for (const __m128i& o : other) shared = _mm_or_si128(shared, _mm_cmpeq_epi32(mine, o));
    }
    const __m128i stale =
        slots.stale
            ? _mm_or_si128(_mm_set1_epi32(static_cast<int>(slots.stale[i])),
                           _mm_loadu_si128(reinterpret_cast<const __m128i*>(&slots.stale[j])))
            : _mm_set1_epi32(-1);
    return overlap & _mm_movemask_ps(_mm_castsi128_ps(_mm_andnot_si128(shared, stale)));
}

}  // namespace

// Candidate pairs are those whose boxes overlap, from a traversal of the BVH against itself: a pair of
// nodes is opened only when the boxes of their live triangles overlap, and a node is paired with
// itself once, so each triangle pair is met once, in the leaf pair that holds it. The node pairs
// are first expanded breadth-first into enough independent tasks for the threads. Triangles
// that share a corner position (in any object) touch there and are not tested.
template <class CornersOf>
std::vector<PairCrossing> find_crossings(const Bvh& bvh, const CornersOf& corners_of,
                                         const WeldedMesh& mesh,
                                         const std::vector<std::uint8_t>& live,
                                         const std::vector<std::uint8_t>* stale, int threads,
                                         const SurfacePatches* patches) {
    const std::uint32_t prims = static_cast<std::uint32_t>(bvh.prim_indices.size());
    constexpr float inf = std::numeric_limits<float>::infinity();
    // Only the triangles that take part have slots (about half of them, without hidden lines:
    // those facing the eye), so that the tests of small subtrees see no dead lanes. A tree
    // range [first, end) holds slots [slot_of[first], slot_of[end]).
    std::vector<std::uint32_t> slot_of(prims + 1);
    std::uint32_t taking_part = 0;
    for (std::uint32_t i = 0; i < prims; ++i) {
        slot_of[i] = taking_part;
        const std::uint32_t t = bvh.prim_indices[i];
        taking_part += t != kNoIndex && live[t] ? 1 : 0;
    }
    slot_of[prims] = taking_part;
    Slots slots(taking_part + kLanes, stale != nullptr, patches != nullptr);
    // The triangles come in the tree's order, which scatters them over the per-triangle
    // arrays: what a slot reads is fetched ahead (the fill is bound by those misses).
    constexpr std::uint32_t kAhead = 16;
    for (std::uint32_t i = 0; i < prims; ++i) {
        if (i + kAhead < prims) {
            const std::uint32_t ahead = bvh.prim_indices[i + kAhead];
            __builtin_prefetch(&live[ahead]);
            __builtin_prefetch(&mesh.tri_vertices[ahead]);
            corners_of.prefetch(ahead);
        }
        if (i + kAhead / 2 < prims)
            for (std::uint32_t v : mesh.tri_vertices[bvh.prim_indices[i + kAhead / 2]])
                __builtin_prefetch(&mesh.vertex_position[v]);
        if (slot_of[i + 1] == slot_of[i]) continue;  // takes no part
        const std::uint32_t t = bvh.prim_indices[i], at = slot_of[i];
        slots.tri[at] = t;
        for (int k = 0; k < 3; ++k)
            slots.corner[k][at] = mesh.vertex_position[mesh.tri_vertices[t][k]];
        if (stale) slots.stale[at] = (*stale)[t] ? kNoIndex : 0;
        BBox box;
        for (const Vec3f& p : corners_of(t)) box.extend(p);
        for (int a = 0; a < 3; ++a) {
            slots.lo[a][at] = box.lo[a];
            slots.hi[a][at] = box.hi[a];
        }
        if (patches)
            for (int a = 0; a < 3; ++a) slots.normal[a][at] = patches->normals[t][a];
    }
    for (std::uint32_t at = taking_part; at < taking_part + kLanes; ++at) {
        slots.tri[at] = kNoIndex;
        for (int a = 0; a < 3; ++a) {
            slots.lo[a][at] = inf;
            slots.hi[a][at] = -inf;
            slots.corner[a][at] = kNoIndex;
        }
        if (stale) slots.stale[at] = 0;
    }
    auto slot_box = [&](std::uint32_t i) {
        return BBox{Vec3f(slots.lo[0][i], slots.lo[1][i], slots.lo[2][i]),
                    Vec3f(slots.hi[0][i], slots.hi[1][i], slots.hi[2][i])};
    };
    // Per node, with `stale` only: whether one of its live triangles is stale.
    std::vector<std::uint8_t> node_stale(stale ? bvh.nodes.size() : 0, 0);
    for (std::size_t i = node_stale.size(); i-- > 0;) {  // children come after parents
        const BvhNode& node = bvh.nodes[i];
        if (node.is_leaf()) {
            for (std::uint32_t k = slot_of[node.first]; k < slot_of[node.first + node.count]; ++k)
                node_stale[i] |= slots.stale[k] != 0;
            continue;
        }
        node_stale[i] = node_stale[node.first] | node_stale[node.first + 1];
    }
    // Per node: its slots, when they are a contiguous range (a subtree's leaves follow each
    // other in the BVHs built here; kNoIndex otherwise). Pairs of small subtrees are tested
    // slot against slot rather than opened further.
    std::vector<std::uint32_t> range_first(bvh.nodes.size()), range_count(bvh.nodes.size());
    for (std::size_t i = bvh.nodes.size(); i-- > 0;) {
        const BvhNode& node = bvh.nodes[i];
        if (node.is_leaf()) {
            range_first[i] = slot_of[node.first];
            range_count[i] = slot_of[node.first + node.count] - slot_of[node.first];
            continue;
        }
        const std::uint32_t l = node.first, r = node.first + 1;
        const bool joined = range_count[l] != kNoIndex && range_count[r] != kNoIndex &&
                            range_first[l] + range_count[l] == range_first[r];
        range_first[i] = range_first[l];
        range_count[i] = joined ? range_count[l] + range_count[r] : kNoIndex;
    }
    if (patches) {
        // The slots across the slots' sides: those of the triangles across them, when they
        // take part. Each triangle's slot is kept in the memory of the tree ranges' (no longer
        // read).
        std::vector<std::uint32_t> slot_of_tri = std::move(slot_of);
        slot_of_tri.assign(live.size(), kNoIndex);
        for (std::uint32_t at = 0; at < taking_part; ++at) slot_of_tri[slots.tri[at]] = at;
        for (std::uint32_t at = 0; at < taking_part + kLanes; ++at)
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t u =
                    at < taking_part ? patches->across[slots.tri[at]][k] : kNoIndex;
                slots.across[k][at] = u == kNoIndex ? kNoIndex : slot_of_tri[u];
            }
    }
    // Whether the live triangles of a subtree (its slots [a0, a0 + an)) cannot cross one another.
    // Seen along an axis d with every normal in the half-space about d, each triangle projects
    // to the plane across d wound the same way; the number of triangles over a point of the
    // plane is then the winding number there of the patch's projected border (the sides without
    // a live, consistently wound neighbour in the subtree: inner sides cancel in pairs). When the
    // border is one simple closed polygon, that number is at most one: no point is covered
    // twice, and two triangles that crossed would cover the points near their crossing twice.
    // The margins keep every decision far from rounding; a patch that fails is searched as
    // before.
    auto cannot_cross_itself = [&](std::uint32_t node) {
        const std::uint32_t a0 = range_first[node], an = range_count[node];
        // The box of the slots' rounded normals, in 127ths.
        float nlo[3], nhi[3];
        for (int a = 0; a < 3; ++a) {
            const std::int8_t* n = slots.normal[a].get();
            __m128i lo = _mm_set1_epi8(127), hi = _mm_set1_epi8(-128);
            std::uint32_t i = a0;
            for (; i + 16 <= a0 + an; i += 16) {
                const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(n + i));
                lo = _mm_min_epi8(lo, v);
                hi = _mm_max_epi8(hi, v);
            }
            alignas(16) std::int8_t l[16], h[16];
            _mm_store_si128(reinterpret_cast<__m128i*>(l), lo);
            _mm_store_si128(reinterpret_cast<__m128i*>(h), hi);
            int least_q = *std::min_element(l, l + 16), most_q = *std::max_element(h, h + 16);
            for (; i < a0 + an; ++i) {
                least_q = std::min<int>(least_q, n[i]);
                most_q = std::max<int>(most_q, n[i]);
            }
            nlo[a] = static_cast<float>(least_q);
            nhi[a] = static_cast<float>(most_q);
        }
        Vec3f d((nlo[0] + nhi[0]) * 0.5f, (nlo[1] + nhi[1]) * 0.5f, (nlo[2] + nhi[2]) * 0.5f);
        const float len = length(d);
        if (!(len > 0.0f)) return false;
        d = d / len;
        // The least n . d over the box of the normals, less what the rounding can take off
        // (half a 127th along each axis).
        float least = 0.0f;
        for (int a = 0; a < 3; ++a) least += std::min(nlo[a] * d[a], nhi[a] * d[a]);
        least = (least - 0.5f * (std::abs(d.x) + std::abs(d.y) + std::abs(d.z))) / 127.0f;
        if (!(least > kPatchCone)) return false;
        const Vec3f e1 =
            normalize(cross(d, std::abs(d.x) < 0.6f ? Vec3f(1, 0, 0) : Vec3f(0, 1, 0)));
        const Vec3f e2 = cross(d, e1);
        const Vec3f c = bvh.nodes[node].bounds.center();
        thread_local PatchBorder border;
        border.sides.clear();
        for (std::uint32_t i = a0; i < a0 + an; ++i) {
            // Sides across which the slot's neighbour is in the subtree are inner sides.
            if (slots.across[0][i] - a0 < an && slots.across[1][i] - a0 < an &&
                slots.across[2][i] - a0 < an)
                continue;
            const std::uint32_t t = slots.tri[i];
            std::array<Vec3f, 3> p{};
            bool read = false;
            for (std::size_t k = 0; k < 3; ++k) {
                if (slots.across[k][i] - a0 < an) continue;
                if (!read) {
                    p = corners_of(t);
                    read = true;
                }
                const Vec3f from = p[k] - c, to = p[(k + 1) % 3] - c;
                border.sides.push_back({{dot(from, e1), dot(from, e2)},
                                        {dot(to, e1), dot(to, e2)},
                                        mesh.tri_vertices[t][k],
                                        mesh.tri_vertices[t][(k + 1) % 3]});
            }
        }
        return border.simple_loop();
    };
    auto overlap = [](const BBox& a, const BBox& b) {
        return !(a.lo.x > b.hi.x || a.hi.x < b.lo.x || a.lo.y > b.hi.y || a.hi.y < b.lo.y ||
                 a.lo.z > b.hi.z || a.hi.z < b.lo.z);
    };
    // Tests slot i against the slots [j0, j1) that may cross it.
    auto test_slots = [&](std::uint32_t i, std::uint32_t j0, std::uint32_t j1,
                          std::vector<PairCrossing>& out) {
        for (std::uint32_t j = j0; j < j1; j += kLanes) {
            int mask = candidate_mask(slots, i, j);
            if (j1 - j < kLanes) mask &= (1 << (j1 - j)) - 1;
            for (; mask; mask &= mask - 1) {
                const std::uint32_t k =
                    j + static_cast<std::uint32_t>(std::countr_zero(static_cast<unsigned>(mask)));
                std::uint32_t t = slots.tri[i], u = slots.tri[k];
                if (u < t) std::swap(t, u);
                PairCrossing found{t, u, {}};
                if (intersect_triangles(corners_of(t), corners_of(u), found.crossing))
                    out.push_back(found);
            }
        }
    };
    using NodePair = std::pair<std::uint32_t, std::uint32_t>;
    // Opens one node pair: tests the triangles of two leaves (or of one leaf with itself), or
    // pushes the child pairs whose boxes may overlap.
    auto expand = [&](NodePair pair, std::vector<NodePair>& next, std::vector<PairCrossing>& out) {
        if (stale && !node_stale[pair.first] && !node_stale[pair.second]) return;
        const std::uint32_t a0 = range_first[pair.first], an = range_count[pair.first];
        const std::uint32_t b0 = range_first[pair.second], bn = range_count[pair.second];
        if (an == 0 || bn == 0) return;  // a subtree without a live triangle
        const BvhNode& a = bvh.nodes[pair.first];
        const BvhNode& b = bvh.nodes[pair.second];
        const BBox& box_a = a.bounds;
        const BBox& box_b = b.bounds;
        if (!overlap(box_a, box_b)) return;
        if (pair.first == pair.second) {
            if (a.is_leaf() || an <= kSmallSubtree) {
                for (std::uint32_t i = a0; i + 1 < a0 + an; ++i) test_slots(i, i + 1, a0 + an, out);
            } else if (patches && an != kNoIndex && an >= kPatchMin &&
                       cannot_cross_itself(pair.first)) {
                return;
            } else {
                next.push_back({a.first, a.first});
                next.push_back({a.first + 1, a.first + 1});
                next.push_back({a.first, a.first + 1});
            }
            return;
        }
        if ((a.is_leaf() && b.is_leaf()) || (an <= kSmallSubtree && bn <= kSmallSubtree)) {
            for (std::uint32_t i = a0; i < a0 + an; ++i)
                if (overlap(slot_box(i), box_b)) test_slots(i, b0, b0 + bn, out);
            return;
        }
        // Open the inner node with the larger box (or the only inner one).
        auto extent = [](const BBox& box) {
            const Vec3f d = box.hi - box.lo;
            return d.x + d.y + d.z;
        };
        if (b.is_leaf() || (!a.is_leaf() && extent(box_a) >= extent(box_b))) {
            next.push_back({a.first, pair.second});
            next.push_back({a.first + 1, pair.second});
        } else {
            next.push_back({pair.first, b.first});
            next.push_back({pair.first, b.first + 1});
        }
    };
    std::vector<PairCrossing> found;
    std::vector<NodePair> tasks{{0u, 0u}}, next;
    const std::size_t wanted_tasks = 256;
    while (!tasks.empty() && tasks.size() < wanted_tasks) {
        next.clear();
        for (const NodePair& pair : tasks) expand(pair, next, found);
        tasks.swap(next);
    }
    auto deeper =
        gather_chunks<PairCrossing>(static_cast<int>(tasks.size()), 4, threads,
                                    [&](int i0, int i1, std::vector<PairCrossing>& out) {
                                        std::vector<NodePair> stack;
                                        for (int i = i0; i < i1; ++i) {
                                            stack.assign(1, tasks[static_cast<std::size_t>(i)]);
                                            while (!stack.empty()) {
                                                const NodePair pair = stack.back();
                                                stack.pop_back();
                                                expand(pair, stack, out);
                                            }
                                        }
                                    });
    found.insert(found.end(), deeper.begin(), deeper.end());
    return found;
}

template std::vector<PairCrossing> find_crossings(const Bvh&, const StoredCorners&,
                                                  const WeldedMesh&,
                                                  const std::vector<std::uint8_t>&,
                                                  const std::vector<std::uint8_t>*, int,
                                                  const SurfacePatches*);
template std::vector<PairCrossing> find_crossings(const Bvh&, const IndexedCorners&,
                                                  const WeldedMesh&,
                                                  const std::vector<std::uint8_t>&,
                                                  const std::vector<std::uint8_t>*, int,
                                                  const SurfacePatches*);

namespace {

// Corner c of triangles t .. t + 3, by axis (lane j: triangle t + j). Three floats a position:
// a 16-byte load could read past the last.
void corner_by_four(const IndexedCorners& corners_of, std::size_t t, int c, __m128& x, __m128& y,
                    __m128& z) {
    __m128 r[4];
    for (std::size_t j = 0; j < 4; ++j) {
        const Vec3f& p = corners_of.positions[corners_of.triangles[t + j][c]];
        std::int64_t x_and_y;  // copied: SIMDe's NEON load would read the floats as integers
        std::memcpy(&x_and_y, &p.x, 8);
        const __m128 xy = _mm_castsi128_ps(_mm_cvtsi64_si128(x_and_y));
        r[j] = _mm_movelh_ps(xy, _mm_load_ss(&p.z));
    }
    const __m128 xy01 = _mm_unpacklo_ps(r[0], r[1]), xy23 = _mm_unpacklo_ps(r[2], r[3]);
    const __m128 z01 = _mm_unpackhi_ps(r[0], r[1]), z23 = _mm_unpackhi_ps(r[2], r[3]);
    x = _mm_movelh_ps(xy01, xy23);
    y = _mm_movehl_ps(xy23, xy01);
    z = _mm_movelh_ps(z01, z23);
}

}  // namespace

// The same operations in the same order as the scalar pass, lane by lane: the same bits. Only
// the box is reduced in another order (the sign of a zero bound can differ) and a NaN volume's
// payload can differ, neither of which a comparison sees. At a million triangles: about a third
// of the scalar pass's instructions.
std::size_t facts_by_four(const IndexedCorners& corners_of, const Vec3f& eye, std::size_t n,
                          const TriangleFacts& out, BBox& box, double& volume) {
    const __m128 zero = _mm_setzero_ps(), inf = _mm_set1_ps(std::numeric_limits<float>::infinity());
    const __m128 ex = _mm_set1_ps(eye.x), ey = _mm_set1_ps(eye.y), ez = _mm_set1_ps(eye.z);
    __m128 lo[3] = {_mm_set1_ps(box.lo.x), _mm_set1_ps(box.lo.y), _mm_set1_ps(box.lo.z)};
    __m128 hi[3] = {_mm_set1_ps(box.hi.x), _mm_set1_ps(box.hi.y), _mm_set1_ps(box.hi.z)};
    auto mul = [](__m128 a, __m128 b) { return _mm_mul_ps(a, b); };
    auto sub = [](__m128 a, __m128 b) { return _mm_sub_ps(a, b); };
    auto dot = [&](__m128 ax, __m128 ay, __m128 az, __m128 bx, __m128 by, __m128 bz) {
        return _mm_add_ps(_mm_add_ps(mul(ax, bx), mul(ay, by)), mul(az, bz));
    };
    std::size_t t = 0;
    for (; t + 4 <= n; t += 4) {
        __m128 p[3][3];
        for (int c = 0; c < 3; ++c) {
            corner_by_four(corners_of, t, c, p[c][0], p[c][1], p[c][2]);
            for (int a = 0; a < 3; ++a) {
                // BBox::extend: std::min(lo, q) is q < lo ? q : lo, as minps(q, lo).
                lo[a] = _mm_min_ps(p[c][a], lo[a]);
                hi[a] = _mm_max_ps(p[c][a], hi[a]);
            }
        }
        // unit_face_normal: cross(p1 - p0, p2 - p0) over its length, zero unless that
        // is positive and finite.
        const __m128 ax = sub(p[1][0], p[0][0]), ay = sub(p[1][1], p[0][1]),
                     az = sub(p[1][2], p[0][2]);
        const __m128 bx = sub(p[2][0], p[0][0]), by = sub(p[2][1], p[0][1]),
                     bz = sub(p[2][2], p[0][2]);
        const __m128 nx = sub(mul(ay, bz), mul(az, by)), ny = sub(mul(az, bx), mul(ax, bz)),
                     nz = sub(mul(ax, by), mul(ay, bx));
        const __m128 len = _mm_sqrt_ps(dot(nx, ny, nz, nx, ny, nz));
        const __m128 ok = _mm_and_ps(_mm_cmpgt_ps(len, zero), _mm_cmplt_ps(len, inf));
        const __m128 ux = _mm_and_ps(ok, _mm_div_ps(nx, len)),
                     uy = _mm_and_ps(ok, _mm_div_ps(ny, len)),
                     uz = _mm_and_ps(ok, _mm_div_ps(nz, len));
        const __m128 facing = dot(ux, uy, uz, sub(ex, p[0][0]), sub(ey, p[0][1]), sub(ez, p[0][2]));
        // Four Vec3f (x0 y0 z0 x1 | y1 z1 x2 y2 | z2 x3 y3 z3) from the lanes, in three stores.
        static_assert(sizeof(Vec3f) == 12 && sizeof(RoundedNormal) == 3);
        char* const normals = reinterpret_cast<char*>(out.normal + t);
        _mm_storeu_ps(reinterpret_cast<float*>(normals),
                      _mm_shuffle_ps(_mm_unpacklo_ps(ux, uy), _mm_unpacklo_ps(uz, ux),
                                     _MM_SHUFFLE(3, 0, 1, 0)));
        _mm_storeu_ps(reinterpret_cast<float*>(normals + 16),
                      _mm_shuffle_ps(_mm_unpacklo_ps(uy, uz), _mm_unpackhi_ps(ux, uy),
                                     _MM_SHUFFLE(1, 0, 3, 2)));
        _mm_storeu_ps(reinterpret_cast<float*>(normals + 32),
                      _mm_shuffle_ps(_mm_unpackhi_ps(uz, ux), _mm_unpackhi_ps(uy, uz),
                                     _MM_SHUFFLE(3, 2, 3, 0)));
        if (out.rounded) {
            // round_normal: n + (n < 0 ? -0.5 : 0.5), truncated; the lanes' whole numbers (within
            // 127) packed to bytes without saturating and put in corner order, 12 bytes.
            const __m128 half = _mm_set1_ps(0.5f), less_half = _mm_set1_ps(-0.5f);
            const __m128 scale = _mm_set1_ps(127.0f);
            auto rounded = [&](__m128 n) {
                const __m128 q = mul(n, scale);
                return _mm_cvttps_epi32(
                    _mm_add_ps(q, _mm_blendv_ps(half, less_half, _mm_cmplt_ps(q, zero))));
            };
            const __m128i bytes =
                _mm_packs_epi16(_mm_packs_epi32(rounded(ux), rounded(uy)),
                                _mm_packs_epi32(rounded(uz), _mm_setzero_si128()));
            const __m128i by_triangle = _mm_shuffle_epi8(
                bytes, _mm_setr_epi8(0, 4, 8, 1, 5, 9, 2, 6, 10, 3, 7, 11, -1, -1, -1, -1));
            auto* const r = reinterpret_cast<char*>(out.rounded + t);
            _mm_storel_epi64(reinterpret_cast<__m128i*>(r), by_triangle);
            const std::int32_t last = _mm_extract_epi32(by_triangle, 2);
            std::memcpy(r + 8, &last, 4);
        }
        // Usability (1 or 0) and the eye's side (kEyeInFront, kEyeBehind or 0: facing > 0 and
        // facing < 0 exclude each other) as bytes, four of each.
        const __m128i one = _mm_set1_epi32(1);
        const __m128i side =
            _mm_or_si128(_mm_and_si128(_mm_castps_si128(_mm_cmpgt_ps(facing, zero)),
                                       _mm_set1_epi32(kEyeInFront)),
                         _mm_and_si128(_mm_castps_si128(_mm_cmplt_ps(facing, zero)),
                                       _mm_set1_epi32(kEyeBehind)));
        const __m128i flags = _mm_packs_epi16(
            _mm_packs_epi32(_mm_and_si128(_mm_castps_si128(ok), one), side), _mm_setzero_si128());
        const std::int32_t usable4 = _mm_cvtsi128_si32(flags), side4 = _mm_extract_epi32(flags, 1);
        std::memcpy(out.usable + t, &usable4, 4);
        std::memcpy(out.eye_side + t, &side4, 4);
        // dot(p0, cross(p1, p2)), each added to the sum in triangle order.
        const __m128 cx = sub(mul(p[1][1], p[2][2]), mul(p[1][2], p[2][1])),
                     cy = sub(mul(p[1][2], p[2][0]), mul(p[1][0], p[2][2])),
                     cz = sub(mul(p[1][0], p[2][1]), mul(p[1][1], p[2][0]));
        alignas(16) float v[4];
        _mm_store_ps(v, dot(p[0][0], p[0][1], p[0][2], cx, cy, cz));
        for (const float vj : v) volume += static_cast<double>(vj);
    }
    alignas(16) float l[3][4], h[3][4];
    for (int a = 0; a < 3; ++a) {
        _mm_store_ps(l[a], lo[a]);
        _mm_store_ps(h[a], hi[a]);
    }
    for (std::size_t j = 0; j < 4; ++j) {
        box.lo = min(box.lo, Vec3f(l[0][j], l[1][j], l[2][j]));
        box.hi = max(box.hi, Vec3f(h[0][j], h[1][j], h[2][j]));
    }
    return t;
}

namespace {

// What band changes across mesh edges are found with.
struct EdgeBands {
    const Scene& scene;
    const WeldedMesh& mesh;
    const FeatureEdgeSettings& settings;
    const Vec3f& eye;
    const std::vector<std::uint8_t>& corner_normals;
};

// Whether the faces t0 and t1 of a welded edge (lo, hi) fall in different bands at its middle,
// each with its normal there (its corner normals' mean, else its face normal n0 or n1, wound
// alike), turned to face the eye. Out of line: the edge loop that calls it stays as small as it
// was.
[[gnu::noinline]] bool bands_differ(const EdgeBands& b, std::uint32_t lo, std::uint32_t hi,
                                    std::uint32_t t0, std::uint32_t t1, const Vec3f& n0,
                                    const Vec3f& n1) {
    const Scene& scene = b.scene;
    const WeldedMesh& mesh = b.mesh;
    const FeatureEdgeSettings& settings = b.settings;
    const Vec3f& eye = b.eye;
    const std::array<std::uint32_t, 2> faces{t0, t1};
    const std::array<Vec3f, 2> face{n0, n1};
    const Vec3f mid =
        (scene.positions[mesh.vertex_position[lo]] + scene.positions[mesh.vertex_position[hi]]) *
        0.5f;
    std::uint8_t band[2];
    for (int f = 0; f < 2; ++f) {
        const std::uint32_t t = faces[static_cast<std::size_t>(f)];
        Vec3f n = face[static_cast<std::size_t>(f)];
        if (b.corner_normals[t]) {
            Vec3f sum(0.0f);
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t w = mesh.tri_vertices[t][k];
                if (w == lo || w == hi) sum += normalize(scene.normals[scene.tri_normals[t][k]]);
            }
            n = normalize(sum);
        }
        if (dot(face[static_cast<std::size_t>(f)], eye - mid) < 0.0f) n = -n;
        band[f] = band_of(settings.band_thresholds, diffuse_light(settings.lights, mid, n));
    }
    return band[0] != band[1];
}

}  // namespace

std::vector<std::uint8_t> closed_objects(const IntersectionCache& cache) {
    std::vector<std::uint8_t> closed;
    for (std::uint8_t open : cache.open) closed.push_back(open ? 0 : 1);
    return closed;
}

std::vector<std::int8_t> outward_objects(const Scene& scene, std::span<const std::uint8_t> closed,
                                         const Vec3f& eye) {
    std::vector<double> volume(closed.size(), 0.0);
    std::vector<BBox> box(closed.size());
    const IndexedCorners corners_of{scene.positions, scene.tri_positions};
    for (std::size_t t = 0; t < scene.triangle_count(); ++t) {
        const std::uint32_t o = scene.tri_object[t];
        if (o >= closed.size() || !closed[o]) continue;
        const auto p = corners_of(t);
        volume[o] += static_cast<double>(dot(p[0], cross(p[1], p[2])));
        for (const Vec3f& q : p) box[o].extend(q);
    }
    std::vector<std::int8_t> outward(closed.size(), 0);
    for (std::size_t o = 0; o < outward.size(); ++o) {
        const BBox& b = box[o];
        const bool around_eye = eye.x >= b.lo.x && eye.y >= b.lo.y && eye.z >= b.lo.z &&
                                eye.x <= b.hi.x && eye.y <= b.hi.y && eye.z <= b.hi.z;
        if (closed[o] && volume[o] != 0.0 && !around_eye) outward[o] = volume[o] > 0.0 ? 1 : -1;
    }
    return outward;
}

std::vector<FeatureSegment> find_feature_edges(const Scene& scene, const WeldedMesh& mesh,
                                               const Bvh& bvh, const Vec3f& eye,
                                               const FeatureEdgeSettings& settings, int threads,
                                               IntersectionCache* cache) {
    const std::size_t n = scene.triangle_count();
    std::vector<FeatureSegment> segments;
    std::size_t objects = scene.objects.size();
    for (std::size_t t = 0; t < n; ++t)
        objects = std::max<std::size_t>(objects, scene.tri_object[t] + std::size_t{1});
    // Objects whose lines on faces turned away from the eye are certainly hidden: closed
    // (every edge has two faces, wound in opposite directions along it), with a non-zero
    // volume, and not around the eye. A line of sight from such a line into the eye starts
    // inside the solid, so it must leave it through the surface on the way.
    std::vector<std::uint8_t> closed(objects, 1);
    std::vector<double> volume(objects, 0.0);
    std::vector<BBox> object_box(objects);

    // Per triangle, in one pass: its unit normal (zero when degenerate: the triangle is not
    // usable), whether it has a normal at every corner, which side of it the eye is on, and
    // its object's box and volume. The corners are read from the scene where needed, not
    // stored: at a million triangles a copy is 40 MB more at the frame's peak, whose first
    // touch costs more than the reads.
    const IndexedCorners corners_of{scene.positions, scene.tri_positions};
    // A full intersection search (without a cache of the same triangles' crossings) skips
    // patches that cannot cross themselves, which read the normals rounded (3 bytes a
    // triangle: the float normals are freed before the search) and the triangles across each
    // side (MeshTopology::triangles_across, found from the mesh edges after the edge loop).
    const bool intersections = settings.intersections && !bvh.nodes.empty();
    const bool some_fresh = cache && cache->corners.size() == n && cache->tested.size() == n;
    const bool patches_searched = intersections && !some_fresh;
    // Sized first and written through pointers, which the stores do not make the loop read
    // again.
    std::vector<Vec3f> normal(n);
    std::vector<std::uint8_t> corner_normals(n), usable_triangle(n), eye_side(n);
    std::vector<RoundedNormal> rounded(patches_searched ? n : 0);
    // (A scene without normals has no triangle with a normal at every corner.)
    const bool normals_given = !scene.tri_normals.empty() && !scene.normals.empty();
    auto triangle_pass = [&](auto one_object) {
        Vec3f* const normal_out = normal.data();
        RoundedNormal* const rounded_out = rounded.data();
        std::uint8_t* const usable_out = usable_triangle.data();
        std::uint8_t* const side_out = eye_side.data();
        std::uint8_t* const corner_normals_out = corner_normals.data();
        // One object's box and volume are summed in locals (the volume in triangle order).
        BBox box;
        double sum = 0.0;
        std::size_t t = 0;
        if constexpr (decltype(one_object)::value) {
            const TriangleFacts facts{normal_out, patches_searched ? rounded_out : nullptr,
                                      usable_out, side_out};
            t = facts_by_four(corners_of, eye, n, facts, box, sum);
            if (normals_given)
                for (std::size_t u = 0; u < t; ++u)
                    corner_normals_out[u] = has_corner_normals(scene, u);
        }
        for (; t < n; ++t) {
            const auto p = corners_of(t);
            const Vec3f nt = unit_face_normal(p[0], p[1], p[2]);
            normal_out[t] = nt;
            if (patches_searched) rounded_out[t] = round_normal(nt);
            usable_out[t] = nt != Vec3f(0.0f);
            const float facing = dot(nt, eye - p[0]);
            side_out[t] = facing > 0 ? kEyeInFront : facing < 0 ? kEyeBehind : 0;
            corner_normals_out[t] = normals_given && has_corner_normals(scene, t);
            const double v = static_cast<double>(dot(p[0], cross(p[1], p[2])));
            if constexpr (decltype(one_object)::value) {
                for (const Vec3f& q : p) box.extend(q);
                sum += v;
            } else {
                const std::uint32_t o = scene.tri_object[t];
                for (const Vec3f& q : p) object_box[o].extend(q);
                volume[o] += v;
            }
        }
        if constexpr (decltype(one_object)::value) {
            object_box[0] = box;
            volume[0] = sum;
        }
    };
    if (objects == 1) triangle_pass(std::true_type{});
    else triangle_pass(std::false_type{});
    auto usable = [&](std::size_t t) { return usable_triangle[t] != 0; };

    // A cache that has seen a frame before: frames follow each other, and this one's mesh
    // edges, corners, and what the mesh edges are made from, are worth keeping for the next (a
    // single frame keeps none of them: an animation's second frame finds them anew).
    const bool frames_follow = cache && cache->frames > 0;
    if (cache) ++cache->frames;
    // The mesh edges, as the last frame's when the triangles' welded corners, objects and
    // usability did not change.
    std::shared_ptr<const MeshTopology> kept = cache ? cache->topology : nullptr;
    if (!kept || cache->welded != mesh.tri_vertices || !kept->same(scene, usable_triangle, objects))
        kept = std::make_shared<const MeshTopology>(scene.tri_object, mesh, usable_triangle,
                                                    objects, frames_follow);
    if (cache) {
        cache->topology = frames_follow ? kept : nullptr;
        cache->open = kept->open;
    }
    const MeshTopology& topology = *kept;
    const Side* const sides = topology.sides.get();
    for (std::size_t o = 0; o < objects; ++o) closed[o] = !topology.open[o];

    auto eye_outside = [&](const BBox& b) {
        return eye.x < b.lo.x || eye.y < b.lo.y || eye.z < b.lo.z || eye.x > b.hi.x ||
               eye.y > b.hi.y || eye.z > b.hi.z;
    };
    // +1: outward normals are the geometric ones; -1: the object is wound inside out; 0: unknown.
    std::vector<int> outward(objects, 0);
    for (std::size_t o = 0; o < objects; ++o)
        if (closed[o] && volume[o] != 0.0 && eye_outside(object_box[o]))
            outward[o] = volume[o] > 0.0 ? 1 : -1;
    // Triangles turned away from the eye on those objects: every point inside them is hidden
    // by the solid, so an intersection line on one is certainly hidden.
    // In the same pass, the triangles that take part in the intersection search: usable ones,
    // and without hidden lines only those not turned away.
    std::vector<std::uint8_t>& turned_away = eye_side;  // in its place
    std::vector<std::uint8_t> live_triangle(intersections ? n : 0);
    if (objects == 1) {
        // Bytes without branches, which the compiler does sixteen at a time (through locals: the
        // stores could otherwise change n, which the lambdas above take by reference).
        const std::uint8_t closed_solid = outward[0] != 0;
        const std::uint8_t away_side = outward[0] > 0 ? kEyeBehind : kEyeInFront;
        const std::uint8_t keep_away = settings.certainly_hidden;
        const std::size_t count = n;
        const std::uint8_t* const usable_of = usable_triangle.data();
        std::uint8_t* const side = eye_side.data();
        for (std::size_t t = 0; t < count; ++t)
            side[t] = closed_solid & usable_of[t] & (side[t] == away_side);
        std::uint8_t* const live = live_triangle.data();
        if (intersections)
            for (std::size_t t = 0; t < count; ++t)
                live[t] = usable_of[t] & (keep_away | (side[t] ^ 1));
    } else {
        for (std::size_t t = 0; t < n; ++t) {
            const int out = outward[scene.tri_object[t]];
            const bool away =
                out != 0 && usable(t) && eye_side[t] == (out > 0 ? kEyeBehind : kEyeInFront);
            turned_away[t] = away;
            if (intersections) live_triangle[t] = usable(t) && (settings.certainly_hidden || !away);
        }
    }

    const float cos_crease =
        portable::cos(settings.crease_angle * std::numbers::pi_v<float> / 180.0f);
    // Shading is smooth across a side shared by two triangles when both have a normal at every
    // corner and the same normals at the side's two ends.
    auto corner_normal = [&](std::uint32_t t, std::uint32_t welded) {
        for (int k = 0; k < 3; ++k)
            if (mesh.tri_vertices[t][k] == welded) return scene.normals[scene.tri_normals[t][k]];
        return Vec3f(0.0f);
    };
    auto smooth_across = [&](std::uint32_t lo, const Side& s0, const Side& s1) {
        if (!corner_normals[s0.tri()] || !corner_normals[s1.tri()]) return false;
        return corner_normal(s0.tri(), lo) == corner_normal(s1.tri(), lo) &&
               corner_normal(s0.tri(), s0.hi()) == corner_normal(s1.tri(), s1.hi());
    };
    const EdgeBands edge_bands{scene, mesh, settings, eye, corner_normals};
    // One segment per edge that is a line: each is classified first, and made only if drawn.
    // The edges come by vertex, their faces from all over the per-triangle arrays: those of the
    // sides a few edges ahead are fetched while this one is classified.
    constexpr std::size_t kAhead = 16;
    const std::size_t side_count = topology.side_count();
    // With one material for every triangle there is no material edge to look for.
    const bool materials =
        settings.materials &&
        std::adjacent_find(scene.tri_material.begin(), scene.tri_material.begin() + n,
                           std::not_equal_to<>()) != scene.tri_material.begin() + n;
    // Read through locals: the stores below (the segments) would otherwise
    // make the loop read the arrays' addresses and the settings again for every edge.
    const Vec3f* const normal_of = normal.data();
    const std::uint32_t* const material_of = scene.tri_material.data();
    const std::uint32_t* const position_of = mesh.vertex_position.data();
    const Vec3f* const positions = scene.positions.data();
    const bool silhouettes = settings.silhouettes, creases = settings.creases;
    // The lower end of the edges from one vertex, and the eye seen from it.
    std::uint32_t at_vertex = kNoIndex;
    Vec3f p0(0.0f), to_eye(0.0f);
    topology.for_each_edge([&](std::uint32_t i, std::uint32_t j,
                               std::uint32_t lo) __attribute__((always_inline)) {
        if (i + kAhead + 2 <= side_count) {
            const std::uint32_t t0 = sides[i + kAhead].tri(), t1 = sides[i + kAhead + 1].tri();
            __builtin_prefetch(&normal_of[t0]);
            __builtin_prefetch(&normal_of[t1]);
            if (materials) {
                __builtin_prefetch(&material_of[t0]);
                __builtin_prefetch(&material_of[t1]);
            }
        }
        // Copies: the segments' stores below could otherwise change them.
        const Side s0 = sides[i];
        if (lo != at_vertex) {
            at_vertex = lo;
            p0 = positions[position_of[lo]];
            to_eye = eye - p0;
        }
        EdgeType type = EdgeType::Border;
        bool certainly_hidden = false;
        if (j - i != 2) {
            if (!settings.borders) return;
        } else {
            const Side s1 = sides[i + 1];
            // Consistently wound neighbours run the shared side in opposite directions.
            const bool consistent = s0.forward() != s1.forward();
            const Vec3f n0 = normal_of[s0.tri()];
            const Vec3f n1 = consistent ? normal_of[s1.tri()] : -normal_of[s1.tri()];
            const float d0 = dot(n0, to_eye), d1 = dot(n1, to_eye);
            const bool front0 = d0 > 0, front1 = d1 > 0;
            if (silhouettes && front0 != front1 &&
                !(settings.smooth_contours && smooth_across(lo, s0, s1)))
                type = EdgeType::Silhouette;
            else if (creases && dot(n0, n1) < cos_crease) type = EdgeType::Crease;
            else if (materials && material_of[s0.tri()] != material_of[s1.tri()])
                type = EdgeType::Material;
            else if (settings.bands && !smooth_across(lo, s0, s1) &&
                     bands_differ(edge_bands, lo, s0.hi(), s0.tri(), s1.tri(), n0, n1))
                type = EdgeType::Band;
            else return;
            const int out = outward[scene.tri_object[s0.tri()]];
            certainly_hidden =
                out != 0 && front0 == (out < 0) && front1 == (out < 0) && d0 != 0 && d1 != 0;
            if (certainly_hidden && !settings.certainly_hidden) return;
        }
        FeatureSegment& seg = segments.emplace_back();
        seg.p0 = p0;
        seg.p1 = positions[position_of[s0.hi()]];
        seg.key0 = {lo, kNoIndex, kNoIndex};
        seg.key1 = {s0.hi(), kNoIndex, kNoIndex};
        seg.faces = {s0.tri(), j - i > 1 ? sides[i + 1].tri() : kNoIndex};
        seg.type = type;
        seg.certainly_hidden = certainly_hidden;
    });

    // Smooth contours: where n . (p - eye), interpolated linearly from the corners, is zero.
    // (Only triangles with a normal at every corner have them.)
    if (settings.silhouettes && settings.smooth_contours && normals_given) {
        // g at a corner depends on its position and normal only, which most triangles around
        // a vertex share: kept per position for the last normal it was computed with.
        std::vector<std::uint32_t> g_normal(scene.positions.size(), kNoIndex);
        std::vector<float> g_value(scene.positions.size());
        for (std::size_t t = 0; t < n; ++t) {
            if (!usable(t) || !corner_normals[t]) continue;
            float g[3];
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t position = scene.tri_positions[t][k],
                                    normal_index = scene.tri_normals[t][k];
                if (g_normal[position] != normal_index) {
                    // Unit normals: the zero's position depends on their lengths.
                    const Vec3f nk = scene.normals[normal_index];
                    const float len = length(nk);
                    g_value[position] =
                        dot(nk, scene.positions[position] - eye) / (len > 0.0f ? len : 1.0f);
                    g_normal[position] = normal_index;
                }
                g[k] = g_value[position];
            }
            // Most triangles have no contour: their corners are read only when one does.
            const bool g0 = g[0] >= 0;
            if (g0 == (g[1] >= 0) && g0 == (g[2] >= 0)) continue;
            const auto p = corners_of(t);
            FeatureSegment seg;
            seg.type = EdgeType::Silhouette;
            seg.smooth = true;
            seg.faces = {static_cast<std::uint32_t>(t), kNoIndex};
            int found = 0;
            for (int k = 0; k < 3; ++k) {
                int u = k, v = (k + 1) % 3;
                if ((g[u] >= 0) == (g[v] >= 0)) continue;
                std::uint32_t wu = mesh.tri_vertices[t][u], wv = mesh.tri_vertices[t][v];
                if (wv < wu) {
                    std::swap(u, v);
                    std::swap(wu, wv);
                }
                const Vec3f q = p[u] + (p[v] - p[u]) * (g[u] / (g[u] - g[v]));
                (found == 0 ? seg.p0 : seg.p1) = q;
                (found == 0 ? seg.key0 : seg.key1) = {wu, wv, kNoIndex};
                ++found;
            }
            if (found == 2 && seg.p0 != seg.p1) segments.push_back(seg);
        }
    }

    // Intersection lines: each triangle against the triangles whose boxes overlap its own.
    if (intersections) {
        // With a cache of the same triangles, a pair is tested only if one of its triangles
        // is stale: its corners changed since the cache's frame, or it did not take part then.
        // Without one, every triangle is.
        std::vector<std::uint8_t> stale;
        if (some_fresh) {
            auto same = [](const Vec3f& a, const Vec3f& b) {
                return std::bit_cast<std::array<std::uint32_t, 3>>(a) ==
                       std::bit_cast<std::array<std::uint32_t, 3>>(b);
            };
            stale.resize(n);
            for (std::size_t t = 0; t < n; ++t) {
                const auto now = corners_of(t);
                stale[t] = !cache->tested[t] ||
                           !std::equal(now.begin(), now.end(), cache->corners[t].begin(), same);
            }
        }
        // Patches that cannot cross themselves are skipped in a full search; one limited to
        // stale triangles is mostly skipped already, and the patches would cost more than
        // they save. The normals, and the mesh edges when no frame follows, are freed before
        // the search makes its slots: the frame's peak.
        std::vector<Vec3f>().swap(normal);
        std::vector<std::uint8_t>().swap(corner_normals);
        // The triangles across the sides, for a full search: found from the mesh edges once the
        // normals are freed, rather than beside them in the edge loop, which was the frame's
        // peak (1.1M triangles: 13 MiB less peak memory and 0.983x the CPU, for 53M more
        // instructions).
        const std::vector<std::array<std::uint32_t, 3>> across =
            patches_searched ? topology.triangles_across(n)
                             : std::vector<std::array<std::uint32_t, 3>>();
        kept.reset();  // `topology` is not read from here on
        const SurfacePatches patches{rounded, across};
        std::vector<PairCrossing> found =
            find_crossings(bvh, corners_of, mesh, live_triangle, some_fresh ? &stale : nullptr,
                           threads, some_fresh ? nullptr : &patches);
        if (cache) {
            // The cache's crossings of triangles that are not stale and take part now; then
            // the cache is this frame's.
            if (some_fresh)
                for (const PairCrossing& c : cache->crossings)
                    if (!stale[c.t] && !stale[c.u] && live_triangle[c.t] && live_triangle[c.u])
                        found.push_back(c);
            // Written after the search, into memory it has freed.
            cache->corners.clear();
            cache->tested.clear();
            if (frames_follow) {
                cache->corners.reserve(n);
                for (std::size_t t = 0; t < n; ++t) cache->corners.push_back(corners_of(t));
                cache->tested = live_triangle;
            }
        }
        // In the order of the triangle pairs, whatever the tree.
        std::sort(found.begin(), found.end(), [](const PairCrossing& x, const PairCrossing& y) {
            return std::tie(x.t, x.u) < std::tie(y.t, y.u);
        });
        for (const PairCrossing& pc : found) {
            const std::uint32_t t = pc.t, u = pc.u;
            const TriangleCrossing& c = pc.crossing;
            FeatureSegment seg;
            seg.type = EdgeType::Intersection;
            seg.p0 = c.p[0];
            seg.p1 = c.p[1];
            seg.faces = {t, u};
            seg.certainly_hidden = turned_away[t] || turned_away[u];
            if (seg.certainly_hidden && !settings.certainly_hidden) continue;
            for (int e = 0; e < 2; ++e) {
                const std::uint32_t on = c.on_b[e] ? u : t, other = c.on_b[e] ? t : u;
                std::uint32_t w0 = mesh.tri_vertices[on][c.edge[e][0]],
                              w1 = mesh.tri_vertices[on][c.edge[e][1]];
                if (w1 < w0) std::swap(w0, w1);
                (e == 0 ? seg.key0 : seg.key1) = {w0, w1, other};
            }
            segments.push_back(seg);
        }
        if (cache) cache->crossings = std::move(found);
    }
    return segments;
}

}  // namespace toonray::ink
