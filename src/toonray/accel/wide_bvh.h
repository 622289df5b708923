#pragma once
/// The traversal structure of TriangleAccel (internal to the accel module): the binary BVH
/// collapsed into 8-wide nodes whose child boxes are tested together with SIMD, over triangles
/// stored four to a block, structure-of-arrays, in leaf order.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "toonray/accel/bvh.h"
#include "toonray/core/bbox.h"
#include "toonray/core/index.h"
#include "toonray/core/math.h"

namespace toonray::accel {

/// Child references: kEmptyChild, an inner node index, or a leaf (kLeafBit set) whose
/// triangles start at slot leaf_first(ref) of the packed triangle array (slot t is lane t % 4 of
/// block t / 4): leaf_count(ref) of them, or when that is 0 (more than 15), up to the first slot
/// whose prim has kLeafEnd set (which every leaf's last slot has).
inline constexpr std::uint32_t kLeafBit = 0x80000000u;
inline constexpr std::uint32_t kLeafCountShift = 27;
inline constexpr std::uint32_t kMaxSlots = 1u << kLeafCountShift;  ///< 134 million triangles
inline constexpr std::uint32_t kLeafEnd =
    0x80000000u;  ///< in TriBlock::prim: last triangle of its leaf
inline constexpr std::uint32_t kEmptyChild = 0xffffffffu;

[[nodiscard]] inline bool is_leaf(std::uint32_t ref) { return (ref & kLeafBit) != 0; }
[[nodiscard]] inline std::uint32_t leaf_first(std::uint32_t ref) { return ref & (kMaxSlots - 1); }
[[nodiscard]] inline std::uint32_t leaf_count(std::uint32_t ref) {
    return (ref >> kLeafCountShift) & 15u;
}

/// 256 bytes, cache-line aligned. Unused slots have empty boxes (lo = +inf, hi = -inf), which
/// no ray enters.
struct alignas(64) WideNode {
    float lo[3][8];  ///< [axis][child]
    float hi[3][8];
    std::uint32_t child[8];
    std::uint32_t pad[8];  ///< pad[0]: bit i set when child[i] is a child
};
static_assert(sizeof(WideNode) == 256);

/// Four triangle slots, structure of arrays. Leaves are packed one after another with no gaps;
/// the slots after the last leaf (and two whole blocks after it, which 8-wide loads may touch)
/// have NaN corners, which fail every test, and prim == kNoIndex.
struct alignas(16) TriBlock {
    float v[3][3][4];       ///< [corner][axis][lane]
    std::uint32_t prim[4];  ///< triangle index in the input order, | kLeafEnd on a leaf's last
};
static_assert(sizeof(TriBlock) == 160);

/// Everything traversal reads.
struct WideBvh {
    std::vector<WideNode> nodes;
    std::vector<TriBlock> blocks;
    std::uint32_t root = kEmptyChild;  ///< inner node 0, or a single leaf, or empty
    int depth = 0;                     ///< wide levels (a leaf root counts 0)
    std::size_t max_stack = 0;         ///< stack entries traversal can need
    /// The sphere around the triangles' box (build()), which tells the instance tiles how
    /// many rays an instance of this tree covers.
    Vec3f centre{0.0f};
    float radius = 0.0f;

    /// Whether rays from `origin` spaced as `ray_angle2` says (the squared angle between
    /// neighbouring rays) should go through this tree as packets: when they cover at least one
    /// ray per block of four triangles over its bounding sphere. Otherwise each ray goes alone:
    /// where many triangles lie between neighbouring rays, a packet's frustum reaches most of
    /// the leaves near its rays to find a few hits (at one sample a pixel, a crowd of 10,000
    /// instances of a 70k-triangle mesh visited 49M leaves by packets against 1M ray by ray,
    /// and took ten times as long), while the piano's keys, a few hundred triangles each under
    /// many pixels, took twice as long ray by ray. Either way the hits are the same; this only
    /// chooses the faster traversal.
    [[nodiscard]] bool dense_for(const Vec3f& origin, float ray_angle2) const;

    /// SAH weights of the collapse: a wide node visit, and a leaf's test per block of 4.
    struct CollapseCosts {
        float node = 1.0f;
        float block = 1.0f;
        std::uint32_t merge_leaf =
            8;  ///< subtrees of at most this many triangles may become one leaf
        std::uint32_t leaf_width = 4;  ///< triangles a leaf test takes at once
    };

    /// Collapses `bvh` (built over `tris`) and packs the triangles. `leaf_areas[i]` is the half
    /// area of the box of triangle bvh.prim_indices[i] (read in leaf order, not gathered).
    void build(const Bvh& bvh, std::span<const float> leaf_areas, std::span<const Vec3f> positions,
               std::span<const std::array<std::uint32_t, 3>> tris, const CollapseCosts& costs);
    /// The same collapse over primitives that are boxes (`bvh` built over `boxes`), without
    /// triangle blocks: the leaves' slots index `slots`, which receives the primitive ids in
    /// leaf order, the last of each leaf or'ed with kLeafEnd (the instance level's tree).
    void build_over_boxes(const Bvh& bvh, std::span<const float> leaf_areas,
                          std::span<const BBox> boxes, const CollapseCosts& costs,
                          std::vector<std::uint32_t>& slots);
};

/// What traversal reads of one instance (TriangleAccel::set_instances), 64 bytes: the ray is
/// taken into object space by `from_world` (summed in double, rounded once: the same bits on
/// every CPU) and traced through the mesh's tree.
struct alignas(64) InstanceRecord {
    float from_world[3][4];  ///< world to object, row-major; unused when `identity`
    const WideBvh* tree = nullptr;
    /// Ties between instances go to the lower rank: 0 for the accelerator's own triangles,
    /// i + 1 for instance i.
    std::uint32_t rank = 0;
    std::uint32_t identity = 0;  ///< 1: object space is world space (the own triangles)
};
static_assert(sizeof(InstanceRecord) == 64);

/// The top level of a two-level BVH: a wide tree over the instances' world boxes whose leaves'
/// slots index `slots`, each the index of a record.
struct InstanceLevel {
    WideBvh tree;  ///< nodes only (no blocks)
    std::vector<std::uint32_t> slots;
    std::vector<InstanceRecord> records;
    std::size_t bottom_stack = 8;  ///< the largest max_stack of the records' trees
};

/// BestHit's "no hit yet, but a hit at the same distance wins" (see kernels.inl): above every
/// triangle index, and positive as a signed number.
inline constexpr std::uint32_t kTieWins = 0x7ffffffeu;

}  // namespace toonray::accel
