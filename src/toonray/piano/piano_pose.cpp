#include "toonray/piano/piano_pose.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <memory>
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

namespace {

// A key's triangles as a mesh in its own frame (positions less its pivot).
std::shared_ptr<TriangleMesh> key_shape(const Scene& rest, const PianoKey& key) {
    auto mesh = std::make_shared<TriangleMesh>();
    std::vector<std::uint32_t> position(rest.positions.size(), kNoIndex),
        normal(rest.normals.size(), kNoIndex), texcoord(rest.texcoords.size(), kNoIndex);
    auto map = [](std::vector<std::uint32_t>& seen, std::uint32_t i, auto& out, const auto& value) {
        if (i == kNoIndex) return kNoIndex;
        if (seen[i] == kNoIndex) {
            seen[i] = static_cast<std::uint32_t>(out.size());
            out.push_back(value);
        }
        return seen[i];
    };
    for (std::size_t t = 0; t < rest.triangle_count(); ++t) {
        if (rest.tri_object[t] != key.object) continue;
        std::array<std::uint32_t, 3> p, n, uv;
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t pi = rest.tri_positions[t][k], ni = rest.tri_normals[t][k],
                                ti = rest.tri_texcoords[t][k];
            p[k] = map(position, pi, mesh->positions, rest.positions[pi] - key.pivot);
            n[k] = ni == kNoIndex ? kNoIndex : map(normal, ni, mesh->normals, rest.normals[ni]);
            uv[k] =
                ti == kNoIndex ? kNoIndex : map(texcoord, ti, mesh->texcoords, rest.texcoords[ti]);
        }
        mesh->add_triangle(p, rest.tri_material[t], 0, n, uv);
    }
    return mesh;
}

// Whether two key shapes are the same within a micrometre: keys of one kind differ only by
// where float arithmetic put their corners.
bool same_shape(const TriangleMesh& a, const TriangleMesh& b) {
    if (a.tri_positions != b.tri_positions || a.tri_normals != b.tri_normals ||
        a.tri_material != b.tri_material || a.positions.size() != b.positions.size() ||
        a.normals != b.normals)
        return false;
    for (std::size_t i = 0; i < a.positions.size(); ++i) {
        const Vec3f d = a.positions[i] - b.positions[i];
        if (std::abs(d.x) > 1e-6f || std::abs(d.y) > 1e-6f || std::abs(d.z) > 1e-6f) return false;
    }
    return true;
}

}  // namespace

Scene instance_keys(const PianoModel& model) {
    const Scene& rest = model.scene;
    Scene out = rest;
    // Without the keys' triangles.
    std::vector<std::uint8_t> is_key(rest.objects.size(), 0);
    for (const PianoKey& key : model.keys) is_key[key.object] = 1;
    out.clear_triangles();
    out.positions = rest.positions;
    out.normals = rest.normals;
    out.texcoords = rest.texcoords;
    out.colours = rest.colours;
    for (std::size_t t = 0; t < rest.triangle_count(); ++t)
        if (!is_key[rest.tri_object[t]])
            out.add_triangle(rest.tri_positions[t], rest.tri_material[t], rest.tri_object[t],
                             rest.tri_normals[t], rest.tri_texcoords[t]);
    std::vector<std::uint32_t> shape_of(model.keys.size());
    std::vector<std::shared_ptr<TriangleMesh>> shapes;
    for (std::size_t k = 0; k < model.keys.size(); ++k) {
        auto shape = key_shape(rest, model.keys[k]);
        std::size_t found = 0;
        while (found < shapes.size() && !same_shape(*shapes[found], *shape)) ++found;
        if (found == shapes.size()) shapes.push_back(shape);
        shape_of[k] = static_cast<std::uint32_t>(found);
    }
    for (auto& shape : shapes) out.add_mesh(shape);
    for (std::size_t k = 0; k < model.keys.size(); ++k)
        out.add_instance(shape_of[k], Affine3::translation(model.keys[k].pivot),
                         model.keys[k].object);
    return out;
}

void pose_key_instances(const PianoModel& model, const PianoPose& pose, Scene& scene) {
    if (scene.instances.size() != model.keys.size())
        throw Error(fmt::format("pose_key_instances: {} instances for {} keys",
                                scene.instances.size(), model.keys.size()));
    for (std::size_t k = 0; k < model.keys.size(); ++k) {
        const PianoKey& key = model.keys[k];
        Affine3 m = Affine3::translation(key.pivot);
        if (pose.key_angle[k] != 0.0f) {
            // pose_piano's rotation, in the same float entries.
            const Rotation rot(key.axis, pose.key_angle[k]);
            const Vec3f rows[3] = {rot.r0, rot.r1, rot.r2};
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) m.m[i][j] = rows[i][j];
        }
        scene.instances[k].to_world = m;
    }
}

}  // namespace toonray
