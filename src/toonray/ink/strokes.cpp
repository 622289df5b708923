#include "toonray/ink/strokes.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <tuple>

#include "toonray/core/portable_math.h"
#include "toonray/ink/chunks.h"
#include "toonray/ink/hash.h"

namespace toonray::ink {

namespace {

float distance(const Point2& a, const Point2& b) { return portable::hypot(a.x - b.x, a.y - b.y); }

float distance_to_segment(const Point2& p, const Point2& a, const Point2& b) {
    const float dx = b.x - a.x, dy = b.y - a.y;
    const float len2 = dx * dx + dy * dy;
    float t = len2 > 0.0f ? ((p.x - a.x) * dx + (p.y - a.y) * dy) / len2 : 0.0f;
    t = std::clamp(t, 0.0f, 1.0f);
    return portable::hypot(p.x - (a.x + dx * t), p.y - (a.y + dy * t));
}

void douglas_peucker(std::span<const Point2> points, std::size_t first, std::size_t last,
                     float tolerance, std::vector<bool>& keep) {
    if (last <= first + 1) return;
    float worst = -1.0f;
    std::size_t at = first;
    for (std::size_t i = first + 1; i < last; ++i) {
        const float d = distance_to_segment(points[i], points[first], points[last]);
        if (d > worst) {
            worst = d;
            at = i;
        }
    }
    if (worst <= tolerance) return;
    keep[at] = true;
    douglas_peucker(points, first, at, tolerance, keep);
    douglas_peucker(points, at, last, tolerance, keep);
}

bool has_key(const EndpointKey& k) { return k.a != kNoIndex; }

// A piece as the chainer sees it: the pieces of a segment with one visibility, merged.
struct Link {
    EdgeType type;
    bool visible;
    Point2 s0, s1;
    EndpointKey key0, key1;
    std::uint16_t style;
    Vec3f w0, w1;  // the ends in the world
    std::uint32_t segment;
};

// Which points Douglas-Peucker keeps, into `keep` (resized to the points).
void simplified(std::span<const Point2> points, float tolerance, std::vector<bool>& keep) {
    if (points.size() <= 2 || !(tolerance > 0.0f)) {
        keep.assign(points.size(), true);
        return;
    }
    keep.assign(points.size(), false);
    keep.front() = keep.back() = true;
    douglas_peucker(points, 0, points.size() - 1, tolerance, keep);
}

// The link ends grouped by endpoint key: end 2 l + side of link l (side 0: key0, 1: key1) is in
// group end_group[2 l + side] (kNoIndex without a key), and a group lists its ends in order of
// (link, side), as a sort of all ends by (key, link, side) would.
struct EndGroups {
    std::vector<std::uint32_t> end_group, offsets, ends;

