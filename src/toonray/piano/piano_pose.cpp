#include "toonray/piano/piano_pose.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <utility>
#include <vector>

#include "toonray/core/portable_math.h"

namespace toonray {
namespace {

/// Rotation by `angle` about the unit `axis`, as a 3x3 matrix applied row by row.
struct Rotation {
    Vec3f r0, r1, r2;

    Rotation(const Vec3f& a, float angle) {
        const float c = portable::cos(angle), s = portable::sin(angle), t = 1.0f - c;
        r0 = {t * a.x * a.x + c, t * a.x * a.y - s * a.z, t * a.x * a.z + s * a.y};
        r1 = {t * a.x * a.y + s * a.z, t * a.y * a.y + c, t * a.y * a.z - s * a.x};
        r2 = {t * a.x * a.z - s * a.y, t * a.y * a.z + s * a.x, t * a.z * a.z + c};
    }
    [[nodiscard]] Vec3f operator()(const Vec3f& v) const {
        return {dot(r0, v), dot(r1, v), dot(r2, v)};
    }
};

/// Rewrites a rigid part's range from the rest pose, turned by `angle` about its pivot.
void pose_part(const RigidPart& part, float angle, const Scene& rest, Scene& out) {
    const Vec3f* src = rest.positions.data() + part.first_position;
    Vec3f* dst = out.positions.data() + part.first_position;
    if (angle == 0.0f) {
        std::copy(src, src + part.position_count, dst);
        std::copy(rest.normals.data() + part.first_normal,
                  rest.normals.data() + part.first_normal + part.normal_count,
                  out.normals.data() + part.first_normal);
        return;
    }
    const Rotation rot(part.axis, angle);
    for (std::uint32_t i = 0; i < part.position_count; ++i)
        dst[i] = part.pivot + rot(src[i] - part.pivot);
    const Vec3f* nsrc = rest.normals.data() + part.first_normal;
    Vec3f* ndst = out.normals.data() + part.first_normal;
    for (std::uint32_t i = 0; i < part.normal_count; ++i) ndst[i] = rot(nsrc[i]);
}

}  // namespace

PunchedRoll::PunchedRoll(const Score& score, const RollGeometry& geometry) : geometry_(geometry) {
    slots_.reserve(score.notes.size());
    const double v = geometry.paper_speed;
    for (const Note& note : score.notes) {
        if (note.key < kLowestKey || note.key > kHighestKey) {
            ++ignored_;
            continue;
        }
        RollSlot slot;
        slot.begin = static_cast<float>(note.start * v);
        slot.end =
            static_cast<float>(std::max(note.end * v, note.start * v + geometry.min_slot_length));
        slot.key = note.key;
        max_length_ = std::max(max_length_, slot.end - slot.begin);
        slots_.push_back(slot);
    }
    std::stable_sort(slots_.begin(), slots_.end(), [](const RollSlot& a, const RollSlot& b) {
        return a.begin < b.begin || (a.begin == b.begin && a.key < b.key);
    });

    // A slot is on the window's paper for roll positions r in the open interval
    // (begin - (top - tracker), end - (bottom - tracker)); the pool must hold the most that
    // overlap. Sweep the interval ends, closing before opening at equal positions.
    std::vector<std::pair<float, int>> events;
    events.reserve(2 * slots_.size());
    const float above = geometry.window_top - geometry.tracker_y;
    const float below = geometry.window_bottom - geometry.tracker_y;
    for (const RollSlot& s : slots_) {
        events.emplace_back(s.begin - above, +1);
        events.emplace_back(s.end - below, -1);
    }
    std::sort(events.begin(), events.end());
    long open = 0;
    for (const auto& e : events) {
        open += e.second;
        max_visible_ = std::max(max_visible_, static_cast<std::size_t>(std::max(open, 0L)));
    }
}

std::size_t PunchedRoll::first_candidate(float lo) const {
    // Every slot with end > lo has begin > lo - max_length_.
    const float from = lo - max_length_;
    auto it = std::lower_bound(slots_.begin(), slots_.end(), from,
                               [](const RollSlot& s, float x) { return s.begin < x; });
    return static_cast<std::size_t>(it - slots_.begin());
}

std::size_t PunchedRoll::visible_count(float r) const {
    std::size_t n = 0;
    for_each_visible(r, [&](const RollSlot&) { ++n; });
    return n;
}

PoseStats pose_piano(const PianoModel& model, const PianoPose& pose, const PunchedRoll* roll,
                     Scene& scene) {
    const Scene& rest = model.scene;
    if (&scene == &rest)
        throw Error(
            "pose_piano: the target scene must be a copy of the model's scene, not the model's "
            "own");
    if (scene.positions.size() != rest.positions.size() ||
        scene.normals.size() != rest.normals.size())
        throw Error(
            fmt::format("pose_piano: scene has {} positions and {} normals; the piano has {} "
                        "and {} (the scene must be a copy of PianoModel::scene)",
                        scene.positions.size(), scene.normals.size(), rest.positions.size(),
                        rest.normals.size()));

    for (std::size_t i = 0; i < model.keys.size(); ++i)
        pose_part(model.keys[i], pose.key_angle[i], rest, scene);
    for (std::size_t i = 0; i < 2; ++i)
        pose_part(model.pedals[i], pose.pedal_angle[i], rest, scene);
    const RollGeometry& g = model.roll_geometry;
    // Paper runs down the front of both spools: a positive turn about +x.
    const float turn = pose.roll_position / g.spool_radius;
    pose_part(model.spool_upper, std::fmod(turn, 6.28318530718f), rest, scene);
    pose_part(model.spool_lower, std::fmod(turn, 6.28318530718f), rest, scene);

    PoseStats stats;
    const HolePool& pool = model.holes;
    Vec3f* holes = scene.positions.data() + pool.first_position;
    if (roll) {
        const float r = pose.roll_position;
        const float z = g.paper_z + g.hole_lift;
        const float hw = 0.5f * g.hole_width;
        roll->for_each_visible(r, [&](const RollSlot& s) {
            if (stats.visible_holes == pool.capacity) {
                ++stats.dropped_holes;
                return;
            }
            // Paper coordinate p sits at world y = tracker_y + (p - r).
            const float y0 = std::max(g.window_bottom, g.tracker_y + (s.begin - r));
            // (Rounding can leave a slot that only grazes the window a hair inverted.)
            const float y1 = std::max(y0, std::min(g.window_top, g.tracker_y + (s.end - r)));
            const float x = g.hole_x(s.key);
            Vec3f* q = holes + 4 * stats.visible_holes;
            q[0] = {x - hw, y0, z};
            q[1] = {x + hw, y0, z};
            q[2] = {x + hw, y1, z};
            q[3] = {x - hw, y1, z};
            ++stats.visible_holes;
        });
    }
    std::fill(holes + 4 * stats.visible_holes, holes + 4 * pool.capacity, pool.park);
    return stats;
}

}  // namespace toonray
