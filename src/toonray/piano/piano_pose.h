#pragma once
/// Posing the piano with constant topology: keys, pedals and spools turn about their pivots and
/// the roll's holes move over the paper, but the triangles never change, so a renderer can refit
/// its BVH instead of rebuilding it.

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/piano/piano_model.h"
#include "toonray/score/score.h"

namespace toonray {

/// Angle of a fully pressed key: the white key fronts drop 10 mm (black keys, shorter, about
/// 8 mm), as on a real piano.
inline constexpr float kKeyDipAngle = 0.042f;
/// Angle of a fully pressed pumping pedal.
inline constexpr float kPedalStrokeAngle = 0.22f;

struct PianoPose {
    /// Per key (index = MIDI - 21), radians about the key's pivot; 0 = rest, positive = front
    /// down (kKeyDipAngle is a full press).
    std::array<float, kPianoKeys> key_angle{};
    /// Metres of paper advanced past the tracker bar (paper speed x time while playing).
    float roll_position = 0.0f;
    /// Left and right pedal, radians; 0 = rest (up), positive = pressed.
    std::array<float, 2> pedal_angle{};
};

/// One punched slot, in paper coordinates: metres along the paper from the start of the roll.
/// The slot's leading edge `begin` reaches the tracker bar at the note's onset.
struct RollSlot {
    float begin = 0.0f;
    float end = 0.0f;
    int key = 0;  ///< MIDI note; its column across the paper is RollGeometry::hole_x(key)
};

/// A score punched into roll paper: one slot per note, its column across the paper by pitch and
/// its length along the paper by duration (at least RollGeometry::min_slot_length).
class PunchedRoll {
public:
    PunchedRoll() = default;
    /// Notes outside the 88 keys get no slot (counted in ignored_notes()).
    explicit PunchedRoll(const Score& score, const RollGeometry& geometry = {});

    [[nodiscard]] const std::vector<RollSlot>& slots() const { return slots_; }  ///< by begin
    [[nodiscard]] const RollGeometry& geometry() const { return geometry_; }
    [[nodiscard]] int ignored_notes() const { return ignored_; }

    /// Paper coordinates on the flat paper in the window at roll position `r`: (lo, hi).
    [[nodiscard]] float window_lo(float r) const {
        return r + geometry_.window_bottom - geometry_.tracker_y;
    }
    [[nodiscard]] float window_hi(float r) const {
        return r + geometry_.window_top - geometry_.tracker_y;
    }

    /// Calls f(slot) for every slot with some length on the flat paper in the window at roll
    /// position `r` (begin < window_hi and end > window_lo), in order of `begin`.
    template <typename F>
    void for_each_visible(float r, F&& f) const {
        const float lo = window_lo(r), hi = window_hi(r);
        std::size_t i = first_candidate(lo);
        for (; i < slots_.size() && slots_[i].begin < hi; ++i)
            if (slots_[i].end > lo) f(slots_[i]);
    }
    [[nodiscard]] std::size_t visible_count(float r) const;
    /// The most slots ever visible at once: the hole pool size this roll needs.
    [[nodiscard]] std::size_t max_visible() const { return max_visible_; }

private:
    [[nodiscard]] std::size_t first_candidate(float lo) const;

    std::vector<RollSlot> slots_;
    RollGeometry geometry_;
    float max_length_ = 0.0f;
    std::size_t max_visible_ = 0;
    int ignored_ = 0;
};

/// What a pose did with the hole pool.
struct PoseStats {
    std::uint32_t visible_holes = 0;  ///< holes placed in front of the paper
    std::uint32_t dropped_holes = 0;  ///< visible slots left out because the pool was full
};

/// The piano with its 88 keys as instances of their shapes (Scene::instances): the keys' own
/// triangles are left out of model.scene's copy (their vertices stay, unused, so that
/// pose_piano still fits it); each distinct key shape (every black key; the white keys by the
/// notches their black neighbours cut) is one mesh in the key's own frame, its pivot at the
/// origin, and the key is an instance of it at its pivot, of the key's object (`w1`..`b36`).
/// Posing then changes 88 transforms (pose_key_instances) instead of the keys' vertices.
[[nodiscard]] Scene instance_keys(const PianoModel& model);

/// Sets the transforms of a scene from instance_keys (instance i = key i) for the key angles
/// of `pose`: each key turned about its pivot as pose_piano turns its vertices.
void pose_key_instances(const PianoModel& model, const PianoPose& pose, Scene& scene);

/// Writes the posed positions and normals of every movable part into `scene`, which must be a
/// copy of model.scene (same sizes; any earlier pose is overwritten). Touches only the movable
/// parts' vertex ranges: keys and pedals turn about their pivots, both spools turn by
/// roll_position / spool radius (paper runs down the front), and the hole pool shows the slots
/// of `roll` (none when null) that lie on the paper in the window at pose.roll_position,
/// clipped to it; unused hole quads are collapsed onto HolePool::park. Throws Error when
/// `scene` does not match the model.
PoseStats pose_piano(const PianoModel& model, const PianoPose& pose, const PunchedRoll* roll,
                     Scene& scene);

}  // namespace toonray
