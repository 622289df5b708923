#include "toonray/piano/piano_pose.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

#include "toonray/core/error.h"

namespace toonray {
namespace {

const PianoModel& piano() {
    static const PianoModel model = build_piano();
    return model;
}

bool same_bits(const Vec3f& a, const Vec3f& b) { return std::memcmp(&a, &b, sizeof(Vec3f)) == 0; }

void expect_same_topology(const Scene& a, const Scene& b) {
    EXPECT_EQ(a.positions.size(), b.positions.size());
    EXPECT_EQ(a.normals.size(), b.normals.size());
    EXPECT_EQ(a.tri_positions, b.tri_positions);
    EXPECT_EQ(a.tri_normals, b.tri_normals);
    EXPECT_EQ(a.tri_material, b.tri_material);
    EXPECT_EQ(a.tri_object, b.tri_object);
}

TEST(PianoPose, PressingOneKeyMovesOnlyItsFrontDown) {
    const PianoModel& m = piano();
    for (int index : {39, 40}) {  // middle C (white) and C#4 (black)
        Scene posed = m.scene;
        PianoPose pose;
        const float a = kKeyDipAngle;
        pose.key_angle[static_cast<std::size_t>(index)] = a;
        pose_piano(m, pose, nullptr, posed);
        const PianoKey& key = m.keys[static_cast<std::size_t>(index)];
        const std::uint32_t first = key.first_position, last = first + key.position_count;
        int front = 0;
        for (std::uint32_t i = 0; i < m.scene.positions.size(); ++i) {
            const Vec3f& rest = m.scene.positions[i];
            const Vec3f& now = posed.positions[i];
            if (i < first || i >= last) {
                ASSERT_TRUE(same_bits(rest, now))
                    << "vertex " << i << " of " << m.scene.objects.size();
                continue;
            }
            const float dz = rest.z - key.pivot.z, dy = rest.y - key.pivot.y;
            // Rotation about x through the pivot: front (dz > 0) goes down by about dz * sin(a).
            EXPECT_NEAR(now.y, key.pivot.y + dy * std::cos(a) - dz * std::sin(a), 1e-5f);
            EXPECT_NEAR(now.z, key.pivot.z + dy * std::sin(a) + dz * std::cos(a), 1e-5f);
            EXPECT_FLOAT_EQ(now.x, rest.x);
            if (dz > 0.9f * key.length) {
                ++front;
                EXPECT_LT(now.y, rest.y - 0.9f * key.length * std::sin(a));
            }
        }
        EXPECT_GE(front, 4);
        // A full press takes the front down about 8-10 mm, still above the keybed (y = 0.68).
        const float drop = key.length * std::sin(a);
        EXPECT_GT(drop, 0.007f);
        EXPECT_LT(drop, 0.0115f);
        float lowest = 1.0f;
        for (std::uint32_t i = first; i < last; ++i)
            lowest = std::min(lowest, posed.positions[i].y);
        EXPECT_GT(lowest, 0.68f);
        expect_same_topology(m.scene, posed);
    }
}

TEST(PianoPose, TopologyNeverChangesAndRestPoseRestores) {
    const PianoModel& m = piano();
    Score score;
    for (int i = 0; i < 50; ++i)
        score.notes.push_back({0.1 * i, 0.1 * i + 0.3, 21 + (i * 13) % 88, 80, 0});
    PunchedRoll roll(score, m.roll_geometry);
    Scene posed = m.scene;
    for (int f = 0; f < 5; ++f) {
        PianoPose pose;
        for (int k = 0; k < kPianoKeys; ++k)
            pose.key_angle[static_cast<std::size_t>(k)] = ((k + f) % 3 == 0) ? kKeyDipAngle : 0.0f;
        pose.pedal_angle = {0.05f * f, 0.2f - 0.05f * f};
        pose.roll_position = 0.07f * f;
        pose_piano(m, pose, &roll, posed);
        expect_same_topology(m.scene, posed);
    }
    // Back to rest: bit for bit the model's scene (holes parked as at rest).
    pose_piano(m, PianoPose{}, nullptr, posed);
    for (std::size_t i = 0; i < m.scene.positions.size(); ++i)
        ASSERT_TRUE(same_bits(m.scene.positions[i], posed.positions[i])) << i;
    for (std::size_t i = 0; i < m.scene.normals.size(); ++i)
        ASSERT_TRUE(same_bits(m.scene.normals[i], posed.normals[i])) << i;
}

TEST(PianoPose, PedalsTurnAboutTheirPivots) {
    const PianoModel& m = piano();
    Scene posed = m.scene;
    PianoPose pose;
    pose.pedal_angle[1] = kPedalStrokeAngle;
    pose_piano(m, pose, nullptr, posed);
    const RigidPart& right = m.pedals[1];
    float rest_front = -1.0f, rest_y = 0.0f, posed_y = 0.0f;
    for (std::uint32_t i = right.first_position; i < right.first_position + right.position_count;
         ++i) {
        const Vec3f& r = m.scene.positions[i];
        const Vec3f& p = posed.positions[i];
        // Distances to the pivot axis are kept.
        const Vec3f dr = r - right.pivot, dp = p - right.pivot;
        EXPECT_NEAR(dr.y * dr.y + dr.z * dr.z, dp.y * dp.y + dp.z * dp.z, 1e-6f);
        if (r.z > rest_front) {
            rest_front = r.z;
            rest_y = r.y;
            posed_y = p.y;
        }
    }
    EXPECT_LT(posed_y, rest_y - 0.03f);  // the toe goes down
    EXPECT_GT(posed_y, 0.0f);            // not through the floor
    for (std::uint32_t i = right.first_normal; i < right.first_normal + right.normal_count; ++i)
        EXPECT_NEAR(length(posed.normals[i]), 1.0f, 1e-5f);
    // The left pedal did not move.
    const RigidPart& left = m.pedals[0];
    for (std::uint32_t i = left.first_position; i < left.first_position + left.position_count; ++i)
        ASSERT_TRUE(same_bits(m.scene.positions[i], posed.positions[i]));
}

TEST(PianoPose, SpoolsTurnWithThePaper) {
    const PianoModel& m = piano();
    const RollGeometry& g = m.roll_geometry;
    Scene posed = m.scene;
    PianoPose pose;
    // A quarter turn of paper: a point at the front of the spool goes to the bottom.
    pose.roll_position = 0.5f * 3.14159265f * g.spool_radius;
    pose_piano(m, pose, nullptr, posed);
    const RigidPart& spool = m.spool_upper;
    int checked = 0;
    for (std::uint32_t i = spool.first_position; i < spool.first_position + spool.position_count;
         ++i) {
        const Vec3f d = m.scene.positions[i] - spool.pivot;
        if (std::abs(d.y) > 1e-4f || d.z < 0.02f) continue;  // points at the front
        const Vec3f p = posed.positions[i] - spool.pivot;
        EXPECT_NEAR(p.z, 0.0f, 1e-4f);
        EXPECT_NEAR(p.y, -d.z, 1e-4f);
        ++checked;
    }
    EXPECT_GT(checked, 10);
    // A full turn brings it back.
    pose.roll_position = 2.0f * 3.14159265f * g.spool_radius;
    pose_piano(m, pose, nullptr, posed);
    for (std::uint32_t i = spool.first_position; i < spool.first_position + spool.position_count;
         ++i)
        EXPECT_NEAR(length(posed.positions[i] - m.scene.positions[i]), 0.0f, 2e-5f);
}

TEST(PianoPose, RejectsASceneThatIsNotACopy) {
    const PianoModel& m = piano();
    Scene other;
    EXPECT_THROW(pose_piano(m, PianoPose{}, nullptr, other), Error);
    EXPECT_THROW(pose_piano(m, PianoPose{}, nullptr, const_cast<Scene&>(m.scene)), Error);
}

/// Hand-made score for the roll tests: a scale, a chord, a long note and an out-of-range note.
Score roll_score() {
    Score s;
    for (int i = 0; i < 12; ++i) s.notes.push_back({0.25 * i, 0.25 * i + 0.2, 48 + 2 * i, 80, 0});
    for (int k : {60, 64, 67, 72}) s.notes.push_back({1.0, 1.9, k, 80, 0});
    s.notes.push_back({0.5, 4.0, 36, 80, 0});
    s.notes.push_back({2.0, 2.0, 100, 80, 0});  // zero length: the minimum slot
    s.notes.push_back({1.5, 1.7, 15, 80, 0});   // below A0: no slot
    std::sort(s.notes.begin(), s.notes.end(),
              [](const Note& a, const Note& b) { return a.start < b.start; });
    return s;
}

/// Notes whose slot lies (partly) on the window's paper at time t, from the geometry alone:
/// the slot runs from y = tracker + v (start - t) up to y = tracker + v (end - t).
int expected_visible(const Score& s, const RollGeometry& g, double t) {
    int n = 0;
    for (const Note& note : s.notes) {
        if (note.key < 21 || note.key > 108) continue;
        const double v = g.paper_speed;
        const double y0 = g.tracker_y + v * (note.start - t);
        const double y1 = std::max(g.tracker_y + v * (note.end - t), y0 + g.min_slot_length);
        if (y1 > g.window_bottom + 1e-6 && y0 < g.window_top - 1e-6) ++n;
    }
    return n;
}

TEST(PianoRoll, VisibleHolesMatchTheNotesInTheWindow) {
    const Score score = roll_score();
    const PianoModel& m = piano();
    const RollGeometry& g = m.roll_geometry;
    const PunchedRoll roll(score, g);
    EXPECT_EQ(roll.ignored_notes(), 1);
    EXPECT_EQ(roll.slots().size(), score.notes.size() - 1);
    Scene posed = m.scene;
    const HolePool& pool = m.holes;
    int nonzero_frames = 0;
    for (double t = -2.0; t < 8.0; t += 1.0 / 24.0) {
        PianoPose pose;
        pose.roll_position = static_cast<float>(g.paper_speed * t);
        const PoseStats stats = pose_piano(m, pose, &roll, posed);
        const int expected = expected_visible(score, g, t);
        EXPECT_EQ(static_cast<int>(stats.visible_holes), expected) << "t = " << t;
        EXPECT_EQ(stats.dropped_holes, 0u);
        EXPECT_EQ(roll.visible_count(pose.roll_position), static_cast<std::size_t>(expected));
        // Placed holes: non-degenerate quads on the window's paper, just in front of it.
        int placed = 0;
        for (std::uint32_t h = 0; h < pool.capacity; ++h) {
            const Vec3f* q = &posed.positions[pool.first_position + 4 * h];
            const float area = length(cross(q[1] - q[0], q[2] - q[0]));
            if (area == 0.0f) {
                for (int c = 0; c < 4; ++c) EXPECT_EQ(q[c], pool.park);
                continue;
            }
            ++placed;
            EXPECT_GE(q[0].y, g.window_bottom);
            EXPECT_LE(q[2].y, g.window_top);
            EXPECT_GT(q[0].z, g.paper_z);
            EXPECT_LT(q[0].z, g.paper_z + 0.001f);
            EXPECT_NEAR(q[1].x - q[0].x, g.hole_width, 1e-6f);
            // Facing the viewer (+z), like the paper.
            EXPECT_GT(cross(q[1] - q[0], q[2] - q[0]).z, 0.0f);
        }
        EXPECT_EQ(placed, expected);
        if (expected > 0) ++nonzero_frames;
    }
    EXPECT_GT(nonzero_frames, 100);
}

TEST(PianoRoll, ASlotReachesTheTrackerBarAtItsOnset) {
    const PianoModel& m = piano();
    const RollGeometry& g = m.roll_geometry;
    Score score;
    score.notes.push_back({3.0, 3.5, 69, 80, 0});
    const PunchedRoll roll(score, g);
    Scene posed = m.scene;
    PianoPose pose;
    pose.roll_position = static_cast<float>(3.0 * g.paper_speed);
    ASSERT_EQ(pose_piano(m, pose, &roll, posed).visible_holes, 1u);
    const Vec3f* q = &posed.positions[m.holes.first_position];
    EXPECT_NEAR(q[0].y, g.tracker_y, 1e-5f);                     // leading edge at the bar
    EXPECT_NEAR(q[2].y - q[0].y, 0.5f * g.paper_speed, 1e-5f);   // length by duration
    EXPECT_NEAR(0.5f * (q[0].x + q[1].x), g.hole_x(69), 1e-6f);  // column by pitch
    EXPECT_LT(g.hole_x(60), g.hole_x(61));                       // bass to the left
    // Later, the slot has moved down the paper.
    pose.roll_position = static_cast<float>(3.5 * g.paper_speed);
    pose_piano(m, pose, &roll, posed);
    EXPECT_NEAR(q[0].y, std::max(g.window_bottom, g.tracker_y - 0.5f * g.paper_speed), 1e-5f);
}

TEST(PianoRoll, PoolSizeCoversTheBusiestWindow) {
    const Score score = roll_score();
    const RollGeometry g;
    const PunchedRoll roll(score, g);
    std::size_t brute = 0;
    for (double t = -3.0; t < 8.0; t += 0.001)
        brute = std::max(brute, roll.visible_count(static_cast<float>(g.paper_speed * t)));
    EXPECT_EQ(roll.max_visible(), brute);

    // A pool smaller than that drops the excess and says so.
    PianoOptions options;
    options.hole_capacity = 3;
    const PianoModel small = build_piano(options);
    Scene posed = small.scene;
    double busiest = 0.0;
    std::size_t most = 0;
    for (double t = 0.0; t < 5.0; t += 0.01) {
        std::size_t n = roll.visible_count(static_cast<float>(g.paper_speed * t));
        if (n > most) {
            most = n;
            busiest = t;
        }
    }
    ASSERT_GT(most, 3u);
    PianoPose pose;
    pose.roll_position = static_cast<float>(g.paper_speed * busiest);
    const PoseStats stats = pose_piano(small, pose, &roll, posed);
    EXPECT_EQ(stats.visible_holes, 3u);
    EXPECT_EQ(stats.dropped_holes, most - 3);
}

TEST(PianoRoll, EmptyScoreShowsBlankPaper) {
    const PianoModel& m = piano();
    const PunchedRoll roll(Score{}, m.roll_geometry);
    EXPECT_EQ(roll.max_visible(), 0u);
    Scene posed = m.scene;
    PianoPose pose;
    pose.roll_position = 1.0f;
    EXPECT_EQ(pose_piano(m, pose, &roll, posed).visible_holes, 0u);
}

}  // namespace
}  // namespace toonray
