#include "toonray/piano/piano_model.h"

#include <cmath>
#include <fmt/format.h>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/core/portable_math.h"
#include "toonray/piano/mesh_builder.h"

namespace toonray {
namespace {

constexpr float kPi = 3.14159265358979f;

// ---------------------------------------------------------------------------------------------
// Dimensions (metres). Real upright proportions; the case is 1.55 x 1.35 x 0.68 with the lid.

// Keyboard: 52 white keys at a 23.5 mm pitch (1.222 m), centred on x = 0.
constexpr float kWhitePitch = 0.0235f;
constexpr float kKeyboardLeft = -26.0f * kWhitePitch;
constexpr float kKeyGap = 0.0011f;  // between neighbouring keys
constexpr float kKeyTop = 0.72f;    // white key top above the floor
constexpr float kWhiteThickness = 0.022f;
constexpr float kKeyBottom = kKeyTop - kWhiteThickness;
constexpr float kKeyFront = 0.34f;
constexpr float kKeyBack = 0.10f;          // pivot line (hidden under the fallboard)
constexpr float kBlackFront = 0.29f;       // black keys stop 50 mm behind the white fronts
constexpr float kBlackTopFront = 0.2825f;  // their front face slopes back
constexpr float kBlackBaseWidth = 0.0130f;
constexpr float kBlackTopWidth = 0.0096f;
constexpr float kBlackShoulder = kKeyTop + 0.002f;  // vertical sides up to here, then taper
constexpr float kBlackTop = kKeyTop + 0.012f;       // 12 mm above the white keys

// Case.
constexpr float kSideOuter = 0.765f;  // outer face of the side panels (|x|)
constexpr float kSideInner = 0.730f;
constexpr float kCaseBack = -0.34f;
constexpr float kSideFront = 0.055f;
constexpr float kCaseTop = 1.315f;  // top board; the lid sits on it
constexpr float kLidTop = 1.35f;
constexpr float kLidHalfWidth = 0.778f;
constexpr float kLidFront = 0.085f;
constexpr float kPlinthTop = 0.065f;
constexpr float kKneeboardFront = 0.040f;
constexpr float kKneeboardTop = 0.62f;
constexpr float kKeybedBottom = 0.62f;
constexpr float kKeybedTop = 0.68f;
constexpr float kKeybedFront = 0.345f;
constexpr float kCheekInner = 0.6125f;      // the key blocks at both ends of the keyboard
constexpr float kUpperBoardFront = 0.055f;  // front board above the keys (spool box, panels)
constexpr float kUpperBoardBack = 0.025f;
constexpr float kUpperBoardBottom = 0.80f;
constexpr float kLegX = 0.69f;
constexpr float kLegZ = 0.275f;

// Spool box window (the opening in the front board).
constexpr float kWindowHalfWidth = 0.215f;
constexpr float kWindowBottom = 0.830f;
constexpr float kWindowTop = 1.040f;
constexpr float kSpoolBoxBack = -0.10f;

// Pedals: pivots at the bottom of the opening in the kneeboard; treads tilted toe-up at rest.
constexpr float kPedalX = 0.095f;
constexpr float kPedalPivotY = 0.100f;
constexpr float kPedalPivotZ = 0.030f;
constexpr float kPedalRestTilt = 0.34f;  // radians, toe up
constexpr float kPedalLength = 0.245f;
constexpr float kPedalHalfWidth = 0.052f;
constexpr float kPedalOpeningHalfWidth = 0.20f;
constexpr float kPedalOpeningTop = 0.19f;

struct Materials {
    std::uint32_t wood, ivory, ebony, brass, paper, felt, floor, hole;
};

Materials add_materials(MeshBuilder& b) {
    // Flat cel shading multiplies Kd by 0.5, 0.75 or 1.0: mid-value colours keep all three
    // bands distinct and readable under black lines.
    Materials m;
    m.wood = b.add_material("wood", {0.56f, 0.28f, 0.14f});
    m.ivory = b.add_material("ivory", {0.97f, 0.94f, 0.84f});
    m.ebony = b.add_material("ebony", {0.13f, 0.12f, 0.12f});
    m.brass = b.add_material("brass", {0.88f, 0.68f, 0.26f});
    m.paper = b.add_material("paper", {0.92f, 0.86f, 0.68f});
    m.felt = b.add_material("felt", {0.62f, 0.11f, 0.13f});
    m.floor = b.add_material("floor", {0.55f, 0.58f, 0.60f});
    m.hole = b.add_material("roll_hole", {0.07f, 0.05f, 0.04f});
    return m;
}

RigidPart begin_part(MeshBuilder& b, std::string name) {
    RigidPart p;
    p.object = b.begin_object(std::move(name));
    p.first_position = static_cast<std::uint32_t>(b.scene().positions.size());
    p.first_normal = static_cast<std::uint32_t>(b.scene().normals.size());
    return p;
}

void end_part(MeshBuilder& b, RigidPart& p) {
    p.position_count = static_cast<std::uint32_t>(b.scene().positions.size()) - p.first_position;
    p.normal_count = static_cast<std::uint32_t>(b.scene().normals.size()) - p.first_normal;
}

// ---------------------------------------------------------------------------------------------
// Profiles.

/// Bolection moulding (fillet, cove, bead, step) framing a panel or an opening; u is the
/// offset outward from the framed edge, v the height off the board. `s` scales it.
std::vector<ProfilePoint> bolection_profile(float s) {
    std::vector<ProfilePoint> p;
    p.push_back({0.022f * s, 0.0f});
    append_arc(p, 0.022f * s, 0.0095f * s, 0.007f * s, 1.5f * kPi, kPi, 5);  // cove
    p.pop_back();  // the bead starts where the cove ends
    append_arc(p, 0.0105f * s, 0.0095f * s, 0.0045f * s, 0.0f, kPi, 8);  // bead
    p.push_back({0.0035f * s, 0.0095f * s});
    p.push_back({0.0035f * s, 0.006f * s});
    p.push_back({0.0f, 0.006f * s});
    p.push_back({0.0f, 0.0f});
    return p;
}

/// Raised (fielded) panel border: a short upstand at the frame, then a bevel rising inward to
/// the flat field.
std::vector<ProfilePoint> field_profile(float bevel_width, float height) {
    return {{0.0f, 0.0f}, {0.0f, 0.0012f}, {-bevel_width, height}};
}

/// Frame moulding and raised field on a board. `f` is the board surface at the panel centre
/// with +z out of the board; the panel spans [-hw, hw] x [-hh, hh] in the frame's x and y.
void raised_panel(MeshBuilder& b, const Frame& f, float hw, float hh, const Materials& m) {
    b.set_frame(f);
    b.set_material(m.wood);
    const Vec3f up(0.0f, 0.0f, 1.0f);
    std::vector<Vec3f> rect = {{-hw, -hh, 0.0f}, {hw, -hh, 0.0f}, {hw, hh, 0.0f}, {-hw, hh, 0.0f}};
    auto moulding = bolection_profile(0.8f);
    b.sweep(rect, true, up, moulding);
    const float bevel = std::min(0.028f, 0.3f * std::min(hw, hh));
    const float height = 0.006f;
    b.sweep(rect, true, up, field_profile(bevel, height));
    float fw = hw - bevel, fh = hh - bevel;
    std::uint32_t a = b.vertex({-fw, -fh, height}), c1 = b.vertex({fw, -fh, height}),
                  c2 = b.vertex({fw, fh, height}), d = b.vertex({-fw, fh, height});
    b.polygon({a, c1, c2, d}, f.direction(up));
    b.set_frame(Frame{});
}

std::vector<ProfilePoint> leg_profile() {
    // Turned column from the bottom block (y = 0.12) to the top block (y = 0.55): base bead,
    // a vase swelling low, a ring, a slender shaft, a cove and a capital bead.
    std::vector<ProfilePoint> p;
    append_arc(p, 0.026f, 0.130f, 0.010f, -0.5f * kPi, 0.5f * kPi, 10);
    p.push_back({0.021f, 0.143f});
    const int vase_steps = 28;
    for (int i = 0; i <= vase_steps; ++i) {
        float s = static_cast<float>(i) / vase_steps;
        float bump =
            portable::pow(std::max(0.0f, portable::sin(kPi * portable::pow(s, 0.62f))), 1.4f);
        float r = 0.0175f + 0.002f * (1.0f - s) + 0.0215f * bump;
        p.push_back({r, 0.150f + 0.250f * s, i > 0 && i < vase_steps});
    }
    append_arc(p, 0.0175f, 0.4135f, 0.0085f, -0.5f * kPi, 0.5f * kPi, 8);
    p.push_back({0.0160f, 0.4260f});
    for (int i = 0; i <= 6; ++i) {
        float s = static_cast<float>(i) / 6.0f;
        p.push_back({0.016f + 0.005f * s * s, 0.430f + 0.075f * s, i > 0 && i < 6});
    }
    append_arc(p, 0.030f, 0.505f, 0.009f, kPi, 0.5f * kPi, 5);
    p.pop_back();
    append_arc(p, 0.030f, 0.523f, 0.009f, -0.5f * kPi, 0.5f * kPi, 10);
    p.push_back({0.027f, 0.535f});
    p.push_back({0.027f, 0.550f});
    return p;
}

/// Cylinder (or tube end to end) along the lathe axis from v0 to v1 with radius r.
std::vector<ProfilePoint> cylinder_profile(float r, float v0, float v1) {
    return {{0.0f, v0}, {r, v0}, {r, v1}, {0.0f, v1}};
}

// ---------------------------------------------------------------------------------------------
// Parts.

float white_left(int white_index) {
    return kKeyboardLeft + kWhitePitch * static_cast<float>(white_index);
}

/// Centre of a black key: off the boundary between its white neighbours as on real keyboards
/// (the C#-D# pair and the F#-G#-A# trio share their groups' width evenly).
float black_center(int midi, int white_index_of_next) {
    int pc = midi % 12;
    float offset = pc == 1   ? -0.100f
                   : pc == 3 ? 0.100f
                   : pc == 6 ? -0.143f
                   : pc == 8 ? 0.0f
                             : 0.143f;
    return white_left(white_index_of_next) + offset * kWhitePitch;
}

void build_keys(MeshBuilder& b, PianoModel& model, const Materials& m) {
    // White-key index of each MIDI note (the black keys sit at the next white key's edge).
    std::array<int, 128> white_index{};
    int w = 0;
    for (int midi = kLowestKey; midi <= kHighestKey; ++midi) {
        white_index[static_cast<std::size_t>(midi)] = w;
        if (!is_black_key(midi)) ++w;
    }
    auto black_edges = [&](int midi, float& l, float& r) {
        float c = black_center(midi, white_index[static_cast<std::size_t>(midi)]);
        l = c - 0.5f * kBlackBaseWidth;
        r = c + 0.5f * kBlackBaseWidth;
    };
    for (int midi = kLowestKey; midi <= kHighestKey; ++midi) {
        PianoKey& key = model.keys[static_cast<std::size_t>(midi - kLowestKey)];
        RigidPart part = begin_part(b, key_object_name(midi));
        key.midi = midi;
        key.black = is_black_key(midi);
        if (!key.black) {
            b.set_material(m.ivory);
            int wi = white_index[static_cast<std::size_t>(midi)];
            float xl = white_left(wi) + 0.5f * kKeyGap, xr = white_left(wi + 1) - 0.5f * kKeyGap;
            float tl = xl, tr = xr;  // the tail narrows where black keys sit beside it
            float bl, br;
            if (midi > kLowestKey && is_black_key(midi - 1)) {
                black_edges(midi - 1, bl, br);
                tl = br + kKeyGap;
            }
            if (midi < kHighestKey && is_black_key(midi + 1)) {
                black_edges(midi + 1, bl, br);
                tr = bl - kKeyGap;
            }
            const float zn = kBlackFront + kKeyGap;  // where the full-width head begins
            std::vector<ProfilePoint> outline;
            outline.push_back({tl, kKeyBack});
            outline.push_back({tr, kKeyBack});
            if (tr < xr) {
                outline.push_back({tr, zn});
                outline.push_back({xr, zn});
            }
            outline.push_back({xr, kKeyFront});
            outline.push_back({xl, kKeyFront});
            if (tl > xl) {
                outline.push_back({xl, zn});
                outline.push_back({tl, zn});
            }
            b.extrude(outline, {1.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 1.0f}, {0.0f, 1.0f, 0.0f},
                      kKeyBottom, kKeyTop);
            key.width = xr - xl;
            key.front_top = {0.5f * (xl + xr), kKeyTop, kKeyFront};
            part.pivot = {0.5f * (xl + xr), kKeyBottom, kKeyBack};
        } else {
            b.set_material(m.ebony);
            float xl, xr;
            black_edges(midi, xl, xr);
            float c = 0.5f * (xl + xr), t = 0.5f * kBlackTopWidth;
            const Vec3f pts[12] = {
                {xl, kKeyBottom, kKeyBack},         {xr, kKeyBottom, kKeyBack},
                {xr, kKeyBottom, kBlackFront},      {xl, kKeyBottom, kBlackFront},
                {xl, kBlackShoulder, kKeyBack},     {xr, kBlackShoulder, kKeyBack},
                {xr, kBlackShoulder, kBlackFront},  {xl, kBlackShoulder, kBlackFront},
                {c - t, kBlackTop, kKeyBack},       {c + t, kBlackTop, kKeyBack},
                {c + t, kBlackTop, kBlackTopFront}, {c - t, kBlackTop, kBlackTopFront}};
            b.convex_solid(pts, {{0, 1, 2, 3},
                                 {8, 9, 10, 11},
                                 {0, 1, 5, 4},
                                 {1, 2, 6, 5},
                                 {2, 3, 7, 6},
                                 {3, 0, 4, 7},
                                 {4, 5, 9, 8},
                                 {5, 6, 10, 9},
                                 {6, 7, 11, 10},
                                 {7, 4, 8, 11}});
            key.width = xr - xl;
            key.front_top = {c, kBlackTop, kBlackTopFront};
            part.pivot = {c, kKeyBottom, kKeyBack};
        }
        part.axis = {1.0f, 0.0f, 0.0f};
        end_part(b, part);
        static_cast<RigidPart&>(key) = part;
        key.length = key.front_top.z - part.pivot.z;
    }
}

/// A U-shaped path at height y along the left side, the front and the right side of the case,
/// counter-clockwise seen from above (so a sweep's outside is away from the case).
std::vector<Vec3f> u_path(float y, float half_width, float front) {
    return {{-half_width, y, kCaseBack},
            {-half_width, y, front},
            {half_width, y, front},
            {half_width, y, kCaseBack}};
}

void build_case(MeshBuilder& b, const Materials& m) {
    b.begin_object("case");
    b.set_material(m.wood);
    // Side panels, full height, their edges chamfered; two raised panels on each outer face.
    for (float s : {-1.0f, 1.0f}) {
        Vec3f lo(s < 0 ? -kSideOuter : kSideInner, 0.0f, kCaseBack);
        Vec3f hi(s < 0 ? -kSideInner : kSideOuter, kCaseTop, kSideFront);
        b.chamfer_box(lo, hi, 0.004f);
        Frame f;
        f.ez = {s, 0.0f, 0.0f};
        f.ey = {0.0f, 1.0f, 0.0f};
        f.ex = cross(f.ey, f.ez);
        const float zc = -0.145f;
        f.origin = {s * kSideOuter, 0.345f, zc};
        raised_panel(b, f, 0.135f, 0.215f, m);
        f.origin = {s * kSideOuter, 0.985f, zc};
        raised_panel(b, f, 0.135f, 0.225f, m);
    }
    // Back, top board and the plinth the case stands on.
    b.box({-kSideInner, kPlinthTop, kCaseBack}, {kSideInner, kCaseTop, kCaseBack + 0.025f});
    b.box({-kSideInner, kCaseTop - 0.025f, kCaseBack}, {kSideInner, kCaseTop, kUpperBoardFront});
    b.chamfer_box({-0.772f, 0.0f, kCaseBack}, {0.772f, kPlinthTop, 0.062f}, 0.003f);

    // Cornice under the lid: a bead under an ovolo, along the front and both sides.
    {
        std::vector<ProfilePoint> cornice;
        append_arc(cornice, 0.0f, 0.006f, 0.006f, -0.5f * kPi, 0.5f * kPi, 7);
        append_arc(cornice, 0.0f, 0.030f, 0.012f, -0.5f * kPi, 0.0f, 8);
        cornice.push_back({0.0f, 0.030f});
        b.sweep(u_path(kCaseTop - 0.031f, kSideOuter, kUpperBoardFront), false, {0.0f, 1.0f, 0.0f},
                cornice);
    }
    // Quarter-round cap on the plinth.
    {
        std::vector<ProfilePoint> cap = {{0.0f, 0.0f}};
        append_arc(cap, 0.002f, 0.0f, 0.005f, 0.0f, 0.5f * kPi, 6);
        cap.push_back({0.0f, 0.005f});
        b.sweep(u_path(kPlinthTop, 0.772f, 0.062f), false, {0.0f, 1.0f, 0.0f}, cap);
    }

    // Lid with chamfered edges and two brass hinge knuckles at the back.
    b.begin_object("lid");
    b.set_material(m.wood);
    b.chamfer_box({-kLidHalfWidth, kCaseTop, kCaseBack}, {kLidHalfWidth, kLidTop, kLidFront},
                  0.008f);
    b.set_material(m.brass);
    for (float x : {-0.45f, 0.45f}) {
        b.set_frame(Frame::along({x, kCaseTop + 0.004f, kCaseBack + 0.005f}, {1.0f, 0.0f, 0.0f}));
        b.lathe(cylinder_profile(0.005f, -0.04f, 0.04f), 16);
    }
    b.set_frame(Frame{});
}

void build_lower_front(MeshBuilder& b, const Materials& m) {
    b.begin_object("kneeboard");
    b.set_material(m.wood);
    const float z0 = kKneeboardFront - 0.03f, z1 = kKneeboardFront;
    const float ow = kPedalOpeningHalfWidth, ot = kPedalOpeningTop;
    // The board around the pedal opening.
    b.box({-kSideInner, kPlinthTop, z0}, {-ow, kKneeboardTop, z1});
    b.box({ow, kPlinthTop, z0}, {kSideInner, kKneeboardTop, z1});
    b.box({-ow, ot, z0}, {ow, kKneeboardTop, z1});
    // The opening's recess: felt-lined back, wooden walls.
    b.set_material(m.felt);
    b.box({-ow, kPlinthTop, -0.09f}, {ow, ot, -0.08f});
    b.set_material(m.wood);
    b.box({-ow - 0.01f, kPlinthTop, -0.09f}, {-ow, ot, z0});
    b.box({ow, kPlinthTop, -0.09f}, {ow + 0.01f, ot, z0});
    b.box({-ow, ot, -0.09f}, {ow, ot + 0.01f, z0});
    // A half-round bead around the opening (symmetric, so the path's direction is free).
    {
        std::vector<ProfilePoint> bead;
        append_arc(bead, 0.0f, 0.0f, 0.006f, 0.0f, kPi, 8);
        const float e = 0.006f;
        std::vector<Vec3f> path = {{-ow - e, kPlinthTop, z1},
                                   {-ow - e, ot + e, z1},
                                   {ow + e, ot + e, z1},
                                   {ow + e, kPlinthTop, z1}};
        b.sweep(path, false, {0.0f, 0.0f, 1.0f}, bead);
    }
    // Three raised panels above the opening.
    for (float xc : {-0.47f, 0.0f, 0.47f}) {
        Frame f;
        f.origin = {xc, 0.405f, z1};
        raised_panel(b, f, xc == 0.0f ? 0.19f : 0.21f, 0.150f, m);
    }

    // Keybed (the shelf the keyboard rests on) with a half-round bead along its front.
    b.begin_object("keybed");
    b.set_material(m.wood);
    b.chamfer_box({-kSideOuter, kKeybedBottom, 0.0f}, {kSideOuter, kKeybedTop, kKeybedFront},
                  0.004f);
    {
        std::vector<ProfilePoint> bead;
        append_arc(bead, 0.0f, 0.0f, 0.0065f, 0.0f, kPi, 8);
        std::vector<Vec3f> path = {{-kSideOuter, kKeybedBottom + 0.016f, kKeybedFront},
                                   {kSideOuter, kKeybedBottom + 0.016f, kKeybedFront}};
        b.sweep(path, false, {0.0f, 0.0f, 1.0f}, bead);
    }

    // Key slip in front of the keys, with a player piano's two control levers (tempo and
    // play/re-roll) in slots: brass blades with ebony knobs.
    b.begin_object("key_slip");
    b.set_material(m.wood);
    const float slip_front = 0.360f;
    b.chamfer_box({-kCheekInner, 0.652f, kKeyFront + 0.002f},
                  {kCheekInner, kKeyBottom + 0.008f, slip_front}, 0.003f);
    for (float x : {-0.24f, 0.24f}) {
        b.set_material(m.ebony);
        b.box({x - 0.045f, 0.662f, slip_front - 0.001f},
              {x + 0.045f, 0.667f, slip_front + 0.0005f});
        b.set_material(m.brass);
        b.chamfer_box({x + 0.012f, 0.6625f, slip_front - 0.004f},
                      {x + 0.018f, 0.6665f, slip_front + 0.006f}, 0.001f);
        b.set_material(m.ebony);
        std::vector<ProfilePoint> knob;
        append_arc(knob, 0.0f, 0.0f, 0.0055f, -0.5f * kPi, 0.5f * kPi, 10, true);
        b.set_frame(Frame::along({x + 0.015f, 0.6645f, slip_front + 0.0095f}, {0.0f, 0.0f, 1.0f}));
        b.lathe(knob, 20);
        b.set_frame(Frame{});
    }
}

void build_keyboard_surround(MeshBuilder& b, const Materials& m) {
    // Cheeks (key blocks): a rounded front and a concave sweep up to the front board.
    for (float s : {-1.0f, 1.0f}) {
        b.begin_object(s < 0 ? "cheek_l" : "cheek_r");
        b.set_material(m.wood);
        std::vector<ProfilePoint> p = {
            {0.025f, kKeybedTop}, {0.360f, kKeybedTop}, {0.360f, 0.735f}};
        append_arc(p, 0.335f, 0.735f, 0.025f, 0.0f, 0.5f * kPi, 8);
        p.back().smooth = false;
        append_arc(p, 0.215f, 0.800f, 0.040f, 1.5f * kPi, kPi, 10);
        p.push_back({kUpperBoardBack, kUpperBoardBottom});
        // The arc's start repeats the point (0.215, 0.76) only if the flat top is missing.
        std::vector<ProfilePoint> q;
        for (const auto& pt : p)
            if (q.empty() || std::abs(q.back().u - pt.u) + std::abs(q.back().v - pt.v) > 1e-6f)
                q.push_back(pt);
        float x0 = s < 0 ? -kSideOuter : kCheekInner, x1 = s < 0 ? -kCheekInner : kSideOuter;
        b.extrude(q, {0.0f, 0.0f, 1.0f}, {0.0f, 1.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, x0, x1);
    }

    // Fallboard over the back of the keys, with a rounded nose and a brass name plate.
    b.begin_object("fallboard");
    b.set_material(m.wood);
    {
        std::vector<ProfilePoint> p = {{0.050f, 0.737f}, {0.205f, 0.737f}, {0.205f, 0.762f}};
        append_arc(p, 0.190f, 0.762f, 0.015f, 0.0f, 0.5f * kPi, 8);
        p.erase(p.end() - 9);  // (0.205, 0.762) again
        p.back().smooth = false;
        p.push_back({0.100f, 0.797f});
        p.push_back({0.050f, 0.806f});
        b.extrude(p, {0.0f, 0.0f, 1.0f}, {0.0f, 1.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, -kCheekInner,
                  kCheekInner);
    }
    b.set_material(m.brass);
    b.chamfer_box({-0.06f, 0.744f, 0.2045f}, {0.06f, 0.756f, 0.2075f}, 0.001f);
}

void build_legs(MeshBuilder& b, const Materials& m) {
    const auto profile = leg_profile();
    for (float s : {-1.0f, 1.0f}) {
        const float x = s * kLegX;
        b.begin_object(s < 0 ? "toe_l" : "toe_r");
        b.set_material(m.wood);
        // Toe block on the floor with a rounded front.
        std::vector<ProfilePoint> toe = {{0.010f, 0.0f}, {0.345f, 0.0f}, {0.345f, 0.020f}};
        append_arc(toe, 0.300f, 0.020f, 0.045f, 0.0f, 0.5f * kPi, 10);
        toe.erase(toe.end() - 11);
        toe.back().smooth = false;
        toe.push_back({0.010f, kPlinthTop});
        b.extrude(toe, {0.0f, 0.0f, 1.0f}, {0.0f, 1.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, x - 0.045f,
                  x + 0.045f);

        b.begin_object(s < 0 ? "leg_l" : "leg_r");
        b.set_material(m.wood);
        b.chamfer_box({x - 0.038f, kPlinthTop, kLegZ - 0.038f},
                      {x + 0.038f, 0.120f, kLegZ + 0.038f}, 0.005f);
        b.chamfer_box({x - 0.040f, 0.550f, kLegZ - 0.040f},
                      {x + 0.040f, kKeybedBottom, kLegZ + 0.040f}, 0.005f);
        b.set_frame(Frame::along({x, 0.0f, kLegZ}, {0.0f, 1.0f, 0.0f}));
        b.lathe(profile, 48, false, false);
        b.set_frame(Frame{});
    }
}

void build_upper_front(MeshBuilder& b, const Materials& m) {
    b.begin_object("upper_front");
    b.set_material(m.wood);
    const float z0 = kUpperBoardBack, z1 = kUpperBoardFront;
    const float w = kWindowHalfWidth;
    b.box({-kSideInner, kUpperBoardBottom, z0}, {kSideInner, kWindowBottom, z1});
    b.box({-kSideInner, kWindowTop, z0}, {kSideInner, kCaseTop - 0.025f, z1});
    b.box({-kSideInner, kWindowBottom, z0}, {-w, kWindowTop, z1});
    b.box({w, kWindowBottom, z0}, {kSideInner, kWindowTop, z1});
    // Moulded frame around the spool-box window (counter-clockwise seen from the front, so the
    // moulding lies outside the opening).
    std::vector<Vec3f> window = {
        {-w, kWindowBottom, z1}, {w, kWindowBottom, z1}, {w, kWindowTop, z1}, {-w, kWindowTop, z1}};
    b.sweep(window, true, {0.0f, 0.0f, 1.0f}, bolection_profile(1.0f));
    // Three raised panels above the window.
    for (float xc : {-0.47f, 0.0f, 0.47f}) {
        Frame f;
        f.origin = {xc, 1.165f, z1};
        raised_panel(b, f, xc == 0.0f ? 0.19f : 0.21f, 0.085f, m);
    }
    // Two smaller panels flanking the window.
    for (float xc : {-0.545f, 0.545f}) {
        Frame f;
        f.origin = {xc, 0.935f, z1};
        raised_panel(b, f, 0.135f, 0.070f, m);
    }

    // The spool box behind the window: felt-lined back, wooden walls.
    b.begin_object("spool_box");
    b.set_material(m.felt);
    b.box({-w, kWindowBottom, kSpoolBoxBack}, {w, kWindowTop, kSpoolBoxBack + 0.01f});
    b.set_material(m.wood);
    b.box({-w - 0.01f, kWindowBottom - 0.01f, kSpoolBoxBack}, {-w, kWindowTop + 0.01f, z0});
    b.box({w, kWindowBottom - 0.01f, kSpoolBoxBack}, {w + 0.01f, kWindowTop + 0.01f, z0});
    b.box({-w, kWindowBottom - 0.01f, kSpoolBoxBack}, {w, kWindowBottom, z0});
    b.box({-w, kWindowTop, kSpoolBoxBack}, {w, kWindowTop + 0.01f, z0});
}

void build_sconces(MeshBuilder& b, const Materials& m) {
    // Swing-arm candle sconces, turned brass, on the small panels beside the window.
    for (float s : {-1.0f, 1.0f}) {
        b.begin_object(s < 0 ? "sconce_l" : "sconce_r");
        b.set_material(m.brass);
        const Vec3f base(s * 0.545f, 0.935f, kUpperBoardFront + 0.006f);
        // Back plate with a moulded edge and a boss for the arm.
        std::vector<ProfilePoint> plate = {{0.0f, 0.0f}, {0.030f, 0.0f}, {0.030f, 0.002f}};
        append_arc(plate, 0.022f, 0.002f, 0.008f, 0.0f, 0.5f * kPi, 6);
        plate.erase(plate.end() - 7);
        plate.back().smooth = false;
        plate.push_back({0.009f, 0.010f});
        append_arc(plate, 0.009f, 0.014f, 0.004f, -0.5f * kPi, 0.5f * kPi, 5);
        plate.erase(plate.end() - 6);  // (0.009, 0.010) again
        plate.push_back({0.0f, 0.018f});
        b.set_frame(Frame::along(base, {0.0f, 0.0f, 1.0f}));
        b.lathe(plate, 32);
        // The arm, with a bead half-way.
        std::vector<ProfilePoint> arm = {{0.0f, 0.016f}, {0.0050f, 0.016f}, {0.0050f, 0.040f}};
        append_arc(arm, 0.0050f, 0.045f, 0.005f, -0.5f * kPi, 0.5f * kPi, 8);
        arm.erase(arm.end() - 9);
        arm.push_back({0.0050f, 0.078f});
        arm.push_back({0.0f, 0.078f});
        b.lathe(arm, 24);
        // Drip pan and cup on a vertical axis, a finial drop underneath.
        const Vec3f cup_origin = base + Vec3f(0.0f, 0.0f, 0.080f);
        std::vector<ProfilePoint> cup;
        append_arc(cup, 0.0f, -0.022f, 0.008f, -0.5f * kPi, 0.25f * kPi, 8, true);
        cup.back().smooth = false;
        cup.push_back({0.0045f, -0.011f});
        cup.push_back({0.0300f, -0.004f});
        cup.push_back({0.0340f, -0.002f});
        cup.push_back({0.0340f, 0.002f});
        cup.push_back({0.0300f, 0.002f});
        cup.push_back({0.0140f, 0.000f});
        cup.push_back({0.0120f, 0.003f});
        for (int i = 1; i <= 6; ++i) {
            float t = static_cast<float>(i) / 6.0f;
            cup.push_back({0.012f + 0.004f * t * t, 0.003f + 0.025f * t, i < 6});
        }
        cup.push_back({0.0160f, 0.032f});
        cup.push_back({0.0115f, 0.032f});
        cup.push_back({0.0f, 0.032f});
        b.set_frame(Frame::along(cup_origin, {0.0f, 1.0f, 0.0f}));
        b.lathe(cup, 40);
        // Candle (ivory-coloured wax) and wick.
        b.set_material(m.ivory);
        std::vector<ProfilePoint> candle = {{0.0f, 0.030f}, {0.0105f, 0.030f}, {0.0105f, 0.125f}};
        append_arc(candle, 0.0075f, 0.125f, 0.003f, 0.0f, 0.5f * kPi, 4);
        candle.erase(candle.end() - 5);
        candle.back().smooth = false;
        candle.push_back({0.0f, 0.128f});
        b.lathe(candle, 32);
        b.set_material(m.ebony);
        b.lathe(cylinder_profile(0.0012f, 0.128f, 0.138f), 8);
        b.set_frame(Frame{});
    }
}

/// One spool: the paper wound on it, two flanges with spokes on their outer faces, and the
/// chucks that carry it in the spool box walls. Built about the spool's own axis (world +x).
void build_spool(MeshBuilder& b, const Materials& m, const RollGeometry& roll, float y,
                 std::uint32_t flange_material, std::uint32_t spoke_material) {
    const Vec3f centre(0.0f, y, roll.spool_z);
    const Frame axis = Frame::along(centre, {1.0f, 0.0f, 0.0f});
    const float half = 0.5f * roll.paper_width;
    b.set_frame(axis);
    b.set_material(m.paper);
    b.lathe(cylinder_profile(roll.spool_radius, -half, half), 64);
    b.set_material(m.brass);
    b.lathe(cylinder_profile(0.006f, -(kWindowHalfWidth - 0.0005f), kWindowHalfWidth - 0.0005f),
            16);
    for (float s : {-1.0f, 1.0f}) {
        // Flange: a disc with a rounded rim.
        const float c = s * (half + 0.0035f), t = 0.002f, r = 0.036f;
        std::vector<ProfilePoint> flange = {{0.0f, c - t}, {r - t, c - t}};
        append_arc(flange, r - t, c, t, -0.5f * kPi, 0.5f * kPi, 6);
        flange.erase(flange.end() - 7);
        flange.push_back({0.0f, c + t});
        b.set_material(flange_material);
        b.lathe(flange, 64);
        // Hub.
        b.set_material(m.brass);
        const float h0 = c + s * t, h1 = c + s * (t + 0.012f);
        std::vector<ProfilePoint> hub = {{0.0f, std::min(h0, h1)},
                                         {0.011f, std::min(h0, h1)},
                                         {0.011f, std::max(h0, h1)},
                                         {0.0f, std::max(h0, h1)}};
        b.lathe(hub, 24);
        // Three spokes on the outer face: they show the spool turning.
        b.set_material(spoke_material);
        for (int k = 0; k < 3; ++k) {
            Frame spoke =
                axis.rotated(centre, {1.0f, 0.0f, 0.0f}, 2.0f * kPi * static_cast<float>(k) / 3.0f);
            b.set_frame(spoke);
            const float f0 = c + s * t, f1 = c + s * (t + 0.0025f);
            b.chamfer_box({0.011f, std::min(f0, f1), -0.0025f}, {0.032f, std::max(f0, f1), 0.0025f},
                          0.0008f);
        }
        b.set_frame(axis);
    }
    b.set_frame(Frame{});
}

void build_pedal(MeshBuilder& b, const Materials& m, RigidPart& part, float x,
                 Vec3f& tread_centre) {
    part.pivot = {x, kPedalPivotY, kPedalPivotZ};
    part.axis = {1.0f, 0.0f, 0.0f};
    // Local frame: origin at the pivot, z along the tread, y out of it; tilted toe-up at rest.
    Frame local;
    local.origin = part.pivot;
    const Frame pedal = local.rotated(part.pivot, {1.0f, 0.0f, 0.0f}, -kPedalRestTilt);
    // Hinge barrel with rounded shoulders.
    b.set_material(m.brass);
    b.set_frame(pedal.compose(Frame::along({0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f})));
    std::vector<ProfilePoint> barrel = {{0.0f, -0.058f}};
    append_arc(barrel, 0.010f, -0.055f, 0.003f, -0.5f * kPi, 0.0f, 3);
    barrel.back().smooth = true;
    append_arc(barrel, 0.010f, 0.055f, 0.003f, 0.0f, 0.5f * kPi, 3);
    barrel[barrel.size() - 4].smooth = true;
    barrel.push_back({0.0f, 0.058f});
    b.lathe(barrel, 24);
    // The tread plate (cast brass) with rounded front corners, in the pedal's (x, z) plane.
    b.set_frame(pedal);
    auto rounded = [](float hw, float z0, float z1, float r) {
        std::vector<ProfilePoint> o = {{-hw, z0}, {hw, z0}};
        append_arc(o, hw - r, z1 - r, r, 0.0f, 0.5f * kPi, 6);
        append_arc(o, -hw + r, z1 - r, r, 0.5f * kPi, kPi, 6);
        return o;
    };
    const Vec3f ux(1.0f, 0.0f, 0.0f), uy(0.0f, 1.0f, 0.0f), uz(0.0f, 0.0f, 1.0f);
    b.extrude(rounded(kPedalHalfWidth, 0.0f, kPedalLength, 0.030f), ux, uz, uy, -0.008f, 0.004f);
    // Felt tread pad, inset, and brass ribs across it for grip.
    b.set_material(m.felt);
    b.extrude(rounded(kPedalHalfWidth - 0.008f, 0.030f, kPedalLength - 0.008f, 0.022f), ux, uz, uy,
              0.004f, 0.0075f);
    b.set_material(m.brass);
    for (int i = 0; i < 6; ++i) {
        float z = 0.055f + 0.030f * static_cast<float>(i);
        b.box({-kPedalHalfWidth + 0.014f, 0.0075f, z - 0.002f},
              {kPedalHalfWidth - 0.014f, 0.0100f, z + 0.002f});
    }
    tread_centre = pedal.point({0.0f, 0.0075f, 0.13f});
    b.set_frame(Frame{});
}

/// The flat paper between the spools and the pool of hole quads in front of it, all parked.
void build_roll(MeshBuilder& b, const Materials& m, const RollGeometry& roll,
                std::uint32_t capacity, HolePool& pool) {
    b.set_material(m.paper);
    const float half = 0.5f * roll.paper_width;
    std::uint32_t a = b.vertex({-half, roll.window_bottom, roll.paper_z});
    std::uint32_t c1 = b.vertex({half, roll.window_bottom, roll.paper_z});
    std::uint32_t c2 = b.vertex({half, roll.window_top, roll.paper_z});
    std::uint32_t d = b.vertex({-half, roll.window_top, roll.paper_z});
    b.polygon({a, c1, c2, d}, {0.0f, 0.0f, 1.0f});

    Scene& scene = b.scene();
    pool.material = m.hole;
    pool.capacity = capacity;
    pool.park = {0.0f, roll.tracker_y, roll.paper_z - 0.01f};
    pool.first_position = static_cast<std::uint32_t>(scene.positions.size());
    pool.first_triangle = static_cast<std::uint32_t>(scene.triangle_count());
    pool.object = static_cast<std::uint32_t>(scene.objects.size() - 1);
    for (std::uint32_t i = 0; i < capacity; ++i) {
        std::uint32_t v = static_cast<std::uint32_t>(scene.positions.size());
        for (int k = 0; k < 4; ++k) scene.positions.push_back(pool.park);
        // Corners 0..3 are (x0, y0), (x1, y0), (x1, y1), (x0, y1) when placed: facing +z.
        scene.add_triangle({v, v + 1, v + 2}, m.hole, pool.object);
        scene.add_triangle({v, v + 2, v + 3}, m.hole, pool.object);
    }
}

}  // namespace

PianoModel build_piano(const PianoOptions& options) {
    PianoModel model;
    Scene& scene = model.scene;
    scene.clear();
    MeshBuilder b(scene);
    const Materials m = add_materials(b);
    const RollGeometry& roll = model.roll_geometry;

    build_keys(b, model, m);
    build_case(b, m);
    build_lower_front(b, m);
    build_keyboard_surround(b, m);
    build_legs(b, m);
    build_upper_front(b, m);
    build_sconces(b, m);

    b.begin_object("tracker_bar");
    b.set_material(m.brass);
    b.chamfer_box({-0.165f, roll.tracker_y - 0.008f, roll.paper_z - 0.023f},
                  {0.165f, roll.tracker_y + 0.008f, roll.paper_z - 0.002f}, 0.002f);

    model.spool_upper = begin_part(b, "spool_upper");
    build_spool(b, m, roll, roll.window_top, m.ebony, m.brass);
    model.spool_upper.pivot = {0.0f, roll.window_top, roll.spool_z};
    end_part(b, model.spool_upper);
    model.spool_lower = begin_part(b, "spool_lower");
    build_spool(b, m, roll, roll.window_bottom, m.brass, m.ebony);
    model.spool_lower.pivot = {0.0f, roll.window_bottom, roll.spool_z};
    end_part(b, model.spool_lower);

    model.roll = begin_part(b, "roll");
    build_roll(b, m, roll, options.hole_capacity, model.holes);
    model.roll.pivot = model.spool_upper.pivot;
    end_part(b, model.roll);

    Vec3f tread[2];
    for (int i = 0; i < 2; ++i) {
        RigidPart& pedal = model.pedals[static_cast<std::size_t>(i)];
        pedal = begin_part(b, i == 0 ? "pedal_l" : "pedal_r");
        build_pedal(b, m, pedal, i == 0 ? -kPedalX : kPedalX, tread[i]);
        end_part(b, pedal);
    }

    // Bounds and anchors before the floor goes in.
    model.bounds = scene.bounds();
    model.keyboard_center = {0.0f, kKeyTop, 0.5f * (0.205f + kKeyFront)};
    model.roll_window_center = {0.0f, 0.5f * (kWindowBottom + kWindowTop), kUpperBoardFront};
    model.pedal_center = (tread[0] + tread[1]) * 0.5f;
    model.front_center = {0.0f, kKeyTop, kKeyFront};

    model.floor_object = b.begin_object("floor");
    b.set_material(m.floor);
    {
        std::uint32_t a = b.vertex({-2.2f, 0.0f, -1.0f}), c1 = b.vertex({2.2f, 0.0f, -1.0f}),
                      c2 = b.vertex({2.2f, 0.0f, 2.4f}), d = b.vertex({-2.2f, 0.0f, 2.4f});
        b.polygon({a, c1, c2, d}, {0.0f, 1.0f, 0.0f});
    }

    // A three-quarter view from the player's right, a little above the keys, framing it all.
    scene.camera = look_at({1.7f, 1.6f, 3.3f}, {0.0f, 0.68f, 0.0f}, 38.0f);
    return model;
}

std::string key_object_name(int midi) {
    if (midi < kLowestKey || midi > kHighestKey)
        throw Error(fmt::format("key_object_name: MIDI note {} is outside the 88 keys", midi));
    int whites = 0, blacks = 0;
    for (int k = kLowestKey; k <= midi; ++k) (is_black_key(k) ? blacks : whites)++;
    return is_black_key(midi) ? fmt::format("b{}", blacks) : fmt::format("w{}", whites);
}

CameraSpec look_at(const Vec3f& eye, const Vec3f& target, float horizontal_fov_degrees) {
    Vec3f forward = normalize(target - eye);
    Vec3f right = cross(forward, Vec3f(0.0f, 1.0f, 0.0f));
    if (length(right) < 1e-6f) right = Vec3f(1.0f, 0.0f, 0.0f);
    right = normalize(right);
    Vec3f up = normalize(cross(right, forward));
    float distance = 1.0f / portable::tan(0.5f * horizontal_fov_degrees * kPi / 180.0f);
    return {eye, eye + forward * distance, up};
}

}  // namespace toonray
