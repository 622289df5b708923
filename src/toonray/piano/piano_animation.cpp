#include "toonray/piano/piano_animation.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "toonray/core/portable_math.h"

namespace toonray {
namespace {

double smoothstep(double x) {
    x = std::clamp(x, 0.0, 1.0);
    return x * x * (3.0 - 2.0 * x);
}

}  // namespace

PianoPlayback::PianoPlayback(const Score& score, const PlaybackSettings& settings)
    : settings_(settings), roll_(score, settings.roll) {
    if (!(settings.attack > 0.0) || !(settings.release > 0.0) || settings.min_hold < 0.0 ||
        settings.min_up < 0.0 || !(settings.pedal_cycle > 0.0))
        throw Error(
            "PianoPlayback: attack, release and pedal_cycle must be positive, min_hold and "
            "min_up not negative");
    bool any = false;
    for (const Note& note : score.notes) {
        if (note.key < kLowestKey || note.key > kHighestKey) {
            ++ignored_;
            continue;
        }
        if (!std::isfinite(note.start) || !std::isfinite(note.end)) {
            ++ignored_;
            continue;
        }
        presses_[static_cast<std::size_t>(note.key - kLowestKey)].push_back(
            {note.start, std::max(note.start, note.end), 0.0f});
        start_ = any ? std::min(start_, note.start) : note.start;
        music_end_ = any ? std::max(music_end_, std::max(note.start, note.end))
                         : std::max(note.start, note.end);
        any = true;
    }
    has_notes_ = any;
    if (ignored_ > 0)
        warnings_.push_back(
            fmt::format("{} note{} outside the piano's 88 keys (MIDI {}..{}) or with "
                        "non-finite times ignored",
                        ignored_, ignored_ == 1 ? "" : "s", kLowestKey, kHighestKey));

    const double r = settings.release;
    for (auto& list : presses_) {
        std::sort(list.begin(), list.end(), [](const KeyPress& x, const KeyPress& y) {
            return x.on < y.on || (x.on == y.on && x.off > y.off);
        });
        // Notes struck together on one key are one press.
        std::vector<KeyPress> merged;
        for (const KeyPress& p : list) {
            if (!merged.empty() && p.on - merged.back().on < 1e-6) {
                merged.back().off = std::max(merged.back().off, p.off);
                continue;
            }
            merged.push_back(p);
        }
        // Make room for each release: fully up for min_up before the next press, but never
        // less than min_hold down.
        for (std::size_t i = 0; i + 1 < merged.size(); ++i) {
            KeyPress& p = merged[i];
            p.off = std::min(p.off, merged[i + 1].on - settings.attack - r - settings.min_up);
        }
        for (KeyPress& p : merged) p.off = std::max(p.off, p.on + settings.min_hold);
        list = std::move(merged);
        // Depth where each press begins (above 0 only when the previous release is cut short).
        for (std::size_t i = 1; i < list.size(); ++i)
            list[i].start_depth = press_depth(list[i - 1], list[i].on - settings.attack);
        if (!list.empty()) end_ = std::max(end_, list.back().off + r);
    }
}

float PianoPlayback::press_depth(const KeyPress& p, double t) const {
    // The key starts down `attack` before the onset and bottoms out at it: the hammer strikes
    // (and the note sounds) when the key reaches the bottom.
    const double begin = p.on - settings_.attack;
    if (t < begin) return 0.0f;
    const double down =
        std::min(1.0, p.start_depth + (std::min(t, p.off) - begin) / settings_.attack);
    if (t <= p.off) return static_cast<float>(down);
    return static_cast<float>(std::max(0.0, down - (t - p.off) / settings_.release));
}

float PianoPlayback::key_depth(int midi, double t) const {
    if (midi < kLowestKey || midi > kHighestKey) return 0.0f;
    const auto& list = presses_[static_cast<std::size_t>(midi - kLowestKey)];
    // The latest press that has begun decides the depth (it started from where the previous
    // one had got to).
    const double attack = settings_.attack;
    auto it = std::upper_bound(list.begin(), list.end(), t,
                               [attack](double x, const KeyPress& p) { return x < p.on - attack; });
    if (it == list.begin()) return 0.0f;
    return press_depth(*(it - 1), t);
}

float PianoPlayback::roll_position(double t) const {
    return static_cast<float>(settings_.roll.paper_speed * std::clamp(t, 0.0, music_end_));
}

std::array<float, 2> PianoPlayback::pedal_angles(double t) const {
    if (!has_notes_) return {0.0f, 0.0f};
    const double t0 = start_ - settings_.pedal_lead;
    const double ease = std::max(settings_.pedal_ease, 1e-6);
    const double activity = smoothstep((t - t0) / ease) * (1.0 - smoothstep((t - end_) / ease));
    if (activity <= 0.0) return {0.0f, 0.0f};
    const double phase = 2.0 * 3.14159265358979 * (t - t0) / settings_.pedal_cycle;
    const double left = 0.5 - 0.5 * portable::cos(phase), right = 1.0 - left;
    const double s = settings_.pedal_stroke * activity;
    return {static_cast<float>(s * left), static_cast<float>(s * right)};
}

const std::vector<KeyPress>& PianoPlayback::presses(int midi) const {
    if (midi < kLowestKey || midi > kHighestKey)
        throw Error(
            fmt::format("PianoPlayback::presses: MIDI note {} is outside the 88 keys", midi));
    return presses_[static_cast<std::size_t>(midi - kLowestKey)];
}

PianoPose PianoPlayback::pose_at(double t) const {
    PianoPose pose;
    for (int i = 0; i < kPianoKeys; ++i)
        pose.key_angle[static_cast<std::size_t>(i)] =
            settings_.key_dip_angle * key_depth(kLowestKey + i, t);
    pose.roll_position = roll_position(t);
    pose.pedal_angle = pedal_angles(t);
    return pose;
}

}  // namespace toonray
