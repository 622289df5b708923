#include "toonray/ink/instance_lines.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>
#include <tuple>

#include "toonray/core/parallel.h"
#include "toonray/core/portable_math.h"
#include "toonray/ink/chunks.h"
#include "toonray/ink/mesh_topology.h"

namespace toonray::ink {

namespace {

// Bounds on the normals of a set of (point, normal) pairs: every unit normal lies within the
// angle whose cosine is cos_a of `axis`. Not valid when they spread over a half-space or more
// (or a normal is zero), where no bound on n . (eye - p) follows.
struct Cone {
    Vec3f axis{0.0f};
    float cos_a = 1.0f, sin_a = 0.0f;
    bool valid = false;
};

// A cone around unit normals (axis: their normalised sum; cosine: the least dot product with
// it, lowered a little so that the bound holds despite rounding).
Cone cone_of(std::span<const Vec3f> normals) {
    Cone c;
    Vec3f sum(0.0f);
    for (const Vec3f& n : normals) sum += n;
    const float len = length(sum);
    if (!(len > 0.0f) || !std::isfinite(len)) return c;
    c.axis = sum / len;
    float least = 1.0f;
    for (const Vec3f& n : normals) least = std::min(least, dot(c.axis, n));
    least -= 1e-5f;
    if (!(least > 0.02f)) return c;  // a half-space or more: no use
    c.cos_a = least;
    c.sin_a = std::sqrt(std::max(0.0f, 1.0f - least * least));
    c.valid = true;
    return c;
}

// The cone around two cones.
Cone merge(const Cone& a, const Cone& b) {
    if (!a.valid || !b.valid) return Cone{};
    const Vec3f sum = a.axis + b.axis;
    const float len = length(sum);
    Cone c;
    if (!(len > 0.0f) || !std::isfinite(len)) return c;
    c.axis = sum / len;
    // The angle from the new axis to each cone's farthest normal, as cos(alpha + beta).
    auto reach = [&](const Cone& k) {
        const float ca = std::clamp(dot(c.axis, k.axis), -1.0f, 1.0f);
        const float sa = std::sqrt(std::max(0.0f, 1.0f - ca * ca));
        return ca * k.cos_a - sa * k.sin_a;
    };
    const float least = std::min(reach(a), reach(b)) - 1e-5f;
    if (!(least > 0.02f)) return c;
    c.cos_a = least;
    c.sin_a = std::sqrt(std::max(0.0f, 1.0f - least * least));
    c.valid = true;
    return c;
}

// A node's box as the sphere around it, which is what the cone bound reads of it.
struct BoundingSphere {
    Vec3f centre;
    float radius = std::numeric_limits<float>::infinity();  ///< infinite for an empty box
};

BoundingSphere sphere_of(const BBox& box) {
    if (box.empty()) return {};
    return {box.center(), 0.5f * length(box.extent())};
}

// The sign of n . (eye - p) for every normal n of the cone and point p of the node's box: +1
// when positive for all, -1 when negative for all, 0 when it may change (or the cone is not
// valid). The bound is n . (eye - c) - n . (p - c) with c the box's centre: the second term is
// at most the box's half diagonal r, the first within D cos(phi -+ alpha) of the eye's
// direction phi from the axis, d = eye - c and D = |d|. D cos(phi -+ alpha) is taken as
// p cos(alpha) +- q sin(alpha) with p = axis . d and q = |axis x d| (D cos phi and D sin phi
// without a division, and q without the cancellation of sqrt(D^2 - p^2) near the axis): each
// term is within a few 2^-24 of D, which a margin of 1e-4 (D + r) covers, with the rounding of
// the dot products the lines are classified with. (The tree's nodes are tested in the
// millions for a crowd: this is its hottest function.)
inline int facing_bound(const Cone& cone, const BoundingSphere& box, const Vec3f& eye) {
    if (!cone.valid) return 0;
    const float r = box.radius;
    const Vec3f d = eye - box.centre;
    const float dist = length(d);
    if (!std::isfinite(dist) || !std::isfinite(r) || dist <= r) return 0;
    const float p = dot(cone.axis, d), q = length(cross(cone.axis, d));
    const float margin = 1e-4f * (dist + r);
    // phi + alpha < 180 degrees and D cos(phi + alpha) - r > 0: all positive.
    if (p * cone.cos_a - q * cone.sin_a - r > margin) return 1;
    // phi > alpha and D cos(phi - alpha) + r < 0: all negative.
    if (p < dist * cone.cos_a && p * cone.cos_a + q * cone.sin_a + r < -margin) return -1;
    return 0;
}

std::uint32_t float_bits(float f) { return std::bit_cast<std::uint32_t>(f + 0.0f); }

bool same_point(const Vec3f& a, const Vec3f& b) {
    return float_bits(a.x) == float_bits(b.x) && float_bits(a.y) == float_bits(b.y) &&
           float_bits(a.z) == float_bits(b.z);
}

bool overlap(const BBox& a, const BBox& b) {
    return !(a.lo.x > b.hi.x || a.hi.x < b.lo.x || a.lo.y > b.hi.y || a.hi.y < b.lo.y ||
             a.lo.z > b.hi.z || a.hi.z < b.lo.z);
}

BBox intersection(const BBox& a, const BBox& b) { return BBox{max(a.lo, b.lo), min(a.hi, b.hi)}; }

// Grown by a relative margin: transformed boxes hold transformed points only up to rounding.
BBox grown(const BBox& b) {
    if (b.empty()) return b;
    const float size = std::max({b.hi.x - b.lo.x, b.hi.y - b.lo.y, b.hi.z - b.lo.z,
                                 std::abs(b.lo.x), std::abs(b.lo.y), std::abs(b.lo.z),
                                 std::abs(b.hi.x), std::abs(b.hi.y), std::abs(b.hi.z)});
    const Vec3f pad(size * 1e-5f);
    return BBox{b.lo - pad, b.hi + pad};
}

// The view as five half-spaces through or in front of the eye: the near plane and the four
// sides through the image's edges grown by `margin` pixels. A box whose eight corners are all
// outside one of them holds nothing that visibility keeps.
class ViewVolume {
public:
    ViewVolume(const ScreenProjection& view, const ViewPlane& plane, float margin) {
        eye_ = view.eye();
        const float w = static_cast<float>(view.width()), h = static_cast<float>(view.height());
        auto at = [&](float x, float y) { return plane.pixel_point(x, y) - eye_; };
        const Vec3f centre = at(0.5f * w, 0.5f * h);
        // Sides: the plane through the eye and an image line.
        const Vec3f corners[4] = {at(-margin, -margin), at(w + margin, -margin),
                                  at(w + margin, h + margin), at(-margin, h + margin)};
        for (int i = 0; i < 4; ++i) {
            Vec3f n = cross(corners[i], corners[(i + 1) % 4]);
            if (dot(n, centre) < 0.0f) n = -n;
            normal_[i] = n / length(n);
            offset_[i] = 0.0f;
        }
        // Near: behind the eye (visibility clips a little in front of it).
        normal_[4] = normalize(centre);
        offset_[4] = 0.0f;
    }
    // Whether the box may hold a point in the view.
    [[nodiscard]] bool may_see(const BBox& box) const {
        if (box.empty()) return false;
        const float size = length(box.extent()) + length(box.center() - eye_);
        for (int i = 0; i < 5; ++i) {
            // The box's corner farthest along the normal.
            const Vec3f& n = normal_[i];
            const Vec3f p((n.x >= 0 ? box.hi.x : box.lo.x), (n.y >= 0 ? box.hi.y : box.lo.y),
                          (n.z >= 0 ? box.hi.z : box.lo.z));
            if (dot(n, p - eye_) < offset_[i] - 1e-4f * size) return false;
        }
        return true;
    }
    // Whether the whole box is inside (its nodes need no test).
    [[nodiscard]] bool sees_all(const BBox& box) const {
        const float size = length(box.extent()) + length(box.center() - eye_);
        for (int i = 0; i < 5; ++i) {
            const Vec3f& n = normal_[i];
            const Vec3f p((n.x >= 0 ? box.lo.x : box.hi.x), (n.y >= 0 ? box.lo.y : box.hi.y),
                          (n.z >= 0 ? box.lo.z : box.hi.z));
            if (dot(n, p - eye_) < offset_[i] + 1e-4f * size) return false;
        }
        return true;
    }

private:
    Vec3f eye_;
    Vec3f normal_[5];
    float offset_[5];
};

}  // namespace

// The eye-independent ink work on one mesh, in object space.
struct MeshLines {
    std::shared_ptr<const TriangleMesh> mesh;  ///< held: its address is its identity
    FeatureEdgeSettings settings;              ///< what the classes were made with
    WeldedMesh welded;
    std::vector<std::array<Vec3f, 3>> corners;
    std::vector<Vec3f> normal;  ///< unit face normals; zero for a triangle that is not usable
    std::vector<std::uint8_t> corner_normals;
    std::vector<float> normal_length;  ///< per normal: its length, 1 for a zero one
    int volume_sign = 0;               ///< closed with a non-zero volume: its sign; else 0
    BBox box;

