#include "toonray/score/midi.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <fmt/format.h>
#include <string>

namespace toonray {
namespace {

constexpr std::uint32_t kMaxDelta = 0x0FFFFFFF;  // the largest 4-byte variable-length quantity
constexpr std::uint32_t kMaxTempo = 0xFFFFFF;    // tempo meta events hold 24 bits

/// A note-on waiting for its note-off. Per track, channel and key they form a FIFO queue: a
/// vector with a head index, so popping the front is O(1) whatever a hostile file does.
struct OpenNote {
    std::int64_t start;
    int velocity;
};
struct OpenQueue {
    std::vector<OpenNote> items;
    std::size_t head = 0;
    bool empty() const { return head == items.size(); }
    OpenNote pop() {
        OpenNote n = items[head++];
        if (head == items.size()) {
            items.clear();
            head = 0;
        }
        return n;
    }
};

class MidiReader {
public:
    MidiReader(std::span<const std::uint8_t> bytes, std::string_view file, Warnings* warnings,
               const MidiLimits& limits)
        : data_(bytes), file_(file), warnings_(warnings), limits_(limits), open_(16 * 128) {}

    TimedScore read() {
        if (!is_midi(data_)) fail(0, "not a Standard MIDI File (no \"MThd\" header)");
        if (data_.size() < 14) fail(data_.size(), "truncated header chunk");
        const std::uint32_t header_length = be32(4);
        if (header_length < 6)
            fail(4, fmt::format("header chunk length {} is too short (need 6)", header_length));
        if (header_length > data_.size() - 8) fail(data_.size(), "truncated header chunk");
        const unsigned format = be16(8);
        const unsigned tracks = be16(10);
        const unsigned division = be16(12);
        if (format == 2) fail(8, "MIDI format 2 (independent sequences) is not supported");
        if (format > 2) fail(8, fmt::format("unknown MIDI format {}", format));
        if (tracks == 0) fail(10, "the header announces no tracks");
        if (tracks > limits_.max_tracks)
            fail(10, fmt::format("{} tracks exceed the limit of {}", tracks, limits_.max_tracks));
        if (format == 0 && tracks != 1)
            fail(10, fmt::format("a format 0 file has exactly 1 track, the header announces {}",
                                 tracks));
        read_division(division);

        std::size_t pos = 8 + static_cast<std::size_t>(header_length);
        unsigned found = 0;
        while (found < tracks) {
            if (data_.size() - pos < 8)
                fail(pos, fmt::format("truncated file: the header announces {} tracks but the "
                                      "file ends after {}",
                                      tracks, found));
            const std::uint8_t* type = data_.data() + pos;
            const std::uint32_t length = be32(pos + 4);
            const bool is_track = std::memcmp(type, "MTrk", 4) == 0;
            if (!is_track &&
                !std::all_of(type, type + 4, [](std::uint8_t c) { return c >= 0x20 && c < 0x7F; }))
                fail(pos, fmt::format("bad chunk: type bytes {:02X} {:02X} {:02X} {:02X} where "
                                      "\"MTrk\" was expected",
                                      type[0], type[1], type[2], type[3]));
            const std::size_t left = data_.size() - pos - 8;
            if (length > left) {
                const std::string what =
                    is_track ? std::string("track")
                             : fmt::format("\"{}\"", std::string_view(
                                                         reinterpret_cast<const char*>(type), 4));
                fail(pos + 4, fmt::format("truncated {} chunk: length {} but only {} bytes left",
                                          what, length, left));
            }
            if (is_track) {
                read_track(pos + 8, pos + 8 + length, static_cast<int>(found));
                ++found;
            }
            // Chunks of other types are skipped: the standard reserves them for extensions.
            pos += 8 + static_cast<std::size_t>(length);
        }
        normalize(score_, kMidiDefaultTempo, warnings_, file_);
        return std::move(score_);
    }

private:
    [[noreturn]] void fail(std::size_t offset, std::string_view message) const {
        throw Error(fmt::format("{}: byte {}: {}", file_, offset, message));
    }
    void warn(std::string message) const {
        if (warnings_) warnings_->push_back(fmt::format("{}: {}", file_, message));
    }

    std::uint32_t be32(std::size_t at) const {
        return std::uint32_t{data_[at]} << 24 | std::uint32_t{data_[at + 1]} << 16 |
               std::uint32_t{data_[at + 2]} << 8 | data_[at + 3];
    }
    unsigned be16(std::size_t at) const { return unsigned{data_[at]} << 8 | data_[at + 1]; }

