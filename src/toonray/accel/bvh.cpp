#include "toonray/accel/bvh.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <bit>
#include <cstddef>
#include <limits>
#include <memory>
#include <mutex>
#include <type_traits>

#include "toonray/accel/huge_pages.h"
#include "toonray/core/simd_sse.h"

namespace toonray {
namespace {

// A primitive while building: its box, with the primitive id in the w lane of `lo`. The centre
// used for binning is lo + hi (twice the box centre; the factor does not matter).
struct alignas(32) PrimRef {
    __m128 lo;
    __m128 hi;
};

constexpr int kMaxBins = 64;
constexpr int kMaxLeaf = 128;
// Nodes with at least this many primitives are binned by several tasks, in chunks of kChunk;
// subtrees of at least kTaskSize primitives become tasks of their own. These
// are fixed numbers, so the tree never depends on the thread count.
constexpr std::size_t kParallelSplit = 1u << 15;
constexpr std::size_t kChunk = 1u << 13;
constexpr std::size_t kTaskSize = 1u << 11;
// Nodes this small become leaves without an SAH evaluation (when the leaf size allows): the
// wide tree can still spread their triangles over slots of their own (wide_bvh.cpp), and
// binning the bottom levels costs a tenth of the build for no measurable gain.
constexpr std::uint32_t kSmallLeaf = 4;

const __m128 kPosInf = _mm_set1_ps(std::numeric_limits<float>::infinity());
const __m128 kNegInf = _mm_set1_ps(-std::numeric_limits<float>::infinity());

struct Box4 {
    __m128 lo = kPosInf;
    __m128 hi = kNegInf;
    void extend(__m128 l, __m128 h) {
        lo = _mm_min_ps(lo, l);
        hi = _mm_max_ps(hi, h);
    }
    void extend(const Box4& b) { extend(b.lo, b.hi); }
    void extend_point(__m128 p) { extend(p, p); }
    [[nodiscard]] float half_area() const {
        alignas(16) float e[4];
        _mm_store_ps(e, _mm_sub_ps(hi, lo));
        return e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
    }
    [[nodiscard]] BBox bbox() const {
        alignas(16) float l[4], h[4];
        _mm_store_ps(l, lo);
        _mm_store_ps(h, hi);
        return BBox{Vec3f(l[0], l[1], l[2]), Vec3f(h[0], h[1], h[2])};
    }
};

// Per axis and bin: the bounds of the primitives whose centres fall in the bin, and their count
// in the w lane of `hi` (an integer). One store fewer per update than a count array: the binning
// loop is bound by its stores.
struct Bins {
    // Plain data: a Box4 member would initialise all 3 x 64 bins on every construction, and
    // clear() sets only the bins a node uses.
    struct Bin {
        __m128 lo, hi;
    };
    Bin box[3][kMaxBins];  // [axis][bin]
    void clear(int n) {
        const Bin empty{kPosInf, _mm_blend_ps(kNegInf, _mm_setzero_ps(), 8)};
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < n; ++b) box[a][b] = empty;
    }
    void merge(const Bins& o, int n) {
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < n; ++b) {
                Bin& x = box[a][b];
                const Bin& y = o.box[a][b];
                x.lo = _mm_min_ps(x.lo, y.lo);
                x.hi = _mm_blend_ps(
                    _mm_max_ps(x.hi, y.hi),
                    _mm_castsi128_ps(_mm_add_epi32(_mm_castps_si128(x.hi), _mm_castps_si128(y.hi))),
                    8);
            }
    }
    [[nodiscard]] std::uint32_t count(int a, int b) const {
        return static_cast<std::uint32_t>(_mm_extract_epi32(_mm_castps_si128(box[a][b].hi), 3));
    }
    [[nodiscard]] __m128i counts(int b) const {
        return _mm_setr_epi32(static_cast<int>(count(0, b)), static_cast<int>(count(1, b)),
                              static_cast<int>(count(2, b)), 0);
    }
};
static_assert(sizeof(Bins::Bin) == 32 && std::is_trivially_default_constructible_v<Bins>);