    enum : std::uint8_t { kCandidate = 1, kCrease = 2, kMaterial = 4, kBorder = 8 };
    // A mesh edge that can be a line: a silhouette from some eye, or a crease, material
    // boundary or border from every eye.
    struct Edge {
        std::uint32_t lo, hi, t0, t1;
        Vec3f p0;      ///< the position of end lo (read for every edge an eye is tested on)
        Vec3f n0, n1;  ///< the faces' normals, n1 turned for inconsistent winding
        Vec3f p1;      ///< the position of end hi (a crowd's lines looked it up at random)
        std::uint8_t flags;
        std::uint32_t order;  ///< in the mesh's edge order (by welded ends)
    };
    /// An edge that is a line from this eye, as found before the lines are put in edge order.
    struct EdgeLine {
        std::uint32_t order;
        EdgeType type;
        bool certainly_hidden;
        const Edge* edge;
    };
    /// The edges every eye tests: creases, material boundaries and borders (lines from every
    /// eye), and the candidates whose planes are not finite (which no box bounds).
    std::vector<Edge> tested_edges;
    // The edges that are silhouette candidates and nothing else, in a tree over their faces'
    // planes. Face f is seen from the front from eye E when n . (E - p) > 0 for a point p of
    // its plane: when the 4D point (n, -n . p) lies on the positive side of the hyperplane
    // through the origin with normal (E, 1) (the duality of Hertzmann and Zorin 2000). An edge
    // is a silhouette when its faces' points lie on both sides, so a node whose 4D box lies on
    // one side holds none. The tree is built over these points, not over positions: on a
    // bumpy mesh neighbouring faces turn too many ways for a cone around them to prove
    // anything, while faces that turn alike, wherever they are, cluster here. Depth-first
    // order with skip indices, so that every instance's walk only moves forward.
    struct PlaneNode {
        float lo[4], hi[4];          ///< the box of its edges' two points each
        std::uint32_t skip;          ///< the first node after its subtree
        std::uint32_t first, count;  ///< a leaf's edges in plane_edges; count 0 inner
    };
    std::vector<PlaneNode> plane_tree;
    std::vector<Edge> plane_edges;  ///< the candidate-only edges, in the tree's leaf order
    float plane_reach = 0;          ///< the largest |x| + |y| + |z| of their first ends
    Bvh tree;                       ///< over the triangles
    // The smooth contours' hierarchy as each instance's walk reads it (empty when the mesh has
    // no smooth triangles): the tree's nodes in depth-first order, a node's subtree being the
    // nodes from it up to `skip`, so that a walk only moves forward through memory.
    struct WalkNode {
        BoundingSphere sphere;  ///< around the node's box
        Cone smooth;            ///< around the unit corner normals of its smooth triangles
        std::uint32_t skip;     ///< the first node after its subtree
        std::uint32_t first;    ///< a leaf's first slot of tree.prim_indices
        std::uint16_t count;    ///< a leaf's slots; 0 for an inner node
        bool has_smooth;        ///< whether its triangles can give smooth contours
    };
    std::vector<WalkNode> walk;
    std::vector<BBox> walk_box;           ///< per walk node: its box (for the view volume)
    std::vector<PairCrossing> crossings;  ///< within the mesh (usable triangles), by (t, u)