    void read_division(unsigned division) {
        if (!(division & 0x8000)) {
            if (division == 0) fail(12, "time division of 0 ticks per quarter note");
            score_.ppq = static_cast<int>(division);
            return;
        }
        // SMPTE: -fps in the high byte, ticks per frame in the low byte. Ticks then have a fixed
        // length, which a fixed tempo of one second per quarter expresses exactly, and tempo
        // events do not apply.
        const int fps = -static_cast<int>(static_cast<std::int8_t>(division >> 8));
        const int ticks_per_frame = static_cast<int>(division & 0xFF);
        if (fps != 24 && fps != 25 && fps != 29 && fps != 30)
            fail(12, fmt::format("bad SMPTE time division: {} frames per second", fps));
        if (ticks_per_frame == 0) fail(12, "bad SMPTE time division: 0 ticks per frame");
        smpte_ = true;
        // 29 stands for 29.97 drop-frame: 30 frames take 1.001 s.
        score_.ppq = (fps == 29 ? 30 : fps) * ticks_per_frame;
        score_.tempo.push_back(TempoChange{0, fps == 29 ? 1001000u : 1000000u});
    }

    void count_event(std::size_t at) {
        if (++events_ > limits_.max_events)
            fail(at, fmt::format("more than {} events (the limit)", limits_.max_events));
    }

    /// Reads a variable-length quantity of at most 4 bytes within [p, end).
    std::uint32_t vlq(std::size_t& p, std::size_t end) const {
        const std::size_t start = p;
        std::uint32_t value = 0;
        for (int i = 0; i < 4; ++i) {
            if (p >= end) fail(start, "truncated track chunk: an event runs past its end");
            const std::uint8_t b = data_[p++];
            value = value << 7 | (b & 0x7F);
            if (!(b & 0x80)) return value;
        }
        fail(start, "bad variable-length quantity (longer than 4 bytes)");
    }

    void read_track(std::size_t p, std::size_t end, int track) {
        std::int64_t tick = 0;
        std::uint8_t running = 0;
        std::size_t unmatched_offs = 0;
        while (p < end) {
            const std::size_t event_start = p;
            tick += vlq(p, end);
            count_event(event_start);
            if (p >= end) fail(event_start, "truncated track chunk: an event runs past its end");
            std::uint8_t status = data_[p];
            if (status & 0x80) {
                ++p;
            } else if (running) {
                status = running;
            } else {
                fail(p, fmt::format("data byte 0x{:02X} where a status byte was expected (no "
                                    "running status in effect)",
                                    status));
            }

            if (status < 0xF0) {
                running = status;
                const int count = (status & 0xE0) == 0xC0 ? 1 : 2;  // Cn, Dn carry one byte
                if (end - p < static_cast<std::size_t>(count))
                    fail(event_start, "truncated track chunk: an event runs past its end");
                std::uint8_t d[2] = {data_[p], count == 2 ? data_[p + 1] : std::uint8_t{0}};
                for (int i = 0; i < count; ++i)
                    if (d[i] & 0x80)
                        fail(p + i, fmt::format("bad data byte 0x{:02X} in a channel event", d[i]));
                p += count;
                channel_event(status, d[0], d[1], tick, track, unmatched_offs);
            } else if (status == 0xFF) {
                if (p >= end)
                    fail(event_start, "truncated track chunk: an event runs past its end");
                const std::uint8_t type = data_[p++];
                const std::uint32_t length = vlq(p, end);
                if (length > end - p)
                    fail(event_start, fmt::format("truncated track chunk: meta event of {} bytes "
                                                  "runs past its end",
                                                  length));
                if (type == 0x2F) {
                    p = end;  // end of track; anything after it is not part of the track
                    break;
                }
                meta_event(type, p, length, tick, event_start);
                p += length;
            } else if (status == 0xF0 || status == 0xF7) {
                const std::uint32_t length = vlq(p, end);
                if (length > end - p)
                    fail(event_start, fmt::format("truncated track chunk: sysex event of {} bytes "
                                                  "runs past its end",
                                                  length));
                p += length;
            } else {
                fail(p - 1, fmt::format("unexpected status byte 0x{:02X} in a track", status));
            }
        }

        score_.end_tick = std::max(score_.end_tick, tick);
        std::size_t unreleased = 0;
        for (std::size_t slot = 0; slot < open_.size(); ++slot) {
            while (!open_[slot].empty()) {
                const OpenNote n = open_[slot].pop();
                add_note(n, tick, static_cast<int>(slot % 128), track,
                         static_cast<int>(slot / 128));
                ++unreleased;
            }
        }
        if (unreleased > 0)
            warn(fmt::format("track {}: {} note(s) never released; they end with the track", track,
                             unreleased));
        if (unmatched_offs > 0)
            warn(fmt::format("track {}: {} note-off(s) without a sounding note ignored", track,
                             unmatched_offs));
    }

