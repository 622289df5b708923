#include "toonray/score/timed_score.h"

#include <algorithm>
#include <fmt/format.h>
#include <tuple>

namespace toonray {
namespace {

/// Sorts by tick keeping file order within a tick, then keeps only the last entry per tick.
template <typename T>
void sort_last_wins(std::vector<T>& v) {
    std::stable_sort(v.begin(), v.end(), [](const T& a, const T& b) { return a.tick < b.tick; });
    std::vector<T> out;
    out.reserve(v.size());
    for (const T& x : v) {
        if (!out.empty() && out.back().tick == x.tick) out.back() = x;
        else out.push_back(x);
    }
    v = std::move(out);
}

/// Seconds at each tempo change, so a lookup is one binary search.
class TempoMap {
public:
    TempoMap(const std::vector<TempoChange>& tempo, int ppq) : tempo_(tempo), ppq_(ppq) {
        seconds_.reserve(tempo_.size());
        double s = 0.0;
        for (std::size_t i = 0; i < tempo_.size(); ++i) {
            if (i > 0) s += span(tempo_[i - 1].tick, tempo_[i].tick, tempo_[i - 1].us_per_quarter);
            seconds_.push_back(s);
        }
    }

    double seconds(std::int64_t tick) const {
        auto it = std::upper_bound(tempo_.begin(), tempo_.end(), tick,
                                   [](std::int64_t t, const TempoChange& c) { return t < c.tick; });
        if (it == tempo_.begin()) {
            // Before the first change (or no tempo at all) MIDI plays at its default tempo.
            std::int64_t first = tempo_.empty() ? tick : tempo_.front().tick;
            return -span(tick, first, kMidiDefaultTempo);
        }
        std::size_t i = static_cast<std::size_t>(it - tempo_.begin()) - 1;
        return seconds_[i] + span(tempo_[i].tick, tick, tempo_[i].us_per_quarter);
    }

private:
    double span(std::int64_t from, std::int64_t to, std::uint32_t us) const {
        return static_cast<double>(to - from) * us * 1e-6 / ppq_;
    }

    const std::vector<TempoChange>& tempo_;
    int ppq_;
    std::vector<double> seconds_;
};

}  // namespace

double TimedScore::seconds_at(std::int64_t tick) const {
    return TempoMap(tempo, ppq).seconds(tick);
}

void normalize(TimedScore& score, std::uint32_t default_tempo, Warnings* warnings,
               std::string_view file) {
    sort_last_wins(score.tempo);
    if (score.tempo.empty() || score.tempo.front().tick != 0)
        score.tempo.insert(score.tempo.begin(), TempoChange{0, default_tempo});
    sort_last_wins(score.time_signatures);
    // By track and channel within a tick too, so that the order does not depend on how a
    // writer interleaves its tracks; file order within one track and channel is kept.
    std::stable_sort(
        score.pedal.begin(), score.pedal.end(), [](const PedalChange& a, const PedalChange& b) {
            return std::tie(a.tick, a.track, a.channel) < std::tie(b.tick, b.track, b.channel);
        });

    auto& notes = score.notes;
    auto by_voice_key = [](const TimedNote& a, const TimedNote& b) {
        return std::tie(a.track, a.channel, a.key, a.start, a.end, a.velocity) <
               std::tie(b.track, b.channel, b.key, b.start, b.end, b.velocity);
    };
    std::sort(notes.begin(), notes.end(), by_voice_key);
    const auto zero_length = static_cast<std::size_t>(std::count_if(
        notes.begin(), notes.end(), [](const TimedNote& n) { return n.end <= n.start; }));
    std::size_t shortened = 0;
    for (std::size_t i = 0; i + 1 < notes.size(); ++i) {
        TimedNote& a = notes[i];
        const TimedNote& b = notes[i + 1];
        if (a.track == b.track && a.channel == b.channel && a.key == b.key && b.start < a.end) {
            a.end = b.start;
            ++shortened;
        }
    }
    std::erase_if(notes, [](const TimedNote& n) { return n.end <= n.start; });
    std::sort(notes.begin(), notes.end(), [](const TimedNote& a, const TimedNote& b) {
        return std::tie(a.start, a.key, a.track, a.channel, a.end, a.velocity) <
               std::tie(b.start, b.key, b.track, b.channel, b.end, b.velocity);
    });
    for (const TimedNote& n : notes) score.end_tick = std::max(score.end_tick, n.end);
    for (const PedalChange& p : score.pedal) score.end_tick = std::max(score.end_tick, p.tick);
    for (const TempoChange& t : score.tempo) score.end_tick = std::max(score.end_tick, t.tick);
    for (const TimeSignature& t : score.time_signatures)
        score.end_tick = std::max(score.end_tick, t.tick);
    if (!warnings) return;
    auto warn = [&](std::string message) {
        warnings->push_back(file.empty() ? message : located(file, 0, message));
    };
    if (shortened > 0)
        warn(
            fmt::format("{} note(s) overlapped a later note of the same key on the same track "
                        "and channel and were cut short where it starts",
                        shortened));
    if (zero_length > 0) warn(fmt::format("{} note(s) of zero length dropped", zero_length));
}

Score to_score(const TimedScore& timed) {
    TempoMap map(timed.tempo, timed.ppq);
    Score score;
    score.notes.reserve(timed.notes.size());
    for (const TimedNote& n : timed.notes)
        score.notes.push_back(
            Note{map.seconds(n.start), map.seconds(n.end), n.key, n.velocity, n.track});
    // Ticks map to seconds monotonically, so the tick order is already start-then-key order;
    // sort anyway in case the caller skipped normalize.
    std::stable_sort(score.notes.begin(), score.notes.end(), [](const Note& a, const Note& b) {
        return std::tie(a.start, a.key) < std::tie(b.start, b.key);
    });
    std::vector<PedalChange> pedal = timed.pedal;
    std::stable_sort(pedal.begin(), pedal.end(),
                     [](const PedalChange& a, const PedalChange& b) { return a.tick < b.tick; });
    bool down = false;
    for (const PedalChange& p : pedal) {
        if (p.down() == down) continue;
        down = p.down();
        score.sustain.push_back(PedalEvent{map.seconds(p.tick), down});
    }
    score.end_time = std::max(map.seconds(timed.end_tick), score.duration());
    return score;
}

}  // namespace toonray