    [[nodiscard]] bool usable(std::uint32_t t) const { return normal[t] != Vec3f(0.0f); }
    [[nodiscard]] bool made_with(const FeatureEdgeSettings& s) const {
        return s.crease_angle == settings.crease_angle && s.silhouettes == settings.silhouettes &&
               s.borders == settings.borders && s.creases == settings.creases &&
               s.materials == settings.materials && s.intersections == settings.intersections &&
               s.smooth_contours == settings.smooth_contours;
    }
};

namespace {

// A face of a candidate edge as a point of 4D space: its normal and its plane's offset.
std::array<float, 4> plane_point(const Vec3f& n, const Vec3f& p) {
    return {n.x, n.y, n.z, -dot(n, p)};
}

// Splits `edges` (in edge order) into MeshLines::tested_edges and the plane tree: median
// splits of the edges' 4D centres on their widest axis, down to leaves of at most 8 edges (4
// and 16 measured the same on the crowd of performance.md).
void build_plane_tree(MeshLines& ml, std::span<const MeshLines::Edge> edges) {
    constexpr std::uint32_t kLeafEdges = 8;
    std::vector<const MeshLines::Edge*> candidates;
    for (const MeshLines::Edge& e : edges) {
        bool finite = true;
        for (const Vec3f& n : {e.n0, e.n1})
            for (const float x : plane_point(n, e.p0)) finite = finite && std::isfinite(x);
        if (e.flags == MeshLines::kCandidate && finite) candidates.push_back(&e);
        else ml.tested_edges.push_back(e);
    }
    const std::size_t n = candidates.size();
    std::vector<std::array<float, 4>> lo(n), hi(n), centre(n);
    float reach = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const MeshLines::Edge& e = *candidates[i];
        reach = std::max(reach, std::abs(e.p0.x) + std::abs(e.p0.y) + std::abs(e.p0.z));
        const auto a = plane_point(e.n0, e.p0), b = plane_point(e.n1, e.p0);
        for (int k = 0; k < 4; ++k) {
            lo[i][k] = std::min(a[k], b[k]);
            hi[i][k] = std::max(a[k], b[k]);
            centre[i][k] = 0.5f * a[k] + 0.5f * b[k];
        }
    }
    ml.plane_reach = reach;
    // Offsets measured in the mesh's size, as normals are in units: a split then weighs a turn
    // of the faces and a move of their planes alike.
    const float offset_scale = reach > 0 && std::isfinite(reach) ? 1.0f / reach : 1.0f;
    for (auto& c : centre) c[3] *= offset_scale;
    std::vector<std::uint32_t> order(n);
    for (std::uint32_t i = 0; i < n; ++i) order[i] = i;
    ml.plane_edges.reserve(n);
    auto build = [&](auto&& self, std::uint32_t begin, std::uint32_t end) -> void {
        const auto at = static_cast<std::uint32_t>(ml.plane_tree.size());
        MeshLines::PlaneNode node{};
        std::array<float, 4> low, high;
        for (int k = 0; k < 4; ++k) {
            node.lo[k] = low[k] = std::numeric_limits<float>::infinity();
            node.hi[k] = high[k] = -std::numeric_limits<float>::infinity();
        }
        for (std::uint32_t i = begin; i < end; ++i)
            for (int k = 0; k < 4; ++k) {
                const std::uint32_t e = order[i];
                node.lo[k] = std::min(node.lo[k], lo[e][k]);
                node.hi[k] = std::max(node.hi[k], hi[e][k]);
                low[k] = std::min(low[k], centre[e][k]);
                high[k] = std::max(high[k], centre[e][k]);
            }
        ml.plane_tree.push_back(node);
        if (end - begin <= kLeafEdges) {
            ml.plane_tree[at].first = static_cast<std::uint32_t>(ml.plane_edges.size());
            ml.plane_tree[at].count = end - begin;
            ml.plane_tree[at].skip = at + 1;
            for (std::uint32_t i = begin; i < end; ++i)
                ml.plane_edges.push_back(*candidates[order[i]]);
            return;
        }
        int axis = 0;
        for (int k = 1; k < 4; ++k)
            if (high[k] - low[k] > high[axis] - low[axis]) axis = k;
        const std::uint32_t mid = begin + (end - begin) / 2;
        std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                         [&](std::uint32_t x, std::uint32_t y) {
                             return std::tie(centre[x][axis], x) < std::tie(centre[y][axis], y);
                         });
        self(self, begin, mid);
        self(self, mid, end);
        ml.plane_tree[at].skip = static_cast<std::uint32_t>(ml.plane_tree.size());
    };
    if (n > 0) build(build, 0, static_cast<std::uint32_t>(n));
}