// Half areas of three boxes at once (lanes 0-2).
inline __m128 half_areas(const Box4& a, const Box4& b, const Box4& c) {
    __m128 x = _mm_sub_ps(a.hi, a.lo), y = _mm_sub_ps(b.hi, b.lo), z = _mm_sub_ps(c.hi, c.lo),
           w = _mm_setzero_ps();
    _MM_TRANSPOSE4_PS(x, y, z, w);  // now x = extents along x of the three boxes, etc.
    return _mm_add_ps(_mm_add_ps(_mm_mul_ps(x, y), _mm_mul_ps(y, z)), _mm_mul_ps(z, x));
}

// Maps centres (lo + hi) to bin indices on all three axes at once.
struct Binner {
    __m128 base, scale;
    __m128i max_bin;
    Binner(const Box4& centres, int bins) {
        // bins * 0.99999 / extent on each axis, slightly under `bins` so that the largest centre
        // lands in the last bin, not past it; 0 where the extent is not positive, or so small
        // that the scale is not finite, and in lane 3.
        const __m128 extent = _mm_sub_ps(centres.hi, centres.lo);
        const __m128 s = _mm_div_ps(_mm_set1_ps(static_cast<float>(bins) * 0.99999f), extent);
        const __m128 usable =
            _mm_and_ps(_mm_cmpgt_ps(extent, _mm_setzero_ps()),
                       _mm_cmplt_ps(s, _mm_set1_ps(std::numeric_limits<float>::infinity())));
        base = centres.lo;
        scale = _mm_and_ps(_mm_blend_ps(s, _mm_setzero_ps(), 8), usable);
        max_bin = _mm_set1_epi32(bins - 1);
    }
    [[nodiscard]] __m128i bin(const PrimRef& r) const {
        __m128 c = _mm_add_ps(r.lo, r.hi);
        __m128i i = _mm_cvttps_epi32(_mm_mul_ps(_mm_sub_ps(c, base), scale));
        return _mm_max_epi32(_mm_min_epi32(i, max_bin), _mm_setzero_si128());
    }
};


// Adds one primitive to the bin of its centre on each axis; `off` holds the byte offsets of
// those bins. Lane 3 of a bin's hi is its count: the blend takes it from the integer add and
// discards the max's lane 3.
inline void bin_add(Bins& bins, const PrimRef& r, const std::uint32_t* off) {
    char* boxes = reinterpret_cast<char*>(&bins.box[0][0]);
    const __m128i one = _mm_setr_epi32(0, 0, 0, 1);
    for (int a = 0; a < 3; ++a) {
        Bins::Bin& b = *reinterpret_cast<Bins::Bin*>(boxes + off[a]);
        b.lo = _mm_min_ps(b.lo, r.lo);
        b.hi = _mm_blend_ps(_mm_max_ps(b.hi, r.hi),
                            _mm_castsi128_ps(_mm_add_epi32(_mm_castps_si128(b.hi), one)), 8);
    }
}

// Primitives are binned in batches: first the byte offsets of every primitive's three bins,
// then the updates. Computed in the same loop, each update's address came from a chain of
// float operations on its primitive, and the loads of the next updates waited behind stores
// whose addresses were not known yet: 33 cycles a primitive against 12-14 in batches (1M
// triangles, all node sizes).
constexpr std::size_t kBatch = 256;
using BinOffsets = std::uint32_t[kBatch][4];

void bin_offsets(const PrimRef* refs, std::size_t n, const Binner& binner, BinOffsets& offs) {
    const __m128i axis_off = _mm_setr_epi32(0, kMaxBins * 32, 2 * kMaxBins * 32, 0);
    for (std::size_t k = 0; k < n; ++k)
        _mm_store_si128(reinterpret_cast<__m128i*>(offs[k]),
                        _mm_add_epi32(_mm_slli_epi32(binner.bin(refs[k]), 5), axis_off));
}

void bin_range(const PrimRef* refs, std::size_t begin, std::size_t end, const Binner& binner,
               Bins& bins) {
    alignas(16) BinOffsets offs;
    for (std::size_t i = begin; i < end; i += kBatch) {
        const std::size_t m = std::min(kBatch, end - i);
        bin_offsets(refs + i, m, binner, offs);
        for (std::size_t k = 0; k < m; ++k) bin_add(bins, refs[i + k], offs[k]);
    }
}