    void channel_event(std::uint8_t status, std::uint8_t d1, std::uint8_t d2, std::int64_t tick,
                       int track, std::size_t& unmatched_offs) {
        const int kind = status & 0xF0;
        const int channel = status & 0x0F;
        if (kind == 0x90 && d2 > 0) {
            open_[static_cast<std::size_t>(channel * 128 + d1)].items.push_back(OpenNote{tick, d2});
        } else if (kind == 0x80 || kind == 0x90) {
            OpenQueue& q = open_[static_cast<std::size_t>(channel * 128 + d1)];
            if (q.empty()) ++unmatched_offs;
            else add_note(q.pop(), tick, d1, track, channel);
        } else if (kind == 0xB0 && d1 == 64) {
            score_.pedal.push_back(PedalChange{tick, d2, track, channel});
        }
    }

    void add_note(const OpenNote& n, std::int64_t end, int key, int track, int channel) {
        score_.notes.push_back(TimedNote{n.start, end, key, n.velocity, track, channel});
    }

    void meta_event(std::uint8_t type, std::size_t p, std::uint32_t length, std::int64_t tick,
                    std::size_t event_start) {
        if (type == 0x51) {
            if (smpte_) return;  // SMPTE timing does not use tempo
            const std::uint32_t us = length == 3
                                         ? std::uint32_t{data_[p]} << 16 |
                                               std::uint32_t{data_[p + 1]} << 8 | data_[p + 2]
                                         : 0;
            if (us == 0) {
                warn(fmt::format("byte {}: bad tempo event ignored", event_start));
                return;
            }
            score_.tempo.push_back(TempoChange{tick, us});
        } else if (type == 0x58) {
            if (length < 2 || data_[p] == 0 || data_[p + 1] > 7) {
                warn(fmt::format("byte {}: bad time signature ignored", event_start));
                return;
            }
            score_.time_signatures.push_back(TimeSignature{tick, data_[p], 1 << data_[p + 1]});
        }
    }