std::shared_ptr<const MeshLines> make_mesh_lines(std::shared_ptr<const TriangleMesh> source,
                                                 const FeatureEdgeSettings& settings, int threads) {
    auto out = std::make_shared<MeshLines>();
    MeshLines& ml = *out;
    const TriangleMesh& mesh = *source;
    ml.mesh = std::move(source);
    ml.settings = settings;
    const std::size_t n = mesh.triangle_count();
    ml.welded = weld_vertices(mesh, true);
    ml.corners.resize(n);
    ml.normal.resize(n);
    ml.corner_normals.resize(n);
    std::vector<std::uint8_t> usable(n);
    double volume = 0.0;
    for (std::size_t t = 0; t < n; ++t) {
        const auto& v = mesh.tri_positions[t];
        auto& p = ml.corners[t];
        p = {mesh.positions[v[0]], mesh.positions[v[1]], mesh.positions[v[2]]};
        ml.normal[t] = unit_face_normal(p[0], p[1], p[2]);
        usable[t] = ml.normal[t] != Vec3f(0.0f);
        bool corner = true;
        for (std::uint32_t k : mesh.tri_normals[t])
            corner = corner && k != kNoIndex && k < mesh.normals.size();
        ml.corner_normals[t] = corner;
        for (const Vec3f& q : p) ml.box.extend(q);
        volume += static_cast<double>(dot(p[0], cross(p[1], p[2])));
    }
    ml.normal_length.resize(mesh.normals.size());
    for (std::size_t k = 0; k < mesh.normals.size(); ++k) {
        const float len = length(mesh.normals[k]);
        ml.normal_length[k] = len > 0.0f ? len : 1.0f;
    }
    const std::vector<std::uint32_t> one_object(n, 0u);
    const MeshTopology topology(one_object, ml.welded, usable, 1);
    if (!topology.open[0] && volume != 0.0) ml.volume_sign = volume > 0.0 ? 1 : -1;

    // The edges that can be lines, in edge order, each owned by its first side's triangle.
    const float cos_crease =
        portable::cos(settings.crease_angle * std::numbers::pi_v<float> / 180.0f);
    auto corner_normal = [&](std::uint32_t t, std::uint32_t welded) {
        for (int k = 0; k < 3; ++k)
            if (ml.welded.tri_vertices[t][k] == welded) return mesh.normals[mesh.tri_normals[t][k]];
        return Vec3f(0.0f);
    };
    auto smooth_across = [&](std::uint32_t lo, const Side& s0, const Side& s1) {
        if (!ml.corner_normals[s0.tri()] || !ml.corner_normals[s1.tri()]) return false;
        return corner_normal(s0.tri(), lo) == corner_normal(s1.tri(), lo) &&
               corner_normal(s0.tri(), s0.hi()) == corner_normal(s1.tri(), s1.hi());
    };
    std::vector<MeshLines::Edge> edges;
    topology.for_each_edge([&](std::uint32_t i, std::uint32_t j, std::uint32_t lo) {
        const Side& s0 = topology.sides[i];
        MeshLines::Edge edge{lo,
                             s0.hi(),
                             s0.tri(),
                             j - i > 1 ? topology.sides[i + 1].tri() : kNoIndex,
                             mesh.positions[ml.welded.vertex_position[lo]],
                             Vec3f(0.0f),
                             Vec3f(0.0f),
                             mesh.positions[ml.welded.vertex_position[s0.hi()]],
                             0,
                             static_cast<std::uint32_t>(edges.size())};
        if (j - i != 2) {
            if (!settings.borders) return;
            edge.flags = MeshLines::kBorder;
        } else {
            const Side& s1 = topology.sides[i + 1];
            edge.n0 = ml.normal[s0.tri()];
            edge.n1 = s0.forward() != s1.forward() ? ml.normal[s1.tri()] : -ml.normal[s1.tri()];
            if (settings.silhouettes && !(settings.smooth_contours && smooth_across(lo, s0, s1)))
                edge.flags |= MeshLines::kCandidate;
            if (settings.creases && dot(edge.n0, edge.n1) < cos_crease)
                edge.flags |= MeshLines::kCrease;
            else if (settings.materials &&
                     mesh.tri_material[s0.tri()] != mesh.tri_material[s1.tri()])
                edge.flags |= MeshLines::kMaterial;
            if (!edge.flags) return;
        }
        edges.push_back(edge);
    });
    build_plane_tree(ml, edges);
    // The smooth contours' hierarchy: the triangles' BVH (which the crossings search too), each
    // node with a cone around its smooth triangles' corner normals.
    ml.tree = Bvh::build(mesh.positions, mesh.tri_positions, Bvh::Config{}, nullptr);
    struct Node {
        Cone smooth;
        bool smooth_triangles = false;
    };
    std::vector<Node> nodes(ml.tree.nodes.size());
    std::vector<Vec3f> smooth;
    for (std::size_t i = ml.tree.nodes.size(); i-- > 0;) {  // children after parents
        const BvhNode& b = ml.tree.nodes[i];
        Node& node = nodes[i];
        if (!b.is_leaf()) {
            const Node& l = nodes[b.first];
            const Node& r = nodes[b.first + 1];
            node.smooth_triangles = l.smooth_triangles || r.smooth_triangles;
            node.smooth = !l.smooth_triangles
                              ? r.smooth
                              : (!r.smooth_triangles ? l.smooth : merge(l.smooth, r.smooth));
            continue;
        }
        smooth.clear();
        bool zero_normal = false;
        for (std::uint32_t k = b.first; k < b.first + b.count; ++k) {
            const std::uint32_t t = ml.tree.prim_indices[k];
            if (settings.silhouettes && settings.smooth_contours && usable[t] &&
                ml.corner_normals[t]) {
                node.smooth_triangles = true;
                for (std::uint32_t k2 : mesh.tri_normals[t]) {
                    const Vec3f& nn = mesh.normals[k2];
                    const float len = length(nn);
                    if (!(len > 0.0f) || !std::isfinite(len)) zero_normal = true;
                    else smooth.push_back(nn / len);
                }
            }
        }
        node.smooth = zero_normal ? Cone{} : cone_of(smooth);
    }
    // Flattened depth first, left to right: (tree node, or walk node to close, and which).
    std::vector<std::pair<std::uint32_t, bool>> todo;
    if (!nodes.empty() && nodes[0].smooth_triangles) todo.push_back({0u, false});
    while (!todo.empty()) {
        const auto [i, close] = todo.back();
        todo.pop_back();
        if (close) {
            ml.walk[i].skip = static_cast<std::uint32_t>(ml.walk.size());
            continue;
        }
        const BvhNode& b = ml.tree.nodes[i];
        const Node& node = nodes[i];
        const auto at = static_cast<std::uint32_t>(ml.walk.size());
        ml.walk.push_back({sphere_of(b.bounds), node.smooth, at + 1, b.first,
                           static_cast<std::uint16_t>(b.count), node.smooth_triangles});
        ml.walk_box.push_back(b.bounds);
        if (b.is_leaf()) continue;
        todo.push_back({at, true});
        todo.push_back({b.first + 1, false});
        todo.push_back({b.first, false});
    }

    // The crossings within the mesh, among its usable triangles.
    if (settings.intersections && !ml.tree.nodes.empty()) {
        ml.crossings =
            find_crossings(ml.tree, StoredCorners{ml.corners}, ml.welded, usable, nullptr, threads);
        std::sort(ml.crossings.begin(), ml.crossings.end(),
                  [](const PairCrossing& x, const PairCrossing& y) {
                      return std::tie(x.t, x.u) < std::tie(y.t, y.u);
                  });
    }
    return out;
}

// The segment of crossing `c` between triangle t of instance a and triangle u of instance b
// (kNoIndex: the own triangles), whose welded meshes are wa and wb: each end keyed by the
// welded edge that crosses and the triangle it crosses, with their instances.
FeatureSegment crossing_segment(const TriangleCrossing& c, std::uint32_t t, std::uint32_t u,
                                std::uint32_t a, std::uint32_t b, const WeldedMesh& wa,
                                const WeldedMesh& wb, bool hidden) {
    FeatureSegment seg;
    seg.type = EdgeType::Intersection;
    seg.p0 = c.p[0];
    seg.p1 = c.p[1];
    seg.faces = {t, u};
    seg.face_instance = {a, b};
    seg.certainly_hidden = hidden;
    for (int e = 0; e < 2; ++e) {
        const std::uint32_t on = c.on_b[e] ? u : t, other = c.on_b[e] ? t : u;
        const std::uint32_t on_instance = c.on_b[e] ? b : a, other_instance = c.on_b[e] ? a : b;
        const WeldedMesh& w = c.on_b[e] ? wb : wa;
        std::uint32_t w0 = w.tri_vertices[on][c.edge[e][0]], w1 = w.tri_vertices[on][c.edge[e][1]];
        if (w1 < w0) std::swap(w0, w1);
        (e == 0 ? seg.key0 : seg.key1) = {w0, w1, other, on_instance, other_instance};
    }
    return seg;
}

// One instance seen from the eye: the eye in its object space and what follows from it.
struct Placement {
    std::uint32_t instance = kNoIndex;
    const MeshLines* ml = nullptr;
    const Affine3* to_world = nullptr;
    Vec3f eye;        ///< in object space
    int outward = 0;  ///< certainly-hidden rule: +1 / -1 outward normals, 0 none

    [[nodiscard]] bool turned_away(std::uint32_t t) const {
        if (outward == 0 || !ml->usable(t)) return false;
        const float facing = dot(ml->normal[t], eye - ml->corners[t][0]);
        return outward > 0 ? facing < 0 : facing > 0;
    }
};

Placement place(const Scene& scene, std::uint32_t i, const MeshLines* ml, const Vec3f& eye) {
    Placement p;
    p.instance = i;
    p.ml = ml;
    p.to_world = &scene.instances[i].to_world;
    p.eye = p.to_world->inverse().point(eye);
    const BBox& b = ml->box;
    const bool outside = p.eye.x < b.lo.x || p.eye.y < b.lo.y || p.eye.z < b.lo.z ||
                         p.eye.x > b.hi.x || p.eye.y > b.hi.y || p.eye.z > b.hi.z;
    p.outward = outside ? ml->volume_sign : 0;
    return p;
}

