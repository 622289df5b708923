#pragma once
/// The procedural upright player piano: geometry, materials, movable parts and camera anchors.
///
/// Conventions (other modules rely on them): metres; Y up with the floor at y = 0; the piano
/// centred on x = 0; the player side (keyboard front) faces +Z, the back of the case is at
/// z = -0.34 and the key fronts at z = +0.34. Bass keys are at -x.
///
/// Every movable part (the 88 keys `w1`..`w52` and `b1`..`b36`, the pedals, the two spools and
/// the roll's paper with its hole pool) is its own object whose vertices (and normals) form one
/// contiguous range, so posing rewrites only those ranges and never the triangles.

#include <array>
#include <cstdint>
#include <string>

#include "toonray/core/bbox.h"
#include "toonray/core/math.h"
#include "toonray/scene/scene.h"

namespace toonray {

inline constexpr int kPianoKeys = 88;
inline constexpr int kLowestKey = 21;    ///< MIDI A0
inline constexpr int kHighestKey = 108;  ///< MIDI C8

/// True for the sharps/flats (MIDI pitch classes 1, 3, 6, 8, 10).
constexpr bool is_black_key(int midi) {
    int pc = ((midi % 12) + 12) % 12;
    return pc == 1 || pc == 3 || pc == 6 || pc == 8 || pc == 10;
}

/// Object name of the key for MIDI note `midi` (21..108): white keys "w1".."w52" and black
/// keys "b1".."b36", each counted from A0 (w1 = A0 = 21, b1 = A#0 = 22, w24 = middle C = 60).
std::string key_object_name(int midi);

/// The roll mechanism's geometry (shared by the model, the hole placement and the playback;
/// build_piano places the spools and paper from these values).
struct RollGeometry {
    float paper_speed = 0.05f;   ///< m/s of paper past the tracker bar while music plays
    float paper_width = 0.286f;  ///< 11 1/4 inch, the standard 88-note roll
    float paper_z = -0.007f;     ///< the flat paper's front surface (facing +z)
    float hole_lift = 0.0004f;   ///< holes sit this far in front of the paper
    /// The flat stretch of paper between the two spools, seen through the window: world y from
    /// `window_bottom` (top of the take-up spool's paper) to `window_top` (the music roll).
    float window_bottom = 0.870f;
    float window_top = 0.995f;
    float tracker_y = 0.930f;       ///< a note sounds while its slot passes this line
    float hole_pitch = 0.0028222f;  ///< across the paper: 9 holes per inch, as real 88-note rolls
    float hole_width = 0.0018f;
    float min_slot_length = 0.002f;  ///< even the shortest note punches at least this much
    float spool_z = -0.035f;         ///< both spool axes (parallel to x)
    float spool_radius = 0.028f;     ///< radius of the paper wound on either spool

    /// Centre of the slot column for MIDI note `midi` across the paper (bass at -x).
    [[nodiscard]] float hole_x(int midi) const {
        return (static_cast<float>(midi) - 64.5f) * hole_pitch;
    }
};

/// A rigid movable part: an object whose positions [first_position, first_position +
/// position_count) and normals [first_normal, first_normal + normal_count) turn about the line
/// through `pivot` along the unit `axis` (positive angles by the right-hand rule).
struct RigidPart {
    std::uint32_t object = 0;
    std::uint32_t first_position = 0;
    std::uint32_t position_count = 0;
    std::uint32_t first_normal = 0;
    std::uint32_t normal_count = 0;
    Vec3f pivot;
    Vec3f axis{1.0f, 0.0f, 0.0f};
};

/// One key. It pivots about the x axis through its back bottom edge; a positive angle takes
/// the front down.
struct PianoKey : RigidPart {
    int midi = 0;
    bool black = false;
    Vec3f front_top;   ///< rest position of the middle of the key's top front edge
    float width = 0;   ///< at the front (white) or at the base (black)
    float length = 0;  ///< from the pivot to the front
};

/// The roll's hole pool: `capacity` quads (4 positions and 2 triangles each, contiguous),
/// placed each frame in front of the paper where a slot is visible; unused quads collapse onto
/// `park` (zero-area triangles, which rays never hit, behind the paper).
struct HolePool {
    std::uint32_t object = 0;
    std::uint32_t material = 0;
    std::uint32_t first_position = 0;
    std::uint32_t first_triangle = 0;
    std::uint32_t capacity = 0;
    Vec3f park;
};

struct PianoOptions {
    /// Hole quads in the pool: at least the most slots ever visible at once for the score to be
    /// played (PunchedRoll::max_visible()); extra slots in a frame are left out and counted.
    std::uint32_t hole_capacity = 256;
};

struct PianoModel {
    Scene scene;  ///< rest pose, holes parked; its camera is a three-quarter overview
    std::array<PianoKey, kPianoKeys> keys;  ///< index = MIDI - 21
    std::array<RigidPart, 2> pedals;        ///< 0 = left, 1 = right; axis +x, positive = pressed
    RigidPart spool_upper;                  ///< the music roll (turns as paper advances)
    RigidPart spool_lower;                  ///< the take-up spool
    RigidPart roll;  ///< the flat paper and the hole pool (pivot: upper spool axis)
    HolePool holes;
    RollGeometry roll_geometry;
    std::uint32_t floor_object = 0;

    // Anchors for cameras (world space, rest pose).
    BBox bounds;               ///< the piano without the floor
    Vec3f keyboard_center;     ///< middle of the white keys' visible tops
    Vec3f roll_window_center;  ///< middle of the spool-box window, in the front board's plane
    Vec3f pedal_center;        ///< between the two pedals' treads
    Vec3f front_center;        ///< middle of the case front at keyboard height (a look-at point)
};

/// Builds the piano (and a floor) in its rest pose.
PianoModel build_piano(const PianoOptions& options = {});

/// Camera looking from `eye` at `target` with `horizontal_fov_degrees` (toonray's camera: the
/// eye-to-gaze distance sets the field of view), up as close to +Y as possible.
CameraSpec look_at(const Vec3f& eye, const Vec3f& target, float horizontal_fov_degrees);

}  // namespace toonray