// The same into four bin sets, primitive i into set i % 4, merged into `out` after: neighbours
// in memory are neighbours in space and usually share bins, and one set would chain every
// update on the previous one's through memory (four sets measured faster than one or two).
void bin_range4(const PrimRef* refs, std::size_t begin, std::size_t end, const Binner& binner,
                int bins, Bins& out) {
    Bins more[3];
    for (Bins& m : more) m.clear(bins);
    Bins* sets[4] = {&out, &more[0], &more[1], &more[2]};
    alignas(16) BinOffsets offs;
    for (std::size_t i = begin; i < end; i += kBatch) {
        const std::size_t m = std::min(kBatch, end - i);
        bin_offsets(refs + i, m, binner, offs);
        std::size_t k = 0;
        for (; k + 3 < m; k += 4)
            for (std::size_t s = 0; s < 4; ++s) bin_add(*sets[s], refs[i + k + s], offs[k + s]);
        for (; k < m; ++k) bin_add(out, refs[i + k], offs[k]);
    }
    for (const Bins& m : more) out.merge(m, bins);
}

// Nodes as one task makes them, in the order it makes them (depth first, children pairs after
// their parent). A task that builds a subtree of its own gets a chunk of its own, whose node 0
// is that subtree's root; in its parent's chunk the root's slot holds a reference to it
// (kSubtree) until the chunks are joined, ordered by the subtree's first primitive: an order that
// does not depend on scheduling, so neither does the tree's layout.
constexpr std::uint32_t kSubtree = 0xffffffffu;  // BvhNode::count of a slot whose node is elsewhere

struct NodeChunk {
    std::vector<BvhNode> nodes;
    std::uint32_t id = 0;  // index in Builder::chunks
    std::size_t first_prim = 0;
    std::uint32_t offset = 0;  // where its node 1 goes in the joined array
};

struct Task {
    NodeChunk* chunk;
    std::uint32_t node;  // index in chunk->nodes
    std::size_t begin, end;
    Box4 bounds, centres;
};

struct Split {
    int axis = -1;
    int bin = 0;  // primitives in bins [0, bin) go left
    std::uint32_t left_count = 0;
    float cost = std::numeric_limits<float>::infinity();
    Box4 left, right;
};

// Whether a primitive goes left: its bin on axis A is below the split. The same float
// operations as Binner::bin (the clamp does not change the comparison, as 1 <= split < bins),
// so exactly Split::left_count primitives go left.
template <int A>
struct GoesLeft {
    __m128 base, scale;
    __m128i split;  // the split bin in every lane
    // All ones when the centre goes left.
    [[nodiscard]] __m128i mask(__m128 centre) const {
        return _mm_cmplt_epi32(_mm_shuffle_epi32(bin(centre), A * 0x55), split);
    }
    [[nodiscard]] __m128i bin(__m128 centre) const {
        return _mm_cvttps_epi32(_mm_mul_ps(_mm_sub_ps(centre, base), scale));
    }
};