// Puts `lines` in edge order, by a least-significant-digit radix sort on their orders (all
// distinct) through `scratch`, a byte a pass for as many bytes as the largest order has. A
// crowd's instance finds about 900 lines in random order, on which std::sort's comparisons
// mispredict: it took 2.4% of the frame of 10,000 instances.
void sort_by_order(std::vector<MeshLines::EdgeLine>& lines,
                   std::vector<MeshLines::EdgeLine>& scratch) {
    if (lines.size() < 64) {
        std::sort(lines.begin(), lines.end(),
                  [](const auto& x, const auto& y) { return x.order < y.order; });
        return;
    }
    std::uint32_t largest = 0;
    for (const MeshLines::EdgeLine& line : lines) largest = std::max(largest, line.order);
    scratch.resize(lines.size());
    for (int shift = 0; shift < 32 && (largest >> shift) != 0; shift += 8) {
        std::array<std::uint32_t, 257> start{};
        for (const MeshLines::EdgeLine& line : lines) ++start[((line.order >> shift) & 0xff) + 1];
        for (std::size_t b = 1; b < start.size(); ++b) start[b] += start[b - 1];
        for (const MeshLines::EdgeLine& line : lines)
            scratch[start[(line.order >> shift) & 0xff]++] = line;
        lines.swap(scratch);
    }
}

// The mesh edges and smooth contours of one instance, then the crossings within its mesh.
void instance_segments(const Placement& pl, const ViewVolume* volume,
                       const FeatureEdgeSettings& settings, const InstanceLineOptions& options,
                       std::vector<FeatureSegment>& out, std::vector<FeatureSegment>& smooth,
                       std::vector<MeshLines::EdgeLine>& edges_found,
                       std::vector<MeshLines::EdgeLine>& sort_scratch) {
    const MeshLines& ml = *pl.ml;
    const TriangleMesh& mesh = *ml.mesh;
    const Affine3& m = *pl.to_world;
    const Vec3f& eye = pl.eye;
    const std::uint32_t inst = pl.instance;
    smooth.clear();
    edges_found.clear();
    auto edge_segment = [&](const MeshLines::Edge& e) {
        const Vec3f& p0 = e.p0;
        EdgeType type = EdgeType::Border;
        bool certainly_hidden = false;
        if (!(e.flags & MeshLines::kBorder)) {
            const float d0 = dot(e.n0, eye - p0), d1 = dot(e.n1, eye - p0);
            const bool front0 = d0 > 0, front1 = d1 > 0;
            if ((e.flags & MeshLines::kCandidate) && front0 != front1) type = EdgeType::Silhouette;
            else if (e.flags & MeshLines::kCrease) type = EdgeType::Crease;
            else if (e.flags & MeshLines::kMaterial) type = EdgeType::Material;
            else return;
            const int out_sign = pl.outward;
            certainly_hidden = out_sign != 0 && front0 == (out_sign < 0) &&
                               front1 == (out_sign < 0) && d0 != 0 && d1 != 0;
            if (certainly_hidden && !settings.certainly_hidden) return;
        }
        edges_found.push_back({e.order, type, certainly_hidden, &e});
    };
    auto contour = [&](std::uint32_t t) {
        const auto& p = ml.corners[t];
        float g[3];
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t ni = mesh.tri_normals[t][k];
            g[k] = dot(mesh.normals[ni], p[k] - eye) / ml.normal_length[ni];
        }
        FeatureSegment seg;
        seg.type = EdgeType::Silhouette;
        seg.smooth = true;
        seg.faces = {t, kNoIndex};
        seg.face_instance = {inst, kNoIndex};
        int found = 0;
        Vec3f q[2];
        for (int k = 0; k < 3; ++k) {
            int u = k, v = (k + 1) % 3;
            if ((g[u] >= 0) == (g[v] >= 0)) continue;
            std::uint32_t wu = ml.welded.tri_vertices[t][u], wv = ml.welded.tri_vertices[t][v];
            if (wv < wu) {
                std::swap(u, v);
                std::swap(wu, wv);
            }
            q[found == 0 ? 0 : 1] = p[u] + (p[v] - p[u]) * (g[u] / (g[u] - g[v]));
            (found == 0 ? seg.key0 : seg.key1) = {wu, wv, kNoIndex, inst, kNoIndex};
            ++found;
        }
        if (found != 2 || q[0] == q[1]) return;
        seg.p0 = m.point(q[0]);
        seg.p1 = m.point(q[1]);
        if (seg.p0 != seg.p1) smooth.push_back(seg);
    };
    // The mesh edges: those every eye tests, then the candidates in the plane tree's nodes
    // that the eye's hyperplane may cut. The bound of n . (E - p) over a node's box is within
    // a few 2^-24 of |E| + |p| of the exact one, and so is the test of an edge: the margin
    // covers both (and with an eye that is not finite, culls nothing). No node is culled by
    // the view: an instance partly in it gives silhouettes that visibility clips away, and
    // every other instance is in full view or skipped whole.
    for (const MeshLines::Edge& e : ml.tested_edges) edge_segment(e);
    const float margin =
        1e-4f * (std::abs(eye.x) + std::abs(eye.y) + std::abs(eye.z) + ml.plane_reach);
    const auto plane_nodes = static_cast<std::uint32_t>(ml.plane_tree.size());
    for (std::uint32_t i = 0; i < plane_nodes;) {
        const MeshLines::PlaneNode& node = ml.plane_tree[i];
        if (options.cone_culling) {
            float low = node.lo[3], high = node.hi[3];
            for (int k = 0; k < 3; ++k) {
                const float a = eye[k] * node.lo[k], b = eye[k] * node.hi[k];
                low += std::min(a, b);
                high += std::max(a, b);
            }
            if (low > margin || high < -margin) {
                i = node.skip;
                continue;
            }
        }
        for (std::uint32_t e = node.first; e < node.first + node.count; ++e)
            edge_segment(ml.plane_edges[e]);
        ++i;
    }
    // The smooth contours: depth first, left to right (the order of the leaves, whatever is
    // skipped). Nodes before `inside_end` lie inside the view volume (below a node that does).
    const auto nodes = static_cast<std::uint32_t>(ml.walk.size());
    std::uint32_t inside_end = volume == nullptr ? nodes : 0;
    for (std::uint32_t i = 0; i < nodes;) {
        const MeshLines::WalkNode& node = ml.walk[i];
        if (i >= inside_end) {
            const BBox world = grown(m.box(ml.walk_box[i]));
            if (!volume->may_see(world)) {
                i = node.skip;
                continue;
            }
            if (volume->sees_all(world)) inside_end = node.skip;
        }
        if (!node.has_smooth ||
            (options.cone_culling && facing_bound(node.smooth, node.sphere, eye) != 0)) {
            i = node.skip;
            continue;
        }
        for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
            const std::uint32_t t = ml.tree.prim_indices[k];
            if (ml.usable(t) && ml.corner_normals[t]) contour(t);
        }
        ++i;
    }
    // Mesh edges in the mesh's edge order (as the flattened scene lists them: chaining starts
    // strokes in segment order), whichever parts of the hierarchy were skipped; then the smooth
    // contours by triangle.
    sort_by_order(edges_found, sort_scratch);
    for (const MeshLines::EdgeLine& line : edges_found) {
        const MeshLines::Edge& e = *line.edge;
        FeatureSegment& seg = out.emplace_back();
        seg.p0 = m.point(e.p0);
        seg.p1 = m.point(e.p1);
        seg.key0 = {e.lo, kNoIndex, kNoIndex, inst, kNoIndex};
        seg.key1 = {e.hi, kNoIndex, kNoIndex, inst, kNoIndex};
        seg.faces = {e.t0, e.t1};
        seg.face_instance = {inst, e.t1 != kNoIndex ? inst : kNoIndex};
        seg.type = line.type;
        seg.certainly_hidden = line.certainly_hidden;
    }
    std::sort(smooth.begin(), smooth.end(), [](const FeatureSegment& x, const FeatureSegment& y) {
        return x.faces[0] < y.faces[0];
    });
    out.insert(out.end(), smooth.begin(), smooth.end());
    // The crossings within the mesh: its pairs are found once, in object space; each is then
    // crossed again with the instance's corners in the world, so that the segment is the one the
    // flattened scene has, bit for bit.
    for (const PairCrossing& pc : ml.crossings) {
        const bool hidden = pl.turned_away(pc.t) || pl.turned_away(pc.u);
        if (hidden && !settings.certainly_hidden) continue;
        const auto world = [&](std::uint32_t t) {
            const auto& p = ml.corners[t];
            return std::array<Vec3f, 3>{m.point(p[0]), m.point(p[1]), m.point(p[2])};
        };
        TriangleCrossing c;
        if (!intersect_triangles(world(pc.t), world(pc.u), c)) continue;
        out.push_back(crossing_segment(c, pc.t, pc.u, inst, inst, ml.welded, ml.welded, hidden));
    }
}