    std::span<const std::uint8_t> data_;
    std::string_view file_;
    Warnings* warnings_;
    MidiLimits limits_;
    TimedScore score_;
    std::vector<OpenQueue> open_;  // per channel * 128 + key, reused across tracks
    std::size_t events_ = 0;
    bool smpte_ = false;
};

/// One event to write: its bytes, and where it sorts among events at the same tick.
struct OutEvent {
    std::int64_t tick;
    int order;  // 0 meta, 1 note-off, 2 pedal, 3 note-on
    std::uint8_t size;
    std::array<std::uint8_t, 7> bytes;
};

void put_vlq(std::vector<std::uint8_t>& out, std::uint32_t v) {
    std::uint8_t tmp[4];
    int n = 0;
    do {
        tmp[n++] = static_cast<std::uint8_t>(v & 0x7F);
        v >>= 7;
    } while (v && n < 4);
    while (n > 1) out.push_back(tmp[--n] | 0x80);
    out.push_back(tmp[0]);
}

[[noreturn]] void cannot_write(std::string_view why) {
    throw Error(fmt::format("cannot write MIDI: {}", why));
}

void check_range(std::string_view what, std::int64_t v, std::int64_t lo, std::int64_t hi) {
    if (v < lo || v > hi) cannot_write(fmt::format("{} {} outside {}..{}", what, v, lo, hi));
}

}  // namespace

bool is_midi(std::span<const std::uint8_t> bytes) {
    return bytes.size() >= 4 && std::memcmp(bytes.data(), "MThd", 4) == 0;
}

TimedScore read_midi(std::span<const std::uint8_t> bytes, std::string_view file, Warnings* warnings,
                     const MidiLimits& limits) {
    return MidiReader(bytes, file, warnings, limits).read();
}

std::vector<std::uint8_t> write_midi(const TimedScore& score) {
    check_range("ticks per quarter", score.ppq, 1, 0x7FFF);
    int last_track = 0;
    for (const TimedNote& n : score.notes) last_track = std::max(last_track, n.track);
    for (const PedalChange& p : score.pedal) last_track = std::max(last_track, p.track);
    check_range("track", last_track, 0, 0xFFFE);
    std::vector<std::vector<OutEvent>> tracks(static_cast<std::size_t>(last_track) + 1);

    auto add = [&](int track, std::int64_t tick, int order,
                   std::initializer_list<std::uint8_t> bytes) {
        check_range("tick", tick, 0, INT64_MAX);
        OutEvent e{tick, order, static_cast<std::uint8_t>(bytes.size()), {}};
        std::copy(bytes.begin(), bytes.end(), e.bytes.begin());
        tracks[static_cast<std::size_t>(track)].push_back(e);
    };
    for (const TempoChange& t : score.tempo) {
        check_range("tempo (microseconds per quarter)", t.us_per_quarter, 1, kMaxTempo);
        add(0, t.tick, 0,
            {0xFF, 0x51, 0x03, static_cast<std::uint8_t>(t.us_per_quarter >> 16),
             static_cast<std::uint8_t>(t.us_per_quarter >> 8),
             static_cast<std::uint8_t>(t.us_per_quarter)});
    }
    for (const TimeSignature& t : score.time_signatures) {
        check_range("time signature numerator", t.numerator, 1, 255);
        if (t.denominator < 1 || t.denominator > 128 ||
            !std::has_single_bit(static_cast<unsigned>(t.denominator)))
            cannot_write(
                fmt::format("time signature denominator {} is not a power of two "
                            "from 1 to 128",
                            t.denominator));
        // 24 MIDI clocks per metronome click and 8 32nd notes per quarter: the usual values.
        add(0, t.tick, 0,
            {0xFF, 0x58, 0x04, static_cast<std::uint8_t>(t.numerator),
             static_cast<std::uint8_t>(std::countr_zero(static_cast<unsigned>(t.denominator))), 24,
             8});
    }
    for (const TimedNote& n : score.notes) {
        check_range("key", n.key, 0, 127);
        check_range("velocity", n.velocity, 1, 127);
        check_range("channel", n.channel, 0, 15);
        check_range("track", n.track, 0, 0xFFFE);
        if (n.end <= n.start)
            cannot_write(fmt::format("note {} at tick {} ends at tick {}", n.key, n.start, n.end));
        const auto on = static_cast<std::uint8_t>(0x90 | n.channel);
        const auto key = static_cast<std::uint8_t>(n.key);
        add(n.track, n.start, 3, {on, key, static_cast<std::uint8_t>(n.velocity)});
        add(n.track, n.end, 1, {on, key, 0});
    }
    for (const PedalChange& p : score.pedal) {
        check_range("pedal value", p.value, 0, 127);
        check_range("channel", p.channel, 0, 15);
        check_range("track", p.track, 0, 0xFFFE);
        add(p.track, p.tick, 2,
            {static_cast<std::uint8_t>(0xB0 | p.channel), 64, static_cast<std::uint8_t>(p.value)});
    }

    std::int64_t end_tick = score.end_tick;
    for (const auto& events : tracks)
        for (const OutEvent& e : events) end_tick = std::max(end_tick, e.tick);

    std::vector<std::uint8_t> out = {'M', 'T', 'h', 'd', 0, 0, 0, 6, 0, 1};
    out.push_back(static_cast<std::uint8_t>(tracks.size() >> 8));
    out.push_back(static_cast<std::uint8_t>(tracks.size()));
    out.push_back(static_cast<std::uint8_t>(score.ppq >> 8));
    out.push_back(static_cast<std::uint8_t>(score.ppq));
    for (std::size_t t = 0; t < tracks.size(); ++t) {
        auto& events = tracks[t];
        // Stable: pedal changes at one tick keep their order, and so do notes (sorted by key).
        std::stable_sort(events.begin(), events.end(), [](const OutEvent& a, const OutEvent& b) {
            return a.tick != b.tick ? a.tick < b.tick : a.order < b.order;
        });
        out.insert(out.end(), {'M', 'T', 'r', 'k', 0, 0, 0, 0});
        const std::size_t length_at = out.size() - 4;
        std::int64_t tick = 0;
        std::uint8_t running = 0;
        for (const OutEvent& e : events) {
            const std::int64_t delta = e.tick - tick;
            if (delta > kMaxDelta)
                cannot_write(
                    fmt::format("{} ticks between two events of track {} exceed the "
                                "limit of {}",
                                delta, t, kMaxDelta));
            put_vlq(out, static_cast<std::uint32_t>(delta));
            tick = e.tick;
            const bool channel_event = e.bytes[0] < 0xF0;
            const int skip = channel_event && e.bytes[0] == running ? 1 : 0;
            out.insert(out.end(), e.bytes.begin() + skip, e.bytes.begin() + e.size);
            // Meta events cancel running status in the standard; honour that for strict readers.
            running = channel_event ? e.bytes[0] : 0;
        }
        // Every track ends with the piece, keeping a final rest (and the tracks' common end).
        const std::int64_t last = end_tick - tick;
        if (last > kMaxDelta)
            cannot_write(fmt::format("{} ticks before the end of track {} exceed the limit of {}",
                                     last, t, kMaxDelta));
        put_vlq(out, static_cast<std::uint32_t>(last));
        out.insert(out.end(), {0xFF, 0x2F, 0x00});
        const std::size_t length = out.size() - length_at - 4;
        if (length > 0xFFFFFFFFu) cannot_write(fmt::format("track {} is longer than 4 GiB", t));
        for (int i = 0; i < 4; ++i)
            out[length_at + static_cast<std::size_t>(i)] =
                static_cast<std::uint8_t>(length >> (24 - 8 * i));
    }
    return out;
}

}  // namespace toonray