// Partitions refs[begin, end) in place so that the primitives going left come first, up to
// `mid` (their count is known from the bins), and bounds the centres of both sides. Only the
// misplaced primitives move (Hoare's scheme): blocks of 64 of the left part and of the right
// part are classified into bit masks without a branch (the side would mispredict about as
// often as not), and the misplaced ones of both masks are swapped pairwise. Each primitive is
// read once and at most one in two is written, where swapping every primitive to the end of
// the left side (Lomuto's scheme) wrote all of them twice: 19 cycles a primitive against 9-10
// (1M triangles). The order within each side changes no split: bins are minima, maxima and
// counts.
template <int A>
void partition_range(PrimRef* refs, std::size_t begin, std::size_t mid, std::size_t end,
                     GoesLeft<A> left, Box4& lc, Box4& rc) {
    __m128 llo = lc.lo, lhi = lc.hi, rlo = rc.lo, rhi = rc.hi;
    // Bit k: whether refs[from + k] goes left, for k < to - from <= 64. Every centre extends
    // the bounds of the side it goes to.
    auto goes_left = [&](std::size_t from, std::size_t to) {
        std::uint64_t bits = 0;
        for (std::size_t k = from; k < to; ++k) {
            const __m128 c = _mm_add_ps(refs[k].lo, refs[k].hi);
            const __m128 m = _mm_castsi128_ps(left.mask(c));
            bits |= static_cast<std::uint64_t>(_mm_movemask_ps(m) & 1) << (k - from);
            llo = _mm_min_ps(llo, _mm_blendv_ps(kPosInf, c, m));
            lhi = _mm_max_ps(lhi, _mm_blendv_ps(kNegInf, c, m));
            rlo = _mm_min_ps(rlo, _mm_blendv_ps(c, kPosInf, m));
            rhi = _mm_max_ps(rhi, _mm_blendv_ps(c, kNegInf, m));
        }
        return bits;
    };
    auto low_bits = [](std::size_t n) {
        return n >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << n) - 1;
    };
    // Scanned up to l_scan / r_scan; the misplaced primitives of the last blocks scanned (which
    // start at l_base / r_base) that are not swapped yet are the bits of l_wrong / r_wrong.
    std::size_t l_scan = begin, l_base = begin, r_scan = mid, r_base = mid;
    std::uint64_t l_wrong = 0, r_wrong = 0;
    for (;;) {
        if (l_wrong == 0) {
            if (l_scan == mid) break;
            const std::size_t to = std::min<std::size_t>(l_scan + 64, mid);
            l_base = l_scan;
            l_wrong = ~goes_left(l_scan, to) & low_bits(to - l_scan);
            l_scan = to;
        } else if (r_wrong == 0) {
            if (r_scan == end) break;
            const std::size_t to = std::min<std::size_t>(r_scan + 64, end);
            r_base = r_scan;
            r_wrong = goes_left(r_scan, to);
            r_scan = to;
        } else {
            do {
                std::swap(refs[l_base + static_cast<std::size_t>(std::countr_zero(l_wrong))],
                          refs[r_base + static_cast<std::size_t>(std::countr_zero(r_wrong))]);
                l_wrong &= l_wrong - 1;
                r_wrong &= r_wrong - 1;
            } while (l_wrong != 0 && r_wrong != 0);
        }
    }
    // The left part is always scanned to its end (a misplaced primitive there waits for one on
    // the right, and both sides hold as many); the rest of the right part, once every misplaced
    // primitive is swapped, is in place, and its centres still bound the right child.
    for (std::size_t k = r_scan; k < end; ++k) {
        const __m128 c = _mm_add_ps(refs[k].lo, refs[k].hi);
        rlo = _mm_min_ps(rlo, c);
        rhi = _mm_max_ps(rhi, c);
    }
    lc = Box4{llo, lhi};
    rc = Box4{rlo, rhi};
}

struct Builder {
    const Bvh::Config& config;
    int bins;
    int max_leaf;
    int block_shift;              // log2 of the block size
    PrimRef* refs;                // the primitives, partitioned in place
    std::uint32_t* prim_indices;  // leaves write their primitives' ids here
    float* leaf_areas;            // and, when not null, their boxes' half areas
    tbb::task_group tasks;
    std::mutex chunks_mutex;
    std::vector<std::unique_ptr<NodeChunk>> chunks;

    Builder(const Bvh::Config& c, PrimRef* refs_, std::uint32_t* ids, float* areas)
        : config(c),
          bins(std::clamp(c.bin_count, 2, kMaxBins)),
          max_leaf(std::clamp(c.max_leaf_size, 1, kMaxLeaf)),
          block_shift(0),
          refs(refs_),
          prim_indices(ids),
          leaf_areas(areas) {
        while ((1 << block_shift) < std::clamp(c.block_size, 1, 64)) ++block_shift;
    }

    struct NewChunk {
        NodeChunk* chunk;
        std::uint32_t id;
    };
    NewChunk new_chunk(std::size_t first_prim, std::size_t prims) {
        auto chunk = std::make_unique<NodeChunk>();
        chunk->first_prim = first_prim;
        // A subtree has about 0.6 nodes a primitive, but a task's chunk holds only the nodes not
        // in its own subtasks' chunks: the top levels of a large subtree, or a whole small one.
        // Not advised for huge pages, which would zero 2 MiB for the few nodes of a large one.
        chunk->nodes.reserve(std::min<std::size_t>(prims, kTaskSize * 2));
        std::lock_guard lock(chunks_mutex);
        chunk->id = static_cast<std::uint32_t>(chunks.size());
        chunks.push_back(std::move(chunk));
        return {chunks.back().get(), chunks.back()->id};
    }