// A triangle of one side of a pair: its id, its corners in the world and their box.
struct WorldTriangle {
    std::uint32_t t;
    std::array<Vec3f, 3> p;
    BBox box;
};

// The triangles of an instance's mesh whose world boxes overlap `region`.
void triangles_in(const MeshLines& ml, const Affine3& m, const BBox& region,
                  std::vector<WorldTriangle>& out) {
    out.clear();
    if (ml.tree.nodes.empty()) return;
    std::vector<std::uint32_t> stack{0u};
    while (!stack.empty()) {
        const std::uint32_t i = stack.back();
        stack.pop_back();
        const BvhNode& b = ml.tree.nodes[i];
        if (!overlap(grown(m.box(b.bounds)), region)) continue;
        if (!b.is_leaf()) {
            stack.push_back(b.first + 1);
            stack.push_back(b.first);
            continue;
        }
        for (std::uint32_t k = b.first; k < b.first + b.count; ++k) {
            const std::uint32_t t = ml.tree.prim_indices[k];
            if (!ml.usable(t)) continue;
            WorldTriangle w{
                t,
                {m.point(ml.corners[t][0]), m.point(ml.corners[t][1]), m.point(ml.corners[t][2])},
                {}};
            for (const Vec3f& q : w.p) w.box.extend(q);
            if (overlap(w.box, region)) out.push_back(w);
        }
    }
}

// The scene's own triangles whose boxes overlap `region`, through the own binary tree.
void own_triangles_in(const Scene& scene, const Bvh& bvh, const BBox& region,
                      std::vector<WorldTriangle>& out) {
    out.clear();
    if (bvh.nodes.empty()) return;
    std::vector<std::uint32_t> stack{0u};
    while (!stack.empty()) {
        const std::uint32_t i = stack.back();
        stack.pop_back();
        const BvhNode& b = bvh.nodes[i];
        if (!overlap(b.bounds, region)) continue;
        if (!b.is_leaf()) {
            stack.push_back(b.first + 1);
            stack.push_back(b.first);
            continue;
        }
        for (std::uint32_t k = b.first; k < b.first + b.count; ++k) {
            const std::uint32_t t = bvh.prim_indices[k];
            const auto& v = scene.tri_positions[t];
            WorldTriangle w{
                t, {scene.positions[v[0]], scene.positions[v[1]], scene.positions[v[2]]}, {}};
            if (unit_face_normal(w.p[0], w.p[1], w.p[2]) == Vec3f(0.0f)) continue;
            for (const Vec3f& q : w.p) w.box.extend(q);
            if (overlap(w.box, region)) out.push_back(w);
        }
    }
}

// Every crossing between a triangle of `a` and one of `b` (by their world corners; pairs that
// share a corner position touch there and are not tested), t from a and u from b, by (t, u).
// Both lists are sorted by their boxes' low x and swept: each pair whose boxes overlap along x
// is met once, from the one that starts first, rather than every pair of the two lists (two
// crowd instances that overlap share thousands of triangles in their boxes' common part).
// (Boxes with a NaN x, which no order holds, are tested against the whole other list.)
std::vector<PairCrossing> cross(std::vector<WorldTriangle>& a, std::vector<WorldTriangle>& b) {
    auto ordered = [](const WorldTriangle& x) {
        return !std::isnan(x.box.lo.x) && !std::isnan(x.box.hi.x);
    };
    auto by_low_x = [](const WorldTriangle& x, const WorldTriangle& y) {
        return x.box.lo.x < y.box.lo.x;
    };
    const auto a_end =
        static_cast<std::size_t>(std::partition(a.begin(), a.end(), ordered) - a.begin());
    const auto b_end =
        static_cast<std::size_t>(std::partition(b.begin(), b.end(), ordered) - b.begin());
    std::sort(a.begin(), a.begin() + static_cast<std::ptrdiff_t>(a_end), by_low_x);
    std::sort(b.begin(), b.begin() + static_cast<std::ptrdiff_t>(b_end), by_low_x);
    std::vector<PairCrossing> out;
    auto test = [&](const WorldTriangle& x, const WorldTriangle& y) {
        if (!overlap(x.box, y.box)) return;
        bool shared = false;
        for (const Vec3f& p : x.p)
            for (const Vec3f& q : y.p) shared = shared || same_point(p, q);
        if (shared) return;
        PairCrossing pc{x.t, y.t, {}};
        if (intersect_triangles(x.p, y.p, pc.crossing)) out.push_back(pc);
    };
    std::size_t i = 0, j = 0;
    while (i < a_end && j < b_end) {
        if (a[i].box.lo.x <= b[j].box.lo.x) {
            for (std::size_t k = j; k < b_end && b[k].box.lo.x <= a[i].box.hi.x; ++k)
                test(a[i], b[k]);
            ++i;
        } else {
            for (std::size_t k = i; k < a_end && a[k].box.lo.x <= b[j].box.hi.x; ++k)
                test(a[k], b[j]);
            ++j;
        }
    }
    for (std::size_t k = a_end; k < a.size(); ++k)
        for (const WorldTriangle& y : b) test(a[k], y);
    for (std::size_t k = b_end; k < b.size(); ++k)
        for (std::size_t m = 0; m < a_end; ++m) test(a[m], b[k]);
    std::sort(out.begin(), out.end(), [](const PairCrossing& x, const PairCrossing& y) {
        return std::tie(x.t, x.u) < std::tie(y.t, y.u);
    });
    return out;
}

}  // namespace

