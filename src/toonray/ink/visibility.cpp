#include "toonray/ink/visibility.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "toonray/core/portable_math.h"
#include "toonray/ink/chunks.h"
#include "toonray/ink/instance_lines.h"

namespace toonray::ink {

namespace {

// ignored_triangle_keys into a buffer kept across segments.
void gather_ignored(const FeatureSegment& segment, const WeldedMesh& mesh,
                    const InstanceLineCache* instances, std::vector<TriangleKey>& out) {
    out.clear();
    for (int k = 0; k < 2; ++k)
        if (segment.faces[k] != kNoIndex)
            out.push_back(triangle_key(segment.face_instance[k], segment.faces[k]));
    if (segment.smooth && segment.faces[0] != kNoIndex) {
        const std::uint32_t instance = segment.face_instance[0];
        const WeldedMesh& ring =
            instance == kNoIndex ? mesh : instance_welded_mesh(*instances, instance);
        for (std::uint32_t v : ring.tri_vertices[segment.faces[0]])
            for (std::uint32_t i = ring.ring_offsets[v]; i < ring.ring_offsets[v + 1]; ++i)
                out.push_back(triangle_key(instance, ring.ring_triangles[i]));
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
}

// Surfaces between the point and the eye (count_occluders), with `ignored(hit)` telling the
// hits that do not count.
template <class Ignored>
int count_occluders_with(const TriangleAccel& accel, const Vec3f& point, const Vec3f& eye,
                         Ignored&& ignored, const VisibilitySettings& settings) {
    // The ray runs from the point (t = 0) to the eye (t = 1); after each hit it starts again
    // just past it, so every surface on the way is met once. Only the count reaching
    // max_invisibility ends the walk early: however many ignored surfaces come first, the
    // ones behind them are counted.
    const Vec3f dir = eye - point;
    const float t_end = 1.0f - settings.self_epsilon;
    const float skip = settings.self_epsilon * 0.01f;
    float t = settings.self_epsilon;
    int count = 0;
    while (t < t_end) {
        Hit hit;
        if (!accel.intersect(Ray{point + dir * t, dir, t_end - t}, hit)) break;
        if (!ignored(hit))
            if (++count >= settings.max_invisibility) break;
        // At least to the next float, so that the walk ends even with no skip.
        t = std::max(t + hit.t + skip, std::nextafter(t, t_end));
    }
    return count;
}

}  // namespace

std::vector<std::uint32_t> ignored_triangles(const FeatureSegment& segment,
                                             const WeldedMesh& mesh) {
    std::vector<TriangleKey> keys;
    gather_ignored(segment, mesh, nullptr, keys);
    std::vector<std::uint32_t> out;
    for (TriangleKey k : keys) out.push_back(static_cast<std::uint32_t>(k));
    return out;
}

std::vector<TriangleKey> ignored_triangle_keys(const FeatureSegment& segment,
                                               const WeldedMesh& mesh,
                                               const InstanceLineCache* instances) {
    std::vector<TriangleKey> out;
    gather_ignored(segment, mesh, instances, out);
    return out;
}

int count_occluders(const TriangleAccel& accel, const Vec3f& point, const Vec3f& eye,
                    std::span<const std::uint32_t> ignored, const VisibilitySettings& settings) {
    return count_occluders_with(
        accel, point, eye,
        [&](const Hit& hit) {
            return hit.instance == kNoIndex &&
                   std::binary_search(ignored.begin(), ignored.end(), hit.prim);
        },
        settings);
}

int count_occluders(const TriangleAccel& accel, const Vec3f& point, const Vec3f& eye,
                    std::span<const TriangleKey> ignored, const VisibilitySettings& settings) {
    return count_occluders_with(
        accel, point, eye,
        [&](const Hit& hit) {
            return std::binary_search(ignored.begin(), ignored.end(),
                                      triangle_key(hit.instance, hit.prim));
        },
        settings);
}

namespace {

// Samples traced together are laid out in rows of this many: a packet of 4 x 2 rays is then 8
// consecutive samples.
constexpr int kPacketWidth = 4;
// Segments with at most this many samples (one row) trace them one ray at a time: on piano
// frame 30 that takes 10% less time than a packet of 4 x 2 for them (AVX-512 kernels; with
// AVX2, 8 samples would still be faster one by one, but not on the teapot with AVX-512).
constexpr int kSingleRays = 4;

// A batch of segments: at most this many, and at most this many rays traced together from its
// short segments (as tiles of kPacketWidth x 16, which the accelerator cuts the rows into).
constexpr std::size_t kBatchSegments = 256;
constexpr std::size_t kBatchRays = 256;

// The part of one segment inside the view, as a line on the image: A + (B - A) s for s in
// [s_lo, s_hi], and the map from s back to the segment's parameter.
struct ClippedSegment {
    float ta = 0, tb = 1;  // the segment's parameters at A and B
    float za = 1, zb = 1;  // depths at A and B
    Point2 a, b;
    float s_lo = 0, s_hi = 1;