    [[nodiscard]] float blocks(std::uint32_t n) const {
        return static_cast<float>((n + (1u << block_shift) - 1) >> block_shift);
    }

    // Bins t's primitives into `out`. A node of kParallelSplit primitives or more is binned by
    // several tasks, in chunks of kChunk (`chunk_bins` holds their bins).
    void bin(const Task& t, const Binner& binner, int bins, Bins& out,
             std::vector<Bins>& chunk_bins) const {
        const std::size_t n = t.end - t.begin;
        out.clear(bins);
        if (n < kParallelSplit) {
            if (n < 1024) {
                bin_range(refs, t.begin, t.end, binner, out);
            } else {
                bin_range4(refs, t.begin, t.end, binner, bins, out);
            }
            return;
        }
        const std::size_t chunks = (n + kChunk - 1) / kChunk;
        if (chunk_bins.size() < chunks) chunk_bins.resize(chunks);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks, 1), [&](const auto& r) {
            for (std::size_t c = r.begin(); c != r.end(); ++c) {
                chunk_bins[c].clear(bins);
                const std::size_t b = t.begin + c * kChunk;
                bin_range4(refs, b, std::min(b + kChunk, t.end), binner, bins, chunk_bins[c]);
            }
        });
        // min/max and integer sums are exact: the merge order cannot change the result.
        for (std::size_t c = 0; c < chunks; ++c) out.merge(chunk_bins[c], bins);
    }

    [[nodiscard]] __m128 blocks4(__m128i n) const {
        return _mm_cvtepi32_ps(
            _mm_srli_epi32(_mm_add_epi32(n, _mm_set1_epi32((1 << block_shift) - 1)), block_shift));
    }

    // Binned SAH on all three axes at once (lanes 0-2).
    [[nodiscard]] Split find_split(const Bins& b, int bins, std::uint32_t n) const {
        alignas(16) __m128 right_area[kMaxBins];
        alignas(16) __m128i right_count[kMaxBins];
        Box4 acc[3];
        __m128i cnt = _mm_setzero_si128();
        for (int i = bins - 1; i > 0; --i) {
            for (int a = 0; a < 3; ++a) acc[a].extend(b.box[a][i].lo, b.box[a][i].hi);
            cnt = _mm_add_epi32(cnt, b.counts(i));
            right_area[i] = half_areas(acc[0], acc[1], acc[2]);
            right_count[i] = cnt;
        }
        for (auto& a : acc) a = Box4{};
        cnt = _mm_setzero_si128();
        const __m128i total = _mm_set1_epi32(static_cast<int>(n));
        __m128 best_cost = _mm_set1_ps(std::numeric_limits<float>::infinity());
        __m128i best_bin = _mm_setzero_si128();
        __m128i best_count = _mm_setzero_si128();
        for (int i = 0; i < bins - 1; ++i) {
            for (int a = 0; a < 3; ++a) acc[a].extend(b.box[a][i].lo, b.box[a][i].hi);
            cnt = _mm_add_epi32(cnt, b.counts(i));
            __m128 cost = _mm_add_ps(_mm_mul_ps(half_areas(acc[0], acc[1], acc[2]), blocks4(cnt)),
                                     _mm_mul_ps(right_area[i + 1], blocks4(right_count[i + 1])));
            // Both sides must be non-empty.
            __m128 valid = _mm_castsi128_ps(
                _mm_andnot_si128(_mm_or_si128(_mm_cmpeq_epi32(cnt, _mm_setzero_si128()),
                                              _mm_cmpeq_epi32(cnt, total)),
                                 _mm_set1_epi32(-1)));
            __m128 better = _mm_and_ps(valid, _mm_cmplt_ps(cost, best_cost));
            best_cost = _mm_blendv_ps(best_cost, cost, better);
            best_bin = _mm_castps_si128(_mm_blendv_ps(
                _mm_castsi128_ps(best_bin), _mm_castsi128_ps(_mm_set1_epi32(i + 1)), better));
            best_count = _mm_castps_si128(
                _mm_blendv_ps(_mm_castsi128_ps(best_count), _mm_castsi128_ps(cnt), better));
        }
        alignas(16) float costs[4];
        alignas(16) int bin_of[4];
        alignas(16) std::uint32_t count_of[4];
        _mm_store_ps(costs, best_cost);
        _mm_store_si128(reinterpret_cast<__m128i*>(bin_of), best_bin);
        _mm_store_si128(reinterpret_cast<__m128i*>(count_of), best_count);
        Split best;
        for (int axis = 0; axis < 3; ++axis)
            if (costs[axis] < best.cost) {
                best.cost = costs[axis];
                best.axis = axis;
                best.bin = bin_of[axis];
                best.left_count = count_of[axis];
            }
        if (best.axis >= 0)
            for (int i = 0; i < bins; ++i)
                (i < best.bin ? best.left : best.right)
                    .extend(b.box[best.axis][i].lo, b.box[best.axis][i].hi);
        return best;
    }

    // Partitions t's range in place and sets the children's centre bounds. One task, also for
    // the largest nodes: the children's subtrees are tasks of their own, so only the top levels
    // are partitioned with fewer tasks than threads, a small part of a build.
    template <int A>
    void partition_axis(const Task& t, const Binner& binner, const Split& s, Task& l, Task& r) {
        const GoesLeft<A> left{binner.base, binner.scale, _mm_set1_epi32(s.bin)};
        partition_range(refs, t.begin, t.begin + s.left_count, t.end, left, l.centres, r.centres);
    }

    void partition(const Task& t, const Binner& binner, const Split& s, Task& l, Task& r) {
        switch (s.axis) {
            case 0: partition_axis<0>(t, binner, s, l, r); break;
            case 1: partition_axis<1>(t, binner, s, l, r); break;
            default: partition_axis<2>(t, binner, s, l, r); break;
        }
    }

    void range_bounds(std::size_t begin, std::size_t end, Box4& bounds, Box4& centres) const {
        for (std::size_t i = begin; i < end; ++i) {
            bounds.extend(refs[i].lo, refs[i].hi);
            centres.extend_point(_mm_add_ps(refs[i].lo, refs[i].hi));
        }
    }

    static void set_node(const Task& t, const Box4& box, std::uint32_t first, std::uint32_t count) {
        t.chunk->nodes[t.node] = BvhNode{box.bbox(), first, count};
    }

    void make_leaf(const Task& t) {
        for (std::size_t i = t.begin; i < t.end; ++i)
            prim_indices[i] =
                static_cast<std::uint32_t>(_mm_extract_epi32(_mm_castps_si128(refs[i].lo), 3));
        if (leaf_areas)
            for (std::size_t i = t.begin; i < t.end; ++i)
                leaf_areas[i] = Box4{refs[i].lo, refs[i].hi}.half_area();
        set_node(t, t.bounds, static_cast<std::uint32_t>(t.begin),
                 static_cast<std::uint32_t>(t.end - t.begin));
    }

    // Builds the subtree of `root` with an explicit stack (a degenerate mesh could otherwise
    // recurse as deep as it has primitives). Large second children become tasks.
    void build(Task root) {
        std::vector<Task> todo{root};
        Bins bins_storage;
        std::vector<Bins> chunk_bins;  // of the large nodes' chunks
        while (!todo.empty()) {
            Task t = todo.back();
            todo.pop_back();
            const auto n = static_cast<std::uint32_t>(t.end - t.begin);
            // A small node, or one that fits one block (cheaper as a leaf than any split when a
            // traversal step costs at least a block test), is a leaf.
            if (n <= 1 || (n <= static_cast<std::uint32_t>(max_leaf) &&
                           (n <= kSmallLeaf ||
                            config.intersection_cost * blocks(n) <= config.traversal_cost))) {
                make_leaf(t);
                continue;
            }
            // Nodes under 64 primitives get 4 bins: the sweep's cost is per bin, and more bins
            // there gave no better trees (measured on the test scenes).
            const int node_bins = n < 64 ? static_cast<int>(std::min<std::uint32_t>(n, 4)) : bins;
            Binner binner(t.centres, node_bins);
            bin(t, binner, node_bins, bins_storage, chunk_bins);
            Split s = find_split(bins_storage, node_bins, n);
            const float leaf_cost = config.intersection_cost * blocks(n);
            std::size_t mid;
            Task left{t.chunk, 0, t.begin, 0, {}, {}};
            Task right{t.chunk, 0, 0, t.end, {}, {}};
            if (s.axis >= 0) {
                float split_cost = config.traversal_cost +
                                   config.intersection_cost * s.cost / t.bounds.half_area();
                if (!(split_cost < leaf_cost) && n <= static_cast<std::uint32_t>(max_leaf)) {
                    make_leaf(t);
                    continue;
                }
                partition(t, binner, s, left, right);
                mid = t.begin + s.left_count;
                left.bounds = s.left;
                right.bounds = s.right;
            } else {
                if (n <= static_cast<std::uint32_t>(max_leaf)) {
                    make_leaf(t);
                    continue;
                }
                mid = t.begin + n / 2;  // identical centres: split the list in two
                range_bounds(t.begin, mid, left.bounds, left.centres);
                range_bounds(mid, t.end, right.bounds, right.centres);
            }
            left.end = mid;
            right.begin = mid;
            auto& nodes = t.chunk->nodes;
            const auto pair = static_cast<std::uint32_t>(nodes.size());
            nodes.resize(nodes.size() + 2);
            set_node(t, t.bounds, pair, 0);
            left.node = pair;
            right.node = pair + 1;
            if (right.end - right.begin >= kTaskSize && left.end - left.begin >= kTaskSize) {
                // The right child's subtree goes into a chunk of its own, its root first.
                const NewChunk chunk = new_chunk(right.begin, right.end - right.begin);
                nodes[pair + 1] = BvhNode{{}, chunk.id, kSubtree};
                chunk.chunk->nodes.emplace_back();
                right.chunk = chunk.chunk;
                right.node = 0;
                tasks.run([this, right] { build(right); });
            } else {
                todo.push_back(right);
            }
            todo.push_back(left);
        }
    }
};