std::vector<std::size_t> instance_chain_cuts(std::span<const EdgePiece> pieces,
                                             std::span<const FeatureSegment> segments,
                                             std::size_t first_segment, std::size_t end_segment,
                                             std::size_t min_part) {
    auto of_instances = [&](const EdgePiece& p) {
        return p.segment >= first_segment && p.segment < end_segment;
    };
    // A crossing's first face is on one of its sides: cutting where it changes cuts between
    // pairs (a pair's crossings come together).
    auto instance = [&](std::size_t i) { return segments[pieces[i].segment].face_instance[0]; };
    std::size_t i = static_cast<std::size_t>(
        std::find_if(pieces.begin(), pieces.end(), of_instances) - pieces.begin());
    std::vector<std::size_t> cuts{i};
    for (; i < pieces.size() && of_instances(pieces[i]); ++i)
        if (i - cuts.back() >= min_part && instance(i) != instance(i - 1)) cuts.push_back(i);
    if (i > cuts.back()) cuts.push_back(i);
    if (std::any_of(pieces.begin() + static_cast<std::ptrdiff_t>(i), pieces.end(), of_instances))
        return {pieces.size()};
    return cuts;
}

const WeldedMesh& instance_welded_mesh(const InstanceLineCache& cache, std::uint32_t instance) {
    return cache.of_instance[instance]->welded;
}