    [[nodiscard]] float t_of(float s) const {
        // Depth is linear along the segment and 1/depth along its image.
        const float u = s * za / ((1.0f - s) * zb + s * za);
        return ta + (tb - ta) * u;
    }
    [[nodiscard]] Point2 image(float s) const {
        return {a.x + (b.x - a.x) * s, a.y + (b.y - a.y) * s};
    }
};

// How one segment of a batch is sampled: its clipped image, and n samples at the middles of
// n equal steps of its span; the first of its rays traced with the batch, or -1.
struct SegmentPlan {
    ClippedSegment c;
    bool in_view = false;
    float image_length = 0, span = 0;
    int n = 0;
    int first_ray = -1;

    [[nodiscard]] float sample_s(int k) const {
        return c.s_lo + span * (static_cast<float>(k) + 0.5f) / static_cast<float>(n);
    }
};

bool clip_to_view(const FeatureSegment& seg, const ScreenProjection& view, float margin,
                  ClippedSegment& c) {
    const float z0 = view.depth(seg.p0), z1 = view.depth(seg.p1), near = view.near_depth();
    if (!(z0 >= near || z1 >= near)) return false;  // also rejects NaN
    if (z0 < near) c.ta = (near - z0) / (z1 - z0);
    if (z1 < near) c.tb = (near - z0) / (z1 - z0);
    auto at = [&](float t) { return seg.p0 + (seg.p1 - seg.p0) * t; };
    c.za = z0 + (z1 - z0) * c.ta;
    c.zb = z0 + (z1 - z0) * c.tb;
    c.a = view.project(at(c.ta));
    c.b = view.project(at(c.tb));
    // Liang-Barsky against the image grown by the margin.
    const float d[2] = {c.b.x - c.a.x, c.b.y - c.a.y};
    const float o[2] = {c.a.x, c.a.y};
    const float lo[2] = {-margin, -margin};
    const float hi[2] = {static_cast<float>(view.width()) + margin,
                         static_cast<float>(view.height()) + margin};
    for (int axis = 0; axis < 2; ++axis) {
        if (d[axis] == 0.0f) {
            if (o[axis] < lo[axis] || o[axis] > hi[axis]) return false;
            continue;
        }
        float s0 = (lo[axis] - o[axis]) / d[axis], s1 = (hi[axis] - o[axis]) / d[axis];
        if (s0 > s1) std::swap(s0, s1);
        c.s_lo = std::max(c.s_lo, s0);
        c.s_hi = std::min(c.s_hi, s1);
    }
    return c.s_lo < c.s_hi;
}

}  // namespace

void settle_sub_pixel_pieces(std::span<const EdgePiece> pieces, float min_piece,
                             std::vector<char>& visible) {
    const std::size_t n = pieces.size();
    visible.clear();
    for (const EdgePiece& p : pieces) visible.push_back(p.visible());
    if (n < 2) return;
    for (std::size_t k = 0; k < n; ++k) {
        const EdgePiece& p = pieces[k];
        if (portable::hypot(p.s0.x - p.s1.x, p.s0.y - p.s1.y) >= min_piece) continue;
        const bool before = k > 0 ? visible[k - 1] : visible[k + 1];
        const bool after = k + 1 < n ? visible[k + 1] : visible[k - 1];
        // Only when cut from both sides, and contiguous with them (not cut by clipping).
        const bool contiguous =
            (k == 0 || pieces[k - 1].t1 == p.t0) && (k + 1 == n || pieces[k + 1].t0 == p.t1);
        if (before == after && before != static_cast<bool>(visible[k]) && contiguous)
            visible[k] = before;
    }
}

std::vector<EdgePiece> split_by_visibility(std::span<const FeatureSegment> segments,
                                           const VisibilityContext& context,
                                           const VisibilitySettings& settings, int threads) {
    const ScreenProjection& view = context.view;
    // Through an instance level, the rays of short segments are traced together, a batch of
    // segments at a time, and share the top level's traversal (the crowd of 10,000 instances:
    // 0.93x to 0.94x the frame's CPU).
    // Without one they go one at a time: a tile of rays from different segments costs more
    // than it saves in one tree of triangles (1.08x on the piano).
    const bool batched = context.accel.instance_count() > 0;
    // Samples along lines are sparse for every instance's tree, which they cross ray by ray.
    const float ray_angle2 = std::numeric_limits<float>::infinity();
    // Appends the pieces of segments [i0, i1) to `out` (each segment's pieces apart from what
    // `out` held before).
    auto split = [&](int i0, int i1, std::vector<EdgePiece>& out) {
        out.reserve(out.size() + static_cast<std::size_t>(i1 - i0));
        std::vector<float> cuts;
        std::vector<char> settled;
        std::vector<int> states, sample_states;
        std::vector<Vec3f> dirs, points;
        std::vector<Hit> hits;
        std::vector<TriangleKey> ignored;
        std::unique_ptr<bool[]> found;
        std::size_t found_size = 0;
        // Per batch of segments: where each is seen, how many samples it takes, and the rays of
        // the short ones, traced together.
        std::vector<SegmentPlan> plans;
        std::vector<Vec3f> batch_dirs, batch_points;
        std::vector<Hit> batch_hits;
        std::unique_ptr<bool[]> batch_found(new bool[kBatchRays]);
        for (int b0 = i0; b0 < i1;) {
            int b1 = b0;
            plans.clear();
            batch_dirs.clear();
            batch_points.clear();
            // Segments up to a batch's count and rays (a short segment's samples never straddle
            // two batches).
            while (b1 < i1 && plans.size() < kBatchSegments &&
                   batch_dirs.size() + kSingleRays <= kBatchRays) {
                const FeatureSegment& seg = segments[static_cast<std::size_t>(b1++)];
                SegmentPlan& plan = plans.emplace_back();
                plan.in_view = clip_to_view(seg, view, settings.margin, plan.c);
                if (!plan.in_view || (seg.certainly_hidden && settings.max_invisibility <= 1))
                    continue;
                const ClippedSegment& c = plan.c;
                // Samples at the middles of n equal steps of at most `step` pixels; a change
                // between two samples is found by bisection.
                plan.image_length = portable::hypot(c.b.x - c.a.x, c.b.y - c.a.y);
                plan.span = c.s_hi - c.s_lo;
                // A piece whose image is not finite (coordinates beyond a float's range) is
                // sampled once, and no piece more than a million times.
                const float steps = plan.image_length * plan.span / settings.step;
                plan.n = std::isfinite(steps)
                             ? std::max(1, static_cast<int>(std::min(std::ceil(steps), 1.0e6f)))
                             : 1;
                if (!batched || settings.max_invisibility > 1 || plan.n > kSingleRays) continue;
                plan.first_ray = static_cast<int>(batch_dirs.size());
                for (int k = 0; k < plan.n; ++k) {
                    batch_points.push_back(seg.p0 + (seg.p1 - seg.p0) * c.t_of(plan.sample_s(k)));
                    batch_dirs.push_back(batch_points.back() - view.eye());
                }
            }
            if (!batch_dirs.empty()) {
                // Rows of kPacketWidth, the last ray repeated to the end of its row.
                const std::size_t traced = batch_dirs.size();
                const int rows = static_cast<int>((traced + kPacketWidth - 1) / kPacketWidth);
                batch_dirs.resize(static_cast<std::size_t>(rows) * kPacketWidth, batch_dirs.back());
                batch_hits.resize(batch_dirs.size());
                context.accel.intersect_tile(view.eye(), batch_dirs.data(), kPacketWidth, rows,
                                             batch_hits.data(), batch_found.get(),
                                             1.0f - settings.self_epsilon, ray_angle2);
            }
            for (int i = b0; i < b1; ++i) {
                const FeatureSegment& seg = segments[static_cast<std::size_t>(i)];
                const SegmentPlan& plan = plans[static_cast<std::size_t>(i - b0)];
                if (!plan.in_view) continue;
                const ClippedSegment& c = plan.c;
                if (seg.certainly_hidden && settings.max_invisibility <= 1) {
                    if (!settings.keep_hidden) continue;
                    // Hidden, and how deep does not matter: no rays.
                    EdgePiece piece;
                    piece.segment = static_cast<std::uint32_t>(i);
                    piece.type = seg.type;
                    piece.invisibility = 1;
                    piece.t0 = c.s_lo == 0.0f ? c.ta : c.t_of(c.s_lo);
                    piece.t1 = c.s_hi == 1.0f ? c.tb : c.t_of(c.s_hi);
                    if (!(piece.t0 < piece.t1)) continue;
                    piece.p0 = piece.t0 == 0.0f ? seg.p0 : seg.p0 + (seg.p1 - seg.p0) * piece.t0;
                    piece.p1 = piece.t1 == 1.0f ? seg.p1 : seg.p0 + (seg.p1 - seg.p0) * piece.t1;
                    piece.s0 = c.image(c.s_lo);
                    piece.s1 = c.image(c.s_hi);
                    if (piece.t0 == 0.0f) piece.key0 = seg.key0;
                    if (piece.t1 == 1.0f) piece.key1 = seg.key1;
                    out.push_back(piece);
                    continue;
                }
                // The triangles whose hits do not count, gathered when a hit needs them: a
                // sharp line's are its faces, which a hit is compared with directly.
                bool have_ignored = false;
                auto ignored_keys = [&]() -> std::span<const TriangleKey> {
                    if (!have_ignored)
                        gather_ignored(seg, context.mesh, context.instances, ignored);
                    have_ignored = true;
                    return ignored;
                };
                auto is_ignored = [&](const Hit& hit) {
                    const TriangleKey key = triangle_key(hit.instance, hit.prim);
                    if (seg.smooth) {
                        const auto keys = ignored_keys();
                        return std::binary_search(keys.begin(), keys.end(), key);
                    }
                    for (int k = 0; k < 2; ++k)
                        if (seg.faces[k] != kNoIndex &&
                            key == triangle_key(seg.face_instance[k], seg.faces[k]))
                            return true;
                    return false;
                };
                auto state_at = [&](float s) {
                    const float t = c.t_of(s);
                    return count_occluders(context.accel, seg.p0 + (seg.p1 - seg.p0) * t,
                                           view.eye(), ignored_keys(), settings);
                };
                const float image_length = plan.image_length;
                const int n = plan.n;
                sample_states.resize(static_cast<std::size_t>(n));
                if (settings.max_invisibility <= 1) {
                    // Only hidden or not: rays from the eye to each sample's point at parameter 1
                    // (a short segment's with its batch, a longer one's as a tile of its own). A
                    // first hit before 1 - self_epsilon on a triangle that counts means hidden,
                    // none means visible; a first hit on an ignored triangle or right at the eye is
                    // settled from the point as above.
                    auto state_of = [&](const Hit& hit, bool hit_found, const Vec3f& point) {
                        if (!hit_found) return 0;
                        if (hit.t >= settings.self_epsilon && !is_ignored(hit)) return 1;
                        return count_occluders(context.accel, point, view.eye(), ignored_keys(),
                                               settings);
                    };
                    if (plan.first_ray >= 0) {
                        // Traced with the batch.
                        for (int k = 0; k < n; ++k) {
                            const auto at = static_cast<std::size_t>(plan.first_ray + k);
                            sample_states[static_cast<std::size_t>(k)] =
                                state_of(batch_hits[at], batch_found[at], batch_points[at]);
                        }
                    } else {
                        const int rows = (n + kPacketWidth - 1) / kPacketWidth;
                        const std::size_t padded = static_cast<std::size_t>(rows) * kPacketWidth;
                        dirs.resize(padded);
                        points.resize(padded);
                        hits.resize(padded);
                        if (found_size < padded) {
                            found_size = std::max(padded, 2 * found_size);
                            found.reset(new bool[found_size]);
                        }
                        for (int k = 0; k < n; ++k) {
                            const std::size_t at = static_cast<std::size_t>(k);
                            points[at] = seg.p0 + (seg.p1 - seg.p0) * c.t_of(plan.sample_s(k));
                            dirs[at] = points[at] - view.eye();
                        }
                        // Without instances a packet (one group of the tile) does not pay for
                        // itself on a short segment: its rays one at a time, which find the same
                        // hits. Longer ones as a grid kPacketWidth rays wide.
                        if (n <= kSingleRays) {
                            for (std::size_t k = 0; k < static_cast<std::size_t>(n); ++k) {
                                hits[k] = Hit{};
                                found[k] = context.accel.intersect(
                                    Ray{view.eye(), dirs[k], 1.0f - settings.self_epsilon},
                                    hits[k]);
                            }
                        } else {
                            // The last sample repeats to the end of its row.
                            for (std::size_t k = static_cast<std::size_t>(n); k < padded; ++k) {
                                points[k] = points[k - 1];
                                dirs[k] = dirs[k - 1];
                            }
                            context.accel.intersect_tile(view.eye(), dirs.data(), kPacketWidth,
                                                         rows, hits.data(), found.get(),
                                                         1.0f - settings.self_epsilon);
                        }
                        for (int k = 0; k < n; ++k) {
                            const auto at = static_cast<std::size_t>(k);
                            sample_states[at] = state_of(hits[at], found[at], points[at]);
                        }
                    }
                } else {
                    for (int k = 0; k < n; ++k)
                        sample_states[static_cast<std::size_t>(k)] = state_at(plan.sample_s(k));
                }
                // Every sample hidden alike: one hidden piece, which only hidden lines keep (most
                // of a crowd's segments are one such sample).
                if (!settings.keep_hidden && sample_states[0] != 0 &&
                    std::all_of(sample_states.begin() + 1, sample_states.end(),
                                [&](int state) { return state == sample_states[0]; }))
                    continue;
                cuts.assign(1, c.s_lo);
                states.clear();
                int previous = 0;
                for (int k = 0; k < n; ++k) {
                    const int state = sample_states[static_cast<std::size_t>(k)];
                    if (k > 0 && state != previous) {
                        float lo = plan.sample_s(k - 1), hi = plan.sample_s(k);
                        while ((hi - lo) * image_length > settings.precision) {
                            const float mid = 0.5f * (lo + hi);
                            if (mid <= lo || mid >= hi) break;
                            (state_at(mid) == previous ? lo : hi) = mid;
                        }
                        cuts.push_back(0.5f * (lo + hi));
                        states.push_back(previous);
                    }
                    previous = state;
                }
                states.push_back(previous);
                cuts.push_back(c.s_hi);
                const std::size_t first = out.size();
                for (std::size_t k = 0; k < states.size(); ++k) {
                    EdgePiece piece;
                    piece.segment = static_cast<std::uint32_t>(i);
                    piece.type = seg.type;
                    piece.invisibility = states[k];
                    const float s0 = cuts[k], s1 = cuts[k + 1];
                    piece.t0 = c.t_of(s0);
                    piece.t1 = c.t_of(s1);
                    if (k == 0 && c.s_lo == 0.0f)
                        piece.t0 = c.ta;  // exactly, so that the key below holds
                    if (k + 1 == states.size() && c.s_hi == 1.0f) piece.t1 = c.tb;
                    if (!(piece.t0 < piece.t1)) continue;
                    piece.p0 = seg.p0 + (seg.p1 - seg.p0) * piece.t0;
                    piece.p1 = seg.p0 + (seg.p1 - seg.p0) * piece.t1;
                    piece.s0 = c.image(s0);
                    piece.s1 = c.image(s1);
                    if (piece.t0 == 0.0f) {
                        piece.p0 = seg.p0;
                        piece.key0 = seg.key0;
                    }
                    if (piece.t1 == 1.0f) {
                        piece.p1 = seg.p1;
                        piece.key1 = seg.key1;
                    }
                    out.push_back(piece);
                }
                if (!settings.keep_hidden) {
                    // The visibility chaining would give each piece; then only the visible ones.
                    // Tone strokes are drawn where they are seen, without chaining's rule: their
                    // hidden pieces are dropped before it (ink.cpp).
                    const auto mine = std::span(out).subspan(first);
                    if (seg.type == EdgeType::Tone) {
                        settled.clear();
                        for (const EdgePiece& p : mine) settled.push_back(p.visible());
                    } else {
                        settle_sub_pixel_pieces(mine, settings.min_piece, settled);
                    }
                    std::size_t kept = first;
                    for (std::size_t k = 0; k < mine.size(); ++k) {
                        if (!settled[k]) continue;
                        out[kept] = mine[k];
                        out[kept].invisibility = 0;
                        ++kept;
                    }
                    out.resize(kept);
                }
            }
            b0 = b1;
        }
    };
    const auto count = static_cast<int>(segments.size());
    // On one thread the pieces go straight into one list: a crowd's instances, split a chunk
    // at a time, are otherwise copied out of their parts once more.
    if (threads == 1) {
        std::vector<EdgePiece> out;
        split(0, count, out);
        return out;
    }
    return gather_chunks<EdgePiece>(count, 32, threads, split);
}

void drop_segments_without_pieces(std::vector<FeatureSegment>& segments,
                                  std::vector<EdgePiece>& pieces) {
    std::size_t kept = 0;
    for (std::size_t i = 0; i < pieces.size();) {
        const std::uint32_t segment = pieces[i].segment;
        segments[kept] = segments[segment];
        for (; i < pieces.size() && pieces[i].segment == segment; ++i)
            pieces[i].segment = static_cast<std::uint32_t>(kept);
        ++kept;
    }
    segments.resize(kept);
}

}  // namespace toonray::ink