// Builds over n primitives whose boxes box_of(i, lo, hi) gives (w lanes 0).
template <class BoxOf>
Bvh build_over(std::size_t n, BoxOf box_of, const Bvh::Config& config,
               std::vector<float>* leaf_areas) {
    Bvh bvh;
    if (n == 0) return bvh;  // no nodes at all: a zero-count node would read as an inner node

    // Not value-initialised: every element is written before it is read (pages are touched
    // only when used).
    auto refs = accel::make_huge_array<PrimRef>(n);
    Box4 bounds, centres;
    {
        const std::size_t chunks = (n + kChunk - 1) / kChunk;
        std::vector<Box4> b(chunks), c(chunks);
        auto fill = [&](std::size_t chunk) {
            Box4 bb, cc;
            std::size_t e = std::min(n, (chunk + 1) * kChunk);
            for (std::size_t i = chunk * kChunk; i < e; ++i) {
                __m128 lo, hi;
                box_of(i, lo, hi);
                bb.extend(lo, hi);
                cc.extend_point(_mm_add_ps(lo, hi));
                refs[i].lo = _mm_castsi128_ps(
                    _mm_insert_epi32(_mm_castps_si128(lo), static_cast<int>(i), 3));
                refs[i].hi = hi;
            }
            b[chunk] = bb;
            c[chunk] = cc;
        };
        if (n >= kParallelSplit) {
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks, 1), [&](const auto& r) {
                for (std::size_t k = r.begin(); k != r.end(); ++k) fill(k);
            });
        } else {
            for (std::size_t k = 0; k < chunks; ++k) fill(k);
        }
        for (std::size_t k = 0; k < chunks; ++k) {
            bounds.extend(b[k]);
            centres.extend(c[k]);
        }
    }

    accel::reserve_huge(bvh.prim_indices, n);
    bvh.prim_indices.resize(n);
    if (leaf_areas) {
        accel::reserve_huge(*leaf_areas, n);
        leaf_areas->resize(n);
    }
    Builder builder(config, refs.get(), bvh.prim_indices.data(),
                    leaf_areas ? leaf_areas->data() : nullptr);
    NodeChunk* root = builder.new_chunk(0, n).chunk;
    root->nodes.emplace_back();
    builder.build(Task{root, 0, 0, n, bounds, centres});
    builder.tasks.wait();

    // Join the chunks: the root's first, then the others by their first primitive (a parent's
    // chunk comes before its children's, so children stay after their parents).
    std::vector<NodeChunk*> order;
    for (const auto& c : builder.chunks) order.push_back(c.get());
    std::sort(order.begin(), order.end(),
              [](const NodeChunk* a, const NodeChunk* b) { return a->first_prim < b->first_prim; });
    std::size_t total = order[0]->nodes.size();
    for (std::size_t c = 1; c < order.size(); ++c) {
        order[c]->offset = static_cast<std::uint32_t>(total);
        total += order[c]->nodes.size() - 1;  // its root goes into its parent's slot
    }
    accel::reserve_huge(bvh.nodes, total);
    bvh.nodes.resize(total);
    std::vector<std::uint32_t> root_at(builder.chunks.size(), 0);
    for (std::size_t c = 0; c < order.size(); ++c) {
        const NodeChunk& chunk = *order[c];
        // Local node k >= 1 goes to offset + k - 1 (the root chunk: to k).
        const std::uint32_t shift = c == 0 ? 0u : chunk.offset - 1;
        for (std::size_t k = 0; k < chunk.nodes.size(); ++k) {
            BvhNode node = chunk.nodes[k];
            const std::uint32_t at =
                k == 0 && c != 0 ? root_at[chunk.id] : static_cast<std::uint32_t>(k) + shift;
            if (node.count == kSubtree) {
                root_at[node.first] = at;  // filled from that chunk
                continue;
            }
            if (!node.is_leaf()) node.first += shift;
            bvh.nodes[at] = node;
        }
    }
    return bvh;
}

}  // namespace

