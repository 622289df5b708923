#include "toonray/piano/piano_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include "toonray/core/error.h"

namespace toonray {
namespace {

const PianoModel& piano() {
    static const PianoModel model = build_piano();
    return model;
}

/// Bounds of a rigid part's own vertices.
BBox part_bounds(const PianoModel& m, const RigidPart& p) {
    BBox b;
    for (std::uint32_t i = 0; i < p.position_count; ++i)
        b.extend(m.scene.positions[p.first_position + i]);
    return b;
}

/// Signed volume of an object's triangles (positive when they wind outward around a solid).
double signed_volume(const Scene& s, std::uint32_t object) {
    double v = 0.0;
    for (std::size_t t = 0; t < s.triangle_count(); ++t) {
        if (s.tri_object[t] != object) continue;
        const Vec3f& a = s.positions[s.tri_positions[t][0]];
        const Vec3f& b = s.positions[s.tri_positions[t][1]];
        const Vec3f& c = s.positions[s.tri_positions[t][2]];
        v += static_cast<double>(dot(a, cross(b, c))) / 6.0;
    }
    return v;
}

std::uint32_t object_index(const Scene& s, const std::string& name) {
    auto it = std::find(s.objects.begin(), s.objects.end(), name);
    return it == s.objects.end() ? kNoIndex : static_cast<std::uint32_t>(it - s.objects.begin());
}

TEST(PianoModel, TriangleCountIsInTheBudget) {
    const std::size_t n = piano().scene.triangle_count();
    EXPECT_GE(n, 30000u);
    EXPECT_LE(n, 60000u);
}

TEST(PianoModel, KeyNamesCountFromA0) {
    EXPECT_EQ(key_object_name(21), "w1");
    EXPECT_EQ(key_object_name(22), "b1");
    EXPECT_EQ(key_object_name(23), "w2");
    EXPECT_EQ(key_object_name(24), "w3");
    EXPECT_EQ(key_object_name(60), "w24");  // middle C
    EXPECT_EQ(key_object_name(61), "b17");  // A#0 and three octaves of five sharps below it
    EXPECT_EQ(key_object_name(106), "b36");
    EXPECT_EQ(key_object_name(108), "w52");
    EXPECT_THROW(key_object_name(20), Error);
    EXPECT_THROW(key_object_name(109), Error);
}

TEST(PianoModel, HasEightyEightNamedKeyObjects) {
    const PianoModel& m = piano();
    std::set<std::string> names;
    int white = 0, black = 0;
    for (int i = 0; i < kPianoKeys; ++i) {
        const PianoKey& key = m.keys[static_cast<std::size_t>(i)];
        EXPECT_EQ(key.midi, kLowestKey + i);
        EXPECT_EQ(key.black, is_black_key(key.midi));
        ASSERT_LT(key.object, m.scene.objects.size());
        EXPECT_EQ(m.scene.objects[key.object], key_object_name(key.midi));
        names.insert(m.scene.objects[key.object]);
        (key.black ? black : white)++;
    }
    EXPECT_EQ(white, 52);
    EXPECT_EQ(black, 36);
    EXPECT_EQ(names.size(), 88u);
    for (int i = 1; i <= 52; ++i) EXPECT_EQ(names.count("w" + std::to_string(i)), 1u) << i;
    for (int i = 1; i <= 36; ++i) EXPECT_EQ(names.count("b" + std::to_string(i)), 1u) << i;
    // Each name is used by exactly one object.
    for (const std::string& n : names)
        EXPECT_EQ(std::count(m.scene.objects.begin(), m.scene.objects.end(), n), 1) << n;
}

TEST(PianoModel, OverallSizeAndPlacement) {
    const PianoModel& m = piano();
    const Vec3f e = m.bounds.extent();
    EXPECT_NEAR(e.x, 1.55f, 0.155f);
    EXPECT_NEAR(e.y, 1.35f, 0.135f);
    EXPECT_NEAR(e.z, 0.68f, 0.068f);
    EXPECT_FLOAT_EQ(m.bounds.lo.y, 0.0f);                     // stands on the floor
    EXPECT_NEAR(m.bounds.lo.x + m.bounds.hi.x, 0.0f, 1e-4f);  // centred on x = 0
    EXPECT_NEAR(m.bounds.lo.z, -0.34f, 0.01f);                // back of the case
    // The whole scene includes a floor at y = 0, larger than the piano.
    const std::uint32_t floor = object_index(m.scene, "floor");
    ASSERT_NE(floor, kNoIndex);
    EXPECT_EQ(floor, m.floor_object);
    BBox fb;
    for (std::size_t t = 0; t < m.scene.triangle_count(); ++t)
        if (m.scene.tri_object[t] == floor)
            for (auto v : m.scene.tri_positions[t]) fb.extend(m.scene.positions[v]);
    EXPECT_FLOAT_EQ(fb.lo.y, 0.0f);
    EXPECT_FLOAT_EQ(fb.hi.y, 0.0f);
    EXPECT_LT(fb.lo.x, m.bounds.lo.x - 0.5f);
    EXPECT_GT(fb.hi.z, m.bounds.hi.z + 0.5f);
}

TEST(PianoModel, KeyboardProportions) {
    const PianoModel& m = piano();
    std::vector<BBox> whites, blacks;
    for (const PianoKey& k : m.keys) (k.black ? blacks : whites).push_back(part_bounds(m, k));
    ASSERT_EQ(whites.size(), 52u);
    // White pitch 23.5 mm: neighbouring white keys' fronts are that far apart.
    for (std::size_t i = 0; i + 1 < whites.size(); ++i) {
        const float pitch = whites[i + 1].center().x - whites[i].center().x;
        EXPECT_NEAR(pitch, 0.0235f, 0.0003f) << i;
    }
    const float keyboard = whites.back().hi.x - whites.front().lo.x;
    EXPECT_NEAR(keyboard, 1.222f, 0.01f);
    for (const BBox& w : whites) {
        EXPECT_NEAR(w.hi.y, 0.72f, 0.002f);  // key tops 0.72 m above the floor
        EXPECT_NEAR(w.hi.z, 0.34f, 0.002f);  // key fronts at z = +0.34
    }
    // Black keys: raised, shorter and narrower than the white keys.
    const float white_width = whites[10].extent().x, white_length = whites[10].extent().z;
    for (std::size_t i = 0; i < blacks.size(); ++i) {
        const BBox& b = blacks[i];
        EXPECT_GT(b.hi.y, 0.72f + 0.008f) << i;
        EXPECT_LT(b.extent().z, white_length - 0.03f) << i;
        EXPECT_LT(b.extent().x, 0.7f * white_width) << i;
        EXPECT_LT(b.hi.z, 0.34f - 0.04f) << i;  // their fronts well behind the white fronts
    }
    // A black key sits between its white neighbours.
    for (const PianoKey& k : m.keys) {
        if (!k.black) continue;
        const BBox b = part_bounds(m, k);
        const BBox lo = part_bounds(m, m.keys[static_cast<std::size_t>(k.midi - 1 - kLowestKey)]);
        const BBox hi = part_bounds(m, m.keys[static_cast<std::size_t>(k.midi + 1 - kLowestKey)]);
        EXPECT_GT(b.center().x, lo.center().x);
        EXPECT_LT(b.center().x, hi.center().x);
    }
}

TEST(PianoModel, KeysDoNotOverlap) {
    // Beside a black key, the white key's tail (every vertex level with or behind the black
    // key's front) stays clear of it, so every key is free to move.
    const PianoModel& m = piano();
    int checked = 0;
    for (int i = 0; i + 1 < kPianoKeys; ++i) {
        const PianoKey& a = m.keys[static_cast<std::size_t>(i)];
        const PianoKey& b = m.keys[static_cast<std::size_t>(i + 1)];
        if (a.black == b.black) continue;  // B-C and E-F: both white, checked by the pitch
        const PianoKey& black = a.black ? a : b;
        const PianoKey& white = a.black ? b : a;
        const BBox bb = part_bounds(m, black);
        for (std::uint32_t v = 0; v < white.position_count; ++v) {
            const Vec3f& p = m.scene.positions[white.first_position + v];
            if (p.z > bb.hi.z + 1e-5f) continue;  // the head, in front of the black key
            ++checked;
            EXPECT_TRUE(p.x <= bb.lo.x - 0.0005f || p.x >= bb.hi.x + 0.0005f)
                << key_object_name(white.midi) << " vs " << key_object_name(black.midi);
        }
    }
    EXPECT_GT(checked, 200);
}

TEST(PianoModel, MovablePartsOwnTheirVertexRanges) {
    const PianoModel& m = piano();
    const Scene& s = m.scene;
    std::vector<const RigidPart*> parts;
    for (const PianoKey& k : m.keys) parts.push_back(&k);
    for (const RigidPart& p : m.pedals) parts.push_back(&p);
    parts.push_back(&m.spool_upper);
    parts.push_back(&m.spool_lower);
    parts.push_back(&m.roll);
    // Owner object of each position/normal as used by triangles.
    std::vector<std::uint32_t> pos_owner(s.positions.size(), kNoIndex),
        nrm_owner(s.normals.size(), kNoIndex);
    for (std::size_t t = 0; t < s.triangle_count(); ++t)
        for (int c = 0; c < 3; ++c) {
            std::uint32_t o = s.tri_object[t];
            std::uint32_t& po = pos_owner[s.tri_positions[t][c]];
            EXPECT_TRUE(po == kNoIndex || po == o) << "position shared between objects";
            po = o;
            if (s.tri_normals[t][c] != kNoIndex) {
                std::uint32_t& no = nrm_owner[s.tri_normals[t][c]];
                EXPECT_TRUE(no == kNoIndex || no == o) << "normal shared between objects";
                no = o;
            }
        }
    for (const RigidPart* p : parts) {
        ASSERT_GT(p->position_count, 0u);
        EXPECT_LE(p->first_position + p->position_count, s.positions.size());
        EXPECT_LE(p->first_normal + p->normal_count, s.normals.size());
        for (std::uint32_t i = 0; i < p->position_count; ++i)
            EXPECT_TRUE(pos_owner[p->first_position + i] == p->object) << s.objects[p->object];
        for (std::uint32_t i = 0; i < p->normal_count; ++i)
            EXPECT_TRUE(nrm_owner[p->first_normal + i] == p->object) << s.objects[p->object];
        // And every vertex the object's triangles use is in the range.
        for (std::size_t t = 0; t < s.triangle_count(); ++t) {
            if (s.tri_object[t] != p->object) continue;
            for (int c = 0; c < 3; ++c) {
                std::uint32_t v = s.tri_positions[t][c];
                ASSERT_TRUE(v >= p->first_position && v < p->first_position + p->position_count);
                std::uint32_t n = s.tri_normals[t][c];
                ASSERT_TRUE(n == kNoIndex ||
                            (n >= p->first_normal && n < p->first_normal + p->normal_count));
            }
        }
        EXPECT_NEAR(length(p->axis), 1.0f, 1e-6f);
    }
}

TEST(PianoModel, KeysPivotAtTheirBackEnds) {
    const PianoModel& m = piano();
    for (const PianoKey& k : m.keys) {
        const BBox b = part_bounds(m, k);
        EXPECT_NEAR(k.pivot.z, b.lo.z, 1e-5f);  // back end
        EXPECT_NEAR(k.pivot.y, b.lo.y, 1e-5f);  // bottom edge
        EXPECT_NEAR(k.pivot.x, b.center().x, 0.003f);
        EXPECT_EQ(k.axis, Vec3f(1.0f, 0.0f, 0.0f));
        EXPECT_NEAR(k.length, k.front_top.z - k.pivot.z, 1e-6f);
    }
}

TEST(PianoModel, ClosedPartsWindOutward) {
    const PianoModel& m = piano();
    for (const PianoKey& k : m.keys) {
        const BBox b = part_bounds(m, k);
        const double box = static_cast<double>(b.extent().x) * b.extent().y * b.extent().z;
        const double v = signed_volume(m.scene, k.object);
        EXPECT_GT(v, 0.5 * box) << key_object_name(k.midi);
        EXPECT_LE(v, box * 1.0001) << key_object_name(k.midi);
    }
    for (const char* name : {"pedal_l", "pedal_r", "spool_upper", "spool_lower", "leg_l",
                             "sconce_r", "lid", "fallboard", "cheek_l", "toe_r", "tracker_bar"}) {
        std::uint32_t o = object_index(m.scene, name);
        ASSERT_NE(o, kNoIndex) << name;
        EXPECT_GT(signed_volume(m.scene, o), 0.0) << name;
    }
}

TEST(PianoModel, SmoothTrianglesAgreeWithTheirNormals) {
    const Scene& s = piano().scene;
    std::size_t smooth = 0;
    for (std::size_t t = 0; t < s.triangle_count(); ++t) {
        const auto& n = s.tri_normals[t];
        if (n[0] == kNoIndex) continue;
        ++smooth;
        const auto& v = s.tri_positions[t];
        Vec3f g =
            cross(s.positions[v[1]] - s.positions[v[0]], s.positions[v[2]] - s.positions[v[0]]);
        Vec3f sum = s.normals[n[0]] + s.normals[n[1]] + s.normals[n[2]];
        ASSERT_GT(dot(g, sum), 0.0f) << "triangle " << t << " in " << s.objects[s.tri_object[t]];
    }
    EXPECT_GT(smooth, 10000u);  // legs, spools, sconces, pedals are smooth
    for (const Vec3f& n : s.normals) EXPECT_NEAR(length(n), 1.0f, 1e-4f);
}

TEST(PianoModel, MaterialsAreNamedAndAssigned) {
    const PianoModel& m = piano();
    const Scene& s = m.scene;
    auto mat = [&](const std::string& name) {
        for (std::size_t i = 0; i < s.materials.size(); ++i)
            if (s.materials[i].name == name) return static_cast<std::uint32_t>(i);
        return kNoIndex;
    };
    for (const char* name :
         {"wood", "ivory", "ebony", "brass", "paper", "felt", "floor", "roll_hole"})
        ASSERT_NE(mat(name), kNoIndex) << name;
    for (std::size_t t = 0; t < s.triangle_count(); ++t) {
        const std::uint32_t o = s.tri_object[t];
        ASSERT_NE(o, 0u) << "triangle outside any named object";
        ASSERT_NE(s.tri_material[t], 0u) << "triangle on the default material";
    }
    for (const PianoKey& k : m.keys) {
        for (std::size_t t = 0; t < s.triangle_count(); ++t) {
            if (s.tri_object[t] == k.object) {
                ASSERT_EQ(s.tri_material[t], mat(k.black ? "ebony" : "ivory"));
            }
        }
    }
    EXPECT_EQ(m.holes.material, mat("roll_hole"));
}

TEST(PianoModel, HolePoolStartsParked) {
    PianoOptions options;
    options.hole_capacity = 40;
    const PianoModel m = build_piano(options);
    EXPECT_EQ(m.holes.capacity, 40u);
    for (std::uint32_t i = 0; i < 4 * m.holes.capacity; ++i)
        EXPECT_EQ(m.scene.positions[m.holes.first_position + i], m.holes.park);
    for (std::uint32_t t = 0; t < 2 * m.holes.capacity; ++t) {
        EXPECT_EQ(m.scene.tri_object[m.holes.first_triangle + t], m.holes.object);
        EXPECT_EQ(m.scene.tri_material[m.holes.first_triangle + t], m.holes.material);
    }
    EXPECT_EQ(m.scene.triangle_count(), piano().scene.triangle_count() - 2 * (256 - 40));
}

TEST(PianoModel, AnchorsAndCamera) {
    const PianoModel& m = piano();
    auto inside = [&](const Vec3f& p) {
        return p.x >= m.bounds.lo.x && p.x <= m.bounds.hi.x && p.y >= m.bounds.lo.y &&
               p.y <= m.bounds.hi.y && p.z >= m.bounds.lo.z && p.z <= m.bounds.hi.z;
    };
    EXPECT_TRUE(inside(m.keyboard_center));
    EXPECT_TRUE(inside(m.roll_window_center));
    EXPECT_TRUE(inside(m.pedal_center));
    EXPECT_NEAR(m.keyboard_center.y, 0.72f, 0.01f);
    EXPECT_GT(m.roll_window_center.y, m.keyboard_center.y);
    EXPECT_LT(m.pedal_center.y, 0.3f);
    EXPECT_NEAR(m.roll_window_center.x, 0.0f, 1e-6f);
    ASSERT_TRUE(m.scene.camera.has_value());
    EXPECT_GT(m.scene.camera->eye.z, m.bounds.hi.z);  // looks from the player's side
    const RollGeometry& g = m.roll_geometry;
    EXPECT_LT(g.window_bottom, g.tracker_y);
    EXPECT_LT(g.tracker_y, g.window_top);
    // The 88 hole columns fit across the paper.
    EXPECT_LT(g.hole_x(108) + g.hole_width, 0.5f * g.paper_width);
    EXPECT_GT(g.hole_x(21) - g.hole_width, -0.5f * g.paper_width);
}

TEST(PianoModel, LookAtBuildsAnOrthonormalCamera) {
    CameraSpec c = look_at({1.0f, 2.0f, 3.0f}, {0.0f, 0.5f, 0.0f}, 60.0f);
    Vec3f dir = c.gaze - c.eye;
    EXPECT_NEAR(length(dir), 1.0f / std::tan(30.0f * 3.14159265f / 180.0f), 1e-4f);
    EXPECT_NEAR(length(c.up), 1.0f, 1e-5f);
    EXPECT_NEAR(dot(c.up, dir), 0.0f, 1e-5f);
    EXPECT_GT(c.up.y, 0.0f);
}

}  // namespace
}  // namespace toonray