void add_instance_segments(const Scene& scene, const TriangleAccel& accel, const WeldedMesh& own,
                           const ViewPlane& plane, const ScreenProjection& view, float margin,
                           const FeatureEdgeSettings& settings, int threads,
                           InstanceLineCache& cache, std::vector<FeatureSegment>& segments,
                           const InstanceLineOptions& options, InstanceVisibility* visibility) {
    cache.of_instance.clear();
    if (scene.instances.empty()) {
        cache.meshes.clear();
        cache.pairs.clear();
        return;
    }
    // Each mesh's work, from the cache when the same mesh object was seen with these settings.
    std::vector<std::shared_ptr<const MeshLines>> by_mesh(scene.meshes.size());
    std::vector<std::shared_ptr<const MeshLines>> kept;
    for (const Instance& instance : scene.instances) {
        std::shared_ptr<const MeshLines>& ml = by_mesh[instance.mesh];
        if (ml) continue;
        const auto& mesh = scene.meshes[instance.mesh];
        for (const auto& entry : cache.meshes)
            if (entry->mesh == mesh && entry->made_with(settings)) {
                kept.push_back(entry);
                break;
            }
        if (kept.empty() || kept.back()->mesh != mesh) {
            kept.push_back(make_mesh_lines(mesh, settings, threads));
            ++cache.mesh_builds;
        }
        ml = kept.back();
    }
    cache.meshes = std::move(kept);
    cache.of_instance.reserve(scene.instances.size());
    for (const Instance& instance : scene.instances)
        cache.of_instance.push_back(by_mesh[instance.mesh].get());

    // Visibility keeps what lies within its margin of the image: the view volume is wider by
    // some pixels more, so that rounding never culls what visibility would keep.
    const ViewVolume volume_all(view, plane, margin + 8.0f);
    const ViewVolume* view_volume = options.view_culling ? &volume_all : nullptr;
    // The instances' world boxes.
    const std::size_t count = scene.instances.size();
    std::vector<BBox> world(count);
    for (std::size_t i = 0; i < count; ++i)
        world[i] = grown(scene.instances[i].to_world.box(cache.of_instance[i]->box));

    // With visibility: a part's segments keep only those a piece lies on (in order), and its
    // pieces are numbered within the part until the parts are joined.
    const VisibilityContext context{scene, own, accel, view, &cache};
    auto keep_drawn = [&](std::vector<FeatureSegment>& part, std::vector<EdgePiece>& pieces,
                          int part_threads) {
        pieces = split_by_visibility(part, context, visibility->settings, part_threads);
        drop_segments_without_pieces(part, pieces);
        part.shrink_to_fit();
    };
    // Appends the parts' pieces to visibility->pieces, numbered as `segments` will hold the
    // parts' segments (`part_sizes` of them) from index `first` on.
    auto join_pieces = [&](std::vector<std::vector<EdgePiece>>& pieces,
                           const std::vector<std::size_t>& part_sizes, std::size_t first) {
        for (std::size_t c = 0; c < part_sizes.size(); ++c) {
            for (EdgePiece& piece : pieces[c]) piece.segment += static_cast<std::uint32_t>(first);
            first += part_sizes[c];
        }
        append_parts(pieces, visibility->pieces);
    };
    auto sizes_of = [](const std::vector<std::vector<FeatureSegment>>& parts) {
        std::vector<std::size_t> sizes;
        for (const auto& part : parts) sizes.push_back(part.size());
        return sizes;
    };

    // Per instance, in chunks of instances joined in order.
    const Vec3f eye = view.eye();
    // The instances' lines are most of a crowd's segments: they are moved into `segments` last,
    // once the rest is found, into room made for everything (append_parts), so that they are
    // held about once rather than twice.
    constexpr int kInstancesPerChunk = 16;
    std::vector<std::vector<EdgePiece>> piece_parts(
        visibility ? (count + kInstancesPerChunk - 1) / kInstancesPerChunk : 0);
    std::vector<std::vector<FeatureSegment>> lines = chunk_outputs<FeatureSegment>(
        static_cast<int>(count), kInstancesPerChunk, threads,
        [&](int i0, int i1, std::vector<FeatureSegment>& out) {
            std::vector<FeatureSegment> smooth;
            std::vector<MeshLines::EdgeLine> edges_found, sort_scratch;
            for (int i = i0; i < i1; ++i) {
                const auto u = static_cast<std::uint32_t>(i);
                const ViewVolume* volume = nullptr;
                if (view_volume) {
                    if (!view_volume->may_see(world[u])) continue;
                    if (!view_volume->sees_all(world[u])) volume = view_volume;
                }
                instance_segments(place(scene, u, cache.of_instance[u], eye), volume, settings,
                                  options, out, smooth, edges_found, sort_scratch);
            }
            if (visibility)
                keep_drawn(out, piece_parts[static_cast<std::size_t>(i0 / kInstancesPerChunk)], 1);
        });
    if (!settings.intersections) {
        cache.pairs.clear();
        if (visibility) join_pieces(piece_parts, sizes_of(lines), segments.size());
        append_parts(lines, segments);
        return;
    }

    // Intersection lines between instances whose boxes overlap (found by a sweep along x),
    // and between the own triangles and instances. A pair counts when the boxes' common part
    // may be in view.
    std::vector<std::uint32_t> order(count);
    for (std::uint32_t i = 0; i < count; ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::uint32_t x, std::uint32_t y) {
        return std::tie(world[x].lo.x, x) < std::tie(world[y].lo.x, y);
    });
    std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
    for (std::size_t i = 0; i < count; ++i)
        for (std::size_t j = i + 1; j < count && world[order[j]].lo.x <= world[order[i]].hi.x;
             ++j) {
            std::uint32_t a = order[i], b = order[j];
            if (!overlap(world[a], world[b])) continue;
            if (view_volume && !view_volume->may_see(intersection(world[a], world[b]))) continue;
            if (b < a) std::swap(a, b);
            pairs.push_back({a, b});
        }
    std::sort(pairs.begin(), pairs.end());
    std::vector<InstanceLineCache::Pair> found(pairs.size());
    parallel_for(static_cast<int>(pairs.size()), 1, threads, [&](int p0, int p1) {
        std::vector<WorldTriangle> ta, tb;
        for (int p = p0; p < p1; ++p) {
            const auto [a, b] = pairs[static_cast<std::size_t>(p)];
            InstanceLineCache::Pair& pair = found[static_cast<std::size_t>(p)];
            pair.a = a;
            pair.b = b;
            pair.mesh_a = by_mesh[scene.instances[a].mesh];
            pair.mesh_b = by_mesh[scene.instances[b].mesh];
            pair.to_world_a = scene.instances[a].to_world;
            pair.to_world_b = scene.instances[b].to_world;
            // The last frame's crossings when neither moved (the cache's pairs are sorted).
            const auto it = std::lower_bound(
                cache.pairs.begin(), cache.pairs.end(), pair,
                [](const InstanceLineCache::Pair& x, const InstanceLineCache::Pair& y) {
                    return std::tie(x.a, x.b) < std::tie(y.a, y.b);
                });
            if (it != cache.pairs.end() && it->a == a && it->b == b && it->mesh_a == pair.mesh_a &&
                it->mesh_b == pair.mesh_b && it->to_world_a == pair.to_world_a &&
                it->to_world_b == pair.to_world_b) {
                pair.crossings = it->crossings;
                continue;
            }
            const BBox region = intersection(world[a], world[b]);
            triangles_in(*pair.mesh_a, pair.to_world_a, region, ta);
            triangles_in(*pair.mesh_b, pair.to_world_b, region, tb);
            pair.crossings = cross(ta, tb);
        }
    });
    cache.pairs = std::move(found);

    std::vector<FeatureSegment> crossing_lines;
    for (const InstanceLineCache::Pair& pair : cache.pairs) {
        if (pair.crossings.empty()) continue;
        const Placement pa = place(scene, pair.a, pair.mesh_a.get(), eye);
        const Placement pb = place(scene, pair.b, pair.mesh_b.get(), eye);
        for (const PairCrossing& pc : pair.crossings) {
            const bool hidden = pa.turned_away(pc.t) || pb.turned_away(pc.u);
            if (hidden && !settings.certainly_hidden) continue;
            crossing_lines.push_back(crossing_segment(pc.crossing, pc.t, pc.u, pair.a, pair.b,
                                                      pair.mesh_a->welded, pair.mesh_b->welded,
                                                      hidden));
        }
    }
    // The own triangles against each instance (in instance order). The own triangles' rule
    // for faces turned away is not applied here: those crossings are traced and found hidden.
    const Bvh& own_tree = accel.bvh();
    std::vector<std::vector<FeatureSegment>> own_pairs(own_tree.nodes.empty() ? 0 : count);
    const BBox own_box = own_tree.nodes.empty() ? BBox{} : grown(own_tree.nodes[0].bounds);
    parallel_for(static_cast<int>(own_pairs.size()), 16, threads, [&](int i0, int i1) {
        std::vector<WorldTriangle> ta, tb;
        for (int i = i0; i < i1; ++i) {
            const auto b = static_cast<std::uint32_t>(i);
            if (!overlap(own_box, world[b])) continue;
            const BBox region = intersection(own_box, world[b]);
            if (view_volume && !view_volume->may_see(region)) continue;
            own_triangles_in(scene, own_tree, region, ta);
            if (ta.empty()) continue;
            triangles_in(*cache.of_instance[b], scene.instances[b].to_world, region, tb);
            const std::vector<PairCrossing> crossings = cross(ta, tb);
            if (crossings.empty()) continue;
            const Placement pb = place(scene, b, cache.of_instance[b], eye);
            for (const PairCrossing& pc : crossings) {
                const bool hidden = pb.turned_away(pc.u);
                if (hidden && !settings.certainly_hidden) continue;
                own_pairs[static_cast<std::size_t>(i)].push_back(
                    crossing_segment(pc.crossing, pc.t, pc.u, kNoIndex, b, own,
                                     cache.of_instance[b]->welded, hidden));
            }
        }
    });
    std::vector<std::vector<FeatureSegment>> crossings{std::move(crossing_lines)};
    append_parts(own_pairs, crossings[0]);
    if (visibility) {
        piece_parts.emplace_back();
        keep_drawn(crossings[0], piece_parts.back(), threads);
    }
    std::vector<std::size_t> part_sizes = sizes_of(lines);
    part_sizes.push_back(crossings[0].size());
    const std::size_t first = segments.size();
    // The pieces and the segments are joined side by side: each join is a copy into fresh
    // memory, and a crowd's were a serial stage of its frame.
    parallel_for(2, 1, threads, [&](int j0, int j1) {
        for (int j = j0; j < j1; ++j) {
            if (j == 0 && visibility) join_pieces(piece_parts, part_sizes, first);
            if (j == 1) {
                append_parts(lines, segments, crossings[0].size());
                append_parts(crossings, segments);
            }
        }
    });
}

}  // namespace toonray::ink