Bvh Bvh::build(std::span<const BBox> boxes, const Config& config, std::vector<float>* leaf_areas) {
    return build_over(
        boxes.size(),
        [&](std::size_t i, __m128& lo, __m128& hi) {
            const BBox& box = boxes[i];
            lo = _mm_setr_ps(box.lo.x, box.lo.y, box.lo.z, 0.0f);
            hi = _mm_setr_ps(box.hi.x, box.hi.y, box.hi.z, 0.0f);
        },
        config, leaf_areas);
}

Bvh Bvh::build(std::span<const Vec3f> positions, std::span<const std::array<std::uint32_t, 3>> tris,
               const Config& config, std::vector<float>* leaf_areas) {
    return build_over(
        tris.size(),
        [&](std::size_t i, __m128& lo, __m128& hi) {
            // BBox::extend from an empty box, corner by corner: std::min(a, b) is
            // _mm_min_ps(b, a) (and max likewise), also for signed zeros and NaN.
            lo = kPosInf;
            hi = kNegInf;
            for (std::uint32_t v : tris[i]) {
                const Vec3f& p = positions[v];
                const __m128 c = _mm_setr_ps(p.x, p.y, p.z, 0.0f);
                lo = _mm_min_ps(c, lo);
                hi = _mm_max_ps(c, hi);
            }
        },
        config, leaf_areas);
}

void Bvh::refit(std::span<const BBox> boxes) {
    // Children always have larger indices than their parent, so a reverse sweep sees children first.
    for (std::size_t i = nodes.size(); i-- > 0;) {
        BvhNode& node = nodes[i];
        BBox box;
        if (node.is_leaf()) {
            for (std::uint32_t k = node.first; k < node.first + node.count; ++k)
                box.extend(boxes[prim_indices[k]]);
        } else {
            box = nodes[node.first].bounds;
            box.extend(nodes[node.first + 1].bounds);
        }
        node.bounds = box;
    }
}

int Bvh::depth() const {
    if (nodes.empty()) return 0;
    std::vector<std::pair<std::uint32_t, int>> stack{{0u, 1}};
    int deepest = 0;
    while (!stack.empty()) {
        auto [i, d] = stack.back();
        stack.pop_back();
        deepest = std::max(deepest, d);
        if (!nodes[i].is_leaf()) {
            stack.push_back({nodes[i].first, d + 1});
            stack.push_back({nodes[i].first + 1, d + 1});
        }
    }
    return deepest;
}

}  // namespace toonray