    [[nodiscard]] std::span<const std::uint32_t> group(std::uint32_t g) const {
        return {ends.data() + offsets[g], ends.data() + offsets[g + 1]};
    }
};

EndGroups group_ends(const std::vector<Link>& links) {
    EndGroups out;
    const std::size_t count = links.size() * 2;
    auto key_of = [&](std::size_t e) -> const EndpointKey& {
        return e % 2 ? links[e / 2].key1 : links[e / 2].key0;
    };
    out.end_group.assign(count, kNoIndex);
    std::vector<std::uint32_t> sizes;
    {
        // Keys to group numbers in an open-addressing table (linear probing, at most half
        // full). A group is known by its first end, whose key is the group's: a crowd's ink
        // lines have millions of groups, and an end's number is a quarter of its key's size.
        // The table goes before the lists are made.
        std::size_t table_size = 16;
        while (table_size < 2 * count) table_size *= 2;
        std::vector<std::uint32_t> table(table_size, kNoIndex);
        std::vector<std::uint32_t> first_end;
        auto home = [&](const EndpointKey& key) {
            return hash_words(key.a ^ ((key.instance + 1) * 0x9e3779b9u), key.b,
                              key.c ^ ((key.c_instance + 1) * 0x85ebca6bu)) &
                   (table_size - 1);
        };
        // Each end's slot is a cache miss on a crowd's table (tens of megabytes): the slots
        // of the ends kAhead further on are computed and fetched ahead.
        constexpr std::size_t kAhead = 16;
        std::size_t ahead[kAhead];
        for (std::size_t e = 0; e < std::min(kAhead, count); ++e) {
            ahead[e] = has_key(key_of(e)) ? home(key_of(e)) : 0;
            __builtin_prefetch(&table[ahead[e]]);
        }
        for (std::size_t e = 0; e < count; ++e) {
            std::size_t slot = ahead[e % kAhead];
            if (e + kAhead < count) {
                const EndpointKey& next = key_of(e + kAhead);
                const std::size_t next_slot = has_key(next) ? home(next) : 0;
                ahead[e % kAhead] = next_slot;
                __builtin_prefetch(&table[next_slot]);
            }
            const EndpointKey& key = key_of(e);
            if (!has_key(key)) continue;
            while (table[slot] != kNoIndex && key_of(first_end[table[slot]]) != key)
                slot = (slot + 1) & (table_size - 1);
            if (table[slot] == kNoIndex) {
                table[slot] = static_cast<std::uint32_t>(first_end.size());
                first_end.push_back(static_cast<std::uint32_t>(e));
                sizes.push_back(0);
            }
            out.end_group[e] = table[slot];
            ++sizes[table[slot]];
        }
    }
    out.offsets.assign(sizes.size() + 1, 0);
    for (std::size_t g = 0; g < sizes.size(); ++g) out.offsets[g + 1] = out.offsets[g] + sizes[g];
    std::vector<std::uint32_t>().swap(sizes);
    out.ends.resize(out.offsets.back());
    std::vector<std::uint32_t> fill(out.offsets.begin(), out.offsets.end() - 1);
    for (std::size_t e = 0; e < count; ++e)
        if (out.end_group[e] != kNoIndex)
            out.ends[fill[out.end_group[e]]++] = static_cast<std::uint32_t>(e);
    return out;
}

}  // namespace

float polyline_length(std::span<const Point2> points) {
    float total = 0.0f;
    for (std::size_t i = 1; i < points.size(); ++i) total += distance(points[i - 1], points[i]);
    return total;
}

std::vector<Point2> simplify_polyline(std::span<const Point2> points, float tolerance) {
    std::vector<bool> keep;
    simplified(points, tolerance, keep);
    std::vector<Point2> out;
    for (std::size_t i = 0; i < points.size(); ++i)
        if (keep[i]) out.push_back(points[i]);
    return out;
}

std::vector<Stroke> chain_pieces(std::span<const EdgePiece> pieces, const ChainSettings& settings,
                                 std::span<const SegmentStyles> segment_styles) {
    // 1. Per segment: absorb sub-pixel pieces into their neighbours, then merge runs of one
    //    visibility into links.
    std::vector<Link> links;
    links.reserve(pieces.size());
    std::vector<char> visible;
    for (std::size_t i = 0; i < pieces.size();) {
        std::size_t j = i + 1;
        while (j < pieces.size() && pieces[j].segment == pieces[i].segment) ++j;
        settle_sub_pixel_pieces(pieces.subspan(i, j - i), settings.min_piece, visible);
        const std::size_t n = j - i;
        for (std::size_t k = 0; k < n; ++k) {
            const EdgePiece& p = pieces[i + k];
            if (!visible[k] && !settings.hidden) continue;
            if (k > 0 && visible[k] == visible[k - 1] && pieces[i + k - 1].t1 == p.t0 &&
                !links.empty()) {
                links.back().s1 = p.s1;
                links.back().key1 = p.key1;
                links.back().w1 = p.p1;
                continue;
            }
            const std::uint16_t style = p.segment < segment_styles.size()
                                            ? segment_styles[p.segment][visible[k] ? 0 : 1]
                                            : 0;
            links.push_back({p.type, visible[k] != 0, p.s0, p.s1, p.key0, p.key1, style, p.p0, p.p1,
                             p.segment});
        }
        i = j;
    }

    // 2. Link ends by key.
    const EndGroups groups = group_ends(links);
    const float cos_max_turn =
        portable::cos(settings.max_turn * std::numbers::pi_v<float> / 180.0f);

    std::vector<char> used(links.size(), 0);
    std::vector<Stroke> strokes;
    // Buffers for one stroke at a time.
    std::vector<Point2> forward, backward, points, spaced;
    std::vector<Vec3f> forward_world, backward_world, world;
    std::vector<std::size_t> spaced_at;
    std::vector<bool> keep;
    for (std::size_t start = 0; start < links.size(); ++start) {
        if (used[start]) continue;
        used[start] = true;
        const Link& first = links[start];
        // Points from the start's s0 through its s1, grown at the back; then the front.
        forward.assign({first.s0, first.s1});
        forward_world.assign({first.w0, first.w1});
        backward.clear();
        backward_world.clear();
        bool closed = false;
        for (int direction = 0; direction < 2 && !closed; ++direction) {
            std::vector<Point2>& pts = direction == 0 ? forward : backward;
            std::vector<Vec3f>& wpts = direction == 0 ? forward_world : backward_world;
            EndpointKey key = direction == 0 ? first.key1 : first.key0;
            std::uint32_t group = groups.end_group[2 * start + (direction == 0 ? 1 : 0)];
            Point2 tip = direction == 0 ? first.s1 : first.s0;
            Point2 previous = direction == 0 ? first.s0 : first.s1;
            while (group != kNoIndex) {
                // Unused matching links at this key; a link touching it with both ends counts once.
                std::uint32_t best = kNoIndex;
                int candidates = 0;
                float best_cos = -2.0f;
                const float hx = tip.x - previous.x, hy = tip.y - previous.y;
                const float hlen = portable::hypot(hx, hy);
                std::uint32_t last_link = kNoIndex;
                for (const std::uint32_t e : groups.group(group)) {
                    const std::uint32_t link = e / 2;
                    const Link& l = links[link];
                    if (used[link] || l.type != first.type || l.visible != first.visible ||
                        l.style != first.style || link == last_link)
                        continue;
                    last_link = link;
                    ++candidates;
                    const Point2 next = e % 2 == 0 ? l.s1 : l.s0;
                    const float nx = next.x - tip.x, ny = next.y - tip.y;
                    const float nlen = portable::hypot(nx, ny);
                    const float c =
                        hlen > 0 && nlen > 0 ? (hx * nx + hy * ny) / (hlen * nlen) : 1.0f;
                    if (c > best_cos) {
                        best_cos = c;
                        best = e;
                    }
                }
                if (candidates == 0 && direction == 0 && key == first.key0) closed = true;
                if (best == kNoIndex || (candidates > 1 && best_cos < cos_max_turn)) break;
                const std::uint32_t link = best / 2;
                const bool at_start = best % 2 == 0;  // entered at s0: continue from s1
                used[link] = true;
                const Link& l = links[link];
                previous = tip;
                tip = at_start ? l.s1 : l.s0;
                key = at_start ? l.key1 : l.key0;
                group = groups.end_group[2 * link + (at_start ? 1 : 0)];
                pts.push_back(tip);
                wpts.push_back(at_start ? l.w1 : l.w0);
            }
        }
        points.assign(backward.rbegin(), backward.rend());
        points.insert(points.end(), forward.begin(), forward.end());
        world.assign(backward_world.rbegin(), backward_world.rend());
        world.insert(world.end(), forward_world.begin(), forward_world.end());
        if (closed) {
            points.back() = points.front();
            world.back() = world.front();
        }
        // Thin out points closer than min_spacing, keeping both ends.
        spaced_at.assign(1, 0);
        spaced.assign(1, points.front());
        for (std::size_t i = 1; i + 1 < points.size(); ++i)
            if (distance(points[i], spaced.back()) >= settings.min_spacing) {
                spaced.push_back(points[i]);
                spaced_at.push_back(i);
            }
        spaced.push_back(points.back());
        spaced_at.push_back(points.size() - 1);
        Stroke stroke;
        stroke.type = first.type;
        stroke.visible = first.visible;
        stroke.style = first.style;
        stroke.segment = first.segment;
        stroke.closed = closed;
        simplified(spaced, settings.simplify, keep);
        const auto kept = static_cast<std::size_t>(std::count(keep.begin(), keep.end(), true));
        stroke.points.reserve(kept);
        if (settings.eye) stroke.depth.reserve(kept);
        if (settings.world) stroke.world.reserve(kept);
        for (std::size_t i = 0; i < spaced.size(); ++i) {
            if (!keep[i]) continue;
            stroke.points.push_back(spaced[i]);
            if (settings.eye) stroke.depth.push_back(length(world[spaced_at[i]] - *settings.eye));
            if (settings.world) stroke.world.push_back(world[spaced_at[i]]);
        }
        if (stroke.visible && settings.min_length > 0.0f &&
            polyline_length(stroke.points) < settings.min_length)
            continue;
        strokes.push_back(std::move(stroke));
    }
    return strokes;
}

std::vector<Stroke> chain_pieces_in_parts(std::span<const EdgePiece> pieces,
                                          std::span<const std::size_t> cuts,
                                          const ChainSettings& settings,
                                          std::span<const SegmentStyles> segment_styles,
                                          int threads) {
    const std::size_t first = cuts.front(), last = cuts.back();
    if (first == last) return chain_pieces(pieces, settings, segment_styles);
    std::vector<EdgePiece> rest(pieces.begin(),
                                pieces.begin() + static_cast<std::ptrdiff_t>(first));
    rest.insert(rest.end(), pieces.begin() + static_cast<std::ptrdiff_t>(last), pieces.end());
    // Part 0 is the rest; part k the pieces [cuts[k - 1], cuts[k]).
    std::vector<std::vector<Stroke>> parts = chunk_outputs<Stroke>(
        static_cast<int>(cuts.size()), 1, threads, [&](int k0, int k1, std::vector<Stroke>& out) {
            for (int k = k0; k < k1; ++k) {
                const auto at = static_cast<std::size_t>(k);
                std::vector<Stroke> strokes =
                    chain_pieces(k == 0 ? std::span<const EdgePiece>(rest)
                                        : pieces.subspan(cuts[at - 1], cuts[at] - cuts[at - 1]),
                                 settings, segment_styles);
                out.insert(out.end(), std::make_move_iterator(strokes.begin()),
                           std::make_move_iterator(strokes.end()));
            }
        });
    // In the order of their first pieces: the rest's strokes that start before the parts, the
    // parts', then the rest's others (a stroke of the rest that starts before the parts may
    // take pieces after them, as it would chaining all at once).
    std::vector<Stroke>& before = parts.front();
    const std::uint32_t first_segment =
        first < pieces.size() ? pieces[first].segment : std::numeric_limits<std::uint32_t>::max();
    const auto split = std::partition_point(
        before.begin(), before.end(), [&](const Stroke& s) { return s.segment < first_segment; });
    std::vector<Stroke> after(std::make_move_iterator(split),
                              std::make_move_iterator(before.end()));
    before.erase(split, before.end());
    parts.push_back(std::move(after));
    std::vector<Stroke> out;
    append_parts(parts, out);
    return out;
}

}  // namespace toonray::ink
