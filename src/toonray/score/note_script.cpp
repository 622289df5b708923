#include "toonray/score/note_script.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fmt/format.h>
#include <map>
#include <numeric>
#include <utility>
#include <vector>

#include "toonray/core/limits.h"
#include "toonray/score/piano_keys.h"

namespace toonray {
namespace {

/// Times past this are refused, which keeps every sum of ticks far from overflowing yet admits
/// anything a MIDI file within MidiLimits can reach (10^7 events * 2^28 ticks < 2^52).
constexpr std::int64_t kMaxTick = std::int64_t{1} << 52;
constexpr std::int64_t kMaxTicksTerm = 0x7FFFFFFF;

/// Duration letters, longest first, with how many of them make a whole note.
constexpr std::pair<char, int> kLetters[] = {{'W', 1},  {'H', 2},  {'Q', 4}, {'E', 8},
                                             {'S', 16}, {'T', 32}, {'X', 64}};
constexpr int kMaxDots = 3;

inline bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
    while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
    return s;
}

/// Splits on `sep`, keeping empty pieces (callers report them).
std::vector<std::string_view> split(std::string_view s, char sep) {
    std::vector<std::string_view> parts;
    while (true) {
        std::size_t cut = s.find(sep);
        parts.push_back(s.substr(0, cut));
        if (cut == std::string_view::npos) return parts;
        s.remove_prefix(cut + 1);
    }
}

template <typename T>
bool parse_int(std::string_view s, T& value) {
    if (s.empty() || !(s.front() >= '0' && s.front() <= '9')) return false;
    auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
    return ec == std::errc() && ptr == s.data() + s.size();
}

bool iequals(std::string_view a, std::string_view b) {
    return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
               return (x | 0x20) == (y | 0x20);
           });
}

/// Ticks of a letter with dots, or 0 when that is not a whole number of ticks at `ppq`.
std::int64_t letter_ticks(int per_whole, int dots, int ppq) {
    // A dotted value is base * (2 - 2^-dots) = 4 ppq (2^(dots+1) - 1) / (per_whole 2^dots).
    const std::int64_t num = std::int64_t{4} * ppq * ((std::int64_t{2} << dots) - 1);
    const std::int64_t den = std::int64_t{per_whole} << dots;
    return num % den == 0 ? num / den : 0;
}

std::uint32_t tempo_from_bpm(double bpm) {
    const double us = std::round(60e6 / bpm);
    return us >= 1 && us <= 0xFFFFFF ? static_cast<std::uint32_t>(us) : 0;
}

class ScriptParser {
public:
    ScriptParser(std::string_view file, Warnings* warnings) : file_(file), warnings_(warnings) {
        score_.ppq = kScriptDefaultPpq;
        score_.tempo.push_back(TempoChange{0, kScriptDefaultTempo});
    }

    TimedScore parse(std::string_view text) {
        if (text.size() >= 3 && std::memcmp(text.data(), "\xEF\xBB\xBF", 3) == 0)
            text.remove_prefix(3);
        if (const std::size_t nul = text.find('\0'); nul != std::string_view::npos) {
            line_ =
                1 + static_cast<std::size_t>(std::count(text.begin(), text.begin() + nul, '\n'));
            fail(
                "binary data (NUL byte): neither a note script nor a MIDI file (no \"MThd\" header)");
        }
        while (!text.empty()) {
            ++line_;
            std::size_t nl = text.find('\n');
            std::string_view line = text.substr(0, nl);
            text.remove_prefix(nl == std::string_view::npos ? text.size() : nl + 1);
            if (std::size_t hash = line.find('#'); hash != std::string_view::npos)
                line = line.substr(0, hash);
            line = trim(line);
            if (!line.empty()) parse_line(line);
        }
        // Every line takes a step, so trailing "Empty" lines are a final rest.
        for (const auto& [voice, tick] : cursors_)
            score_.end_tick = std::max(score_.end_tick, tick);
        normalize(score_, kScriptDefaultTempo, warnings_, file_);
        return std::move(score_);
    }

private:
    [[noreturn]] void fail(std::string_view message) const { throw_at(file_, line_, message); }

    std::int64_t& cursor() { return cursors_[{track_, channel_}]; }

    void advance(std::int64_t ticks) {
        std::int64_t& c = cursor();
        if (ticks > kMaxTick - c) fail("the score runs past the longest supported time");
        c += ticks;
    }

    std::int64_t step() {
        if (step_ > 0) return step_;
        if (score_.ppq % 2 != 0)
            fail(
                fmt::format("a line is an eighth note by default, which is not a whole number "
                            "of ticks at ppq {}; set 'step'",
                            score_.ppq));
        return score_.ppq / 2;
    }

    void parse_line(std::string_view line) {
        const std::size_t word_end = std::min(line.find_first_of(" \t\f\v\r:"), line.size());
        const std::string_view word = line.substr(0, word_end);
        const std::string_view rest = trim(line.substr(word_end));
        const bool lower_word =
            std::all_of(word.begin(), word.end(), [](char c) { return c >= 'a' && c <= 'z'; });

        if (word == "ppq") {
            if (started_) fail("'ppq' must come before every other line");
            score_.ppq = int_argument(word, rest, 1, 0x7FFF);
            started_ = true;
            return;
        }
        started_ = true;
        if (iequals(line, "Empty")) {
            advance(step());
        } else if (lower_word && !word.empty() && (rest.empty() || rest.front() != ':')) {
            directive(word, rest);
        } else if (iequals(word, "Empty")) {
            fail("'Empty' takes nothing after it");
        } else {
            note_line(line);
        }
    }

    int int_argument(std::string_view directive, std::string_view arg, int lo, int hi) const {
        int v = 0;
        if (arg.empty()) fail(fmt::format("'{}' needs a number", directive));
        if (arg.find_first_of(" \t") != std::string_view::npos)
            fail(fmt::format("'{}' takes one value, got '{}'", directive, arg));
        if (!parse_int(arg, v) || v < lo || v > hi)
            fail(fmt::format("bad value '{}' for '{}': expected a whole number from {} to {}", arg,
                             directive, lo, hi));
        return v;
    }

    void one_argument(std::string_view directive, std::string_view arg) const {
        if (arg.empty()) fail(fmt::format("'{}' needs a value", directive));
        if (arg.find_first_of(" \t") != std::string_view::npos)
            fail(fmt::format("'{}' takes one value, got '{}'", directive, arg));
    }

    void directive(std::string_view word, std::string_view arg) {
        if (word == "tempo") {
            one_argument(word, arg);
            score_.tempo.push_back(TempoChange{cursor(), parse_tempo(arg)});
        } else if (word == "time") {
            one_argument(word, arg);
            std::size_t slash = arg.find('/');
            int num = 0, den = 0;
            if (slash == std::string_view::npos || !parse_int(arg.substr(0, slash), num) ||
                !parse_int(arg.substr(slash + 1), den))
                fail(fmt::format("bad time signature '{}': expected N/D such as 2/4", arg));
            if (num < 1 || num > 255 || den < 1 || den > 128 || (den & (den - 1)) != 0)
                fail(
                    fmt::format("bad time signature '{}': N is 1..255 and D a power of two "
                                "from 1 to 128",
                                arg));
            score_.time_signatures.push_back(TimeSignature{cursor(), num, den});
        } else if (word == "step") {
            one_argument(word, arg);
            step_ = duration(arg);
        } else if (word == "wait") {
            one_argument(word, arg);
            advance(duration(arg));
        } else if (word == "velocity") {
            velocity_ = int_argument(word, arg, 1, 127);
        } else if (word == "track") {
            track_ = int_argument(word, arg, 0, kScriptMaxTrack);
        } else if (word == "channel") {
            channel_ = int_argument(word, arg, 1, 16) - 1;
        } else if (word == "pedal") {
            int value = 0;
            if (arg == "down") value = 127;
            else if (arg == "up") value = 0;
            else if (!parse_int(arg, value) || value > 127)
                fail(fmt::format("bad pedal value '{}': expected down, up or 0..127", arg));
            score_.pedal.push_back(PedalChange{cursor(), value, track_, channel_});
        } else if (word == "ppq") {
            fail("'ppq' must come before every other line");
        } else {
            fail(
                fmt::format("unknown directive '{}' (known: ppq, tempo, time, step, wait, "
                            "velocity, track, channel, pedal)",
                            word));
        }
    }

    std::uint32_t parse_tempo(std::string_view arg) const {
        if (arg.size() > 2 && arg.substr(arg.size() - 2) == "us") {
            std::uint32_t us = 0;
            if (!parse_int(arg.substr(0, arg.size() - 2), us) || us < 1 || us > 0xFFFFFF)
                fail(fmt::format("bad tempo '{}': microseconds per quarter are 1..16777215", arg));
            return us;
        }
        double bpm = 0;
        auto [ptr, ec] = std::from_chars(arg.data(), arg.data() + arg.size(), bpm);
        if (ec != std::errc() || ptr != arg.data() + arg.size() || !std::isfinite(bpm) ||
            !(bpm > 0))
            fail(
                fmt::format("bad tempo '{}': expected quarter notes per minute (such as 72) or "
                            "microseconds per quarter (such as 833333us)",
                            arg));
        std::uint32_t us = tempo_from_bpm(bpm);
        if (us == 0) fail(fmt::format("tempo {} is out of range (3.58 to 60000000 bpm)", arg));
        return us;
    }

    /// Terms joined by '+' (a tie); a term is a letter with optional dots, or ticks.
    std::int64_t duration(std::string_view text) const {
        if (text.empty()) fail("missing duration");
        std::int64_t total = 0;
        for (std::string_view term : split(text, '+')) {
            term = trim(term);
            std::int64_t ticks = 0;
            if (term.empty()) fail(fmt::format("malformed duration '{}'", text));
            if (term.front() >= '0' && term.front() <= '9') {
                if (!parse_int(term, ticks) || ticks < 1 || ticks > kMaxTicksTerm)
                    fail(fmt::format("bad duration '{}': ticks are 1..{}", term, kMaxTicksTerm));
            } else {
                const auto* letter = std::find_if(std::begin(kLetters), std::end(kLetters),
                                                  [&](auto l) { return l.first == term.front(); });
                const std::string_view dots = term.substr(1);
                if (letter == std::end(kLetters) ||
                    dots.find_first_not_of('.') != std::string_view::npos)
                    fail(
                        fmt::format("unknown duration '{}' (use W, H, Q, E, S, T or X for whole "
                                    "to 64th notes, dots as in 'Q.', '+' to tie, or ticks)",
                                    term));
                if (dots.size() > kMaxDots)
                    fail(fmt::format("too many dots in '{}' (at most {})", term, kMaxDots));
                ticks = letter_ticks(letter->second, static_cast<int>(dots.size()), score_.ppq);
                if (ticks == 0)
                    fail(fmt::format("duration '{}' is not a whole number of ticks at ppq {}", term,
                                     score_.ppq));
            }
            total += ticks;
            if (total > kMaxTick) fail(fmt::format("duration '{}' is too long", text));
        }
        return total;
    }

    int key(std::string_view token) const {
        const char kind = token.empty() ? '\0' : token.front();
        int n = -1;
        const bool numbered = (kind == 'w' || kind == 'b' || kind == 'm') && token.size() > 1 &&
                              std::all_of(token.begin() + 1, token.end(),
                                          [](char c) { return c >= '0' && c <= '9'; });
        if (!numbered)
            fail(fmt::format("unknown key '{}' (keys are w1..w52, b1..b36 or m0..m127)", token));
        if (!parse_int(token.substr(1), n)) n = -1;  // too many digits
        if (kind == 'w') {
            const int midi = white_key(n);
            if (midi < 0) fail(fmt::format("unknown key '{}': white keys are w1..w52", token));
            return midi;
        }
        if (kind == 'b') {
            const int midi = black_key(n);
            if (midi < 0) fail(fmt::format("unknown key '{}': black keys are b1..b36", token));
            return midi;
        }
        if (n < 0 || n > 127) fail(fmt::format("unknown key '{}': MIDI keys are m0..m127", token));
        return n;
    }

    void note_line(std::string_view line) {
        const std::int64_t start = cursor();
        for (std::string_view group : split(line, '|')) {
            group = trim(group);
            if (group.empty()) fail(fmt::format("empty note group in '{}'", line));
            const std::size_t colon = group.find(':');
            if (colon == std::string_view::npos)
                fail(
                    fmt::format("malformed note group '{}': expected DURATION:KEYS such as "
                                "'E:w26,w28,w30'",
                                group));
            const std::int64_t length = duration(trim(group.substr(0, colon)));
            if (length > kMaxTick - start) fail("the score runs past the longest supported time");
            const std::string_view keys = trim(group.substr(colon + 1));
            if (keys.empty()) fail(fmt::format("no keys after ':' in '{}'", group));
            for (std::string_view token : split(keys, ',')) {
                token = trim(token);
                if (token.empty()) fail(fmt::format("missing key in '{}'", group));
                int velocity = velocity_;
                if (std::size_t at = token.find('@'); at != std::string_view::npos) {
                    const std::string_view v = trim(token.substr(at + 1));
                    if (!parse_int(v, velocity) || velocity < 1 || velocity > 127)
                        fail(fmt::format("bad velocity in '{}': expected 1..127 after '@'", token));
                    token = trim(token.substr(0, at));
                }
                if (score_.notes.size() >= limits().max_notes)
                    fail(fmt::format("more than {} notes (the limit)", limits().max_notes));
                score_.notes.push_back(
                    TimedNote{start, start + length, key(token), velocity, track_, channel_});
            }
        }
        advance(step());
    }

    std::string_view file_;
    Warnings* warnings_;
    std::size_t line_ = 0;
    TimedScore score_;
    bool started_ = false;
    std::int64_t step_ = 0;  // 0: an eighth note, resolved when first used
    int velocity_ = kScriptDefaultVelocity;
    int track_ = 0;
    int channel_ = 0;
    std::map<std::pair<int, int>, std::int64_t> cursors_;
};

// ---- writing ----

/// A duration as the script writes it: one letter with dots, else a tie of up to four
/// letters, else ticks.
std::string duration_text(std::int64_t ticks, int ppq) {
    for (auto [letter, per_whole] : kLetters)
        for (int dots = 0; dots <= kMaxDots; ++dots)
            if (letter_ticks(per_whole, dots, ppq) == ticks)
                return std::string(1, letter) + std::string(static_cast<std::size_t>(dots), '.');
    std::string tie;
    std::int64_t left = ticks;
    for (int terms = 0; terms < 4 && left > 0; ++terms) {
        const auto* it = std::find_if(std::begin(kLetters), std::end(kLetters), [&](auto l) {
            const std::int64_t t = letter_ticks(l.second, 0, ppq);
            return t > 0 && t <= left;
        });
        if (it == std::end(kLetters)) break;
        if (!tie.empty()) tie += '+';
        tie += it->first;
        left -= letter_ticks(it->second, 0, ppq);
    }
    return left == 0 ? tie : fmt::format("{}", ticks);
}

/// Quarter notes per minute when a short decimal reads back as exactly `us`, else "<us>us".
std::string tempo_text(std::uint32_t us) {
    for (int decimals = 0; decimals <= 3; ++decimals) {
        std::string text = fmt::format("{:.{}f}", 60e6 / us, decimals);
        double bpm = 0;
        std::from_chars(text.data(), text.data() + text.size(), bpm);
        if (bpm > 0 && tempo_from_bpm(bpm) == us) return text;
    }
    return fmt::format("{}us", us);
}

std::string pedal_text(int value) {
    if (value == 127) return "down";
    if (value == 0) return "up";
    return fmt::format("{}", value);
}

/// What happens at one tick of one section.
struct Moment {
    std::vector<const TempoChange*> tempo;
    std::vector<const TimeSignature*> time;
    std::vector<const PedalChange*> pedal;
    std::vector<const TimedNote*> notes;
};

}  // namespace

TimedScore parse_note_script(std::string_view text, std::string_view file, Warnings* warnings) {
    return ScriptParser(file, warnings).parse(text);
}

std::string write_note_script(const TimedScore& score) {
    const int ppq = score.ppq;
    std::string out =
        "# toonray note script (docs/scores.md): one line per step, DURATION:KEYS groups\n";
    out += fmt::format("ppq {}\n", ppq);

    // Sections, one per track and channel; the tempo map and time signatures go in the first.
    std::map<std::pair<int, int>, std::map<std::int64_t, Moment>> sections;
    for (const TimedNote& n : score.notes)
        sections[{n.track, n.channel}][n.start].notes.push_back(&n);
    for (const PedalChange& p : score.pedal)
        sections[{p.track, p.channel}][p.tick].pedal.push_back(&p);
    auto& first = sections.empty() ? sections[{0, 0}] : sections.begin()->second;
    // Without a tempo at tick 0 a MIDI player uses its default; the script's default differs.
    static const TempoChange midi_default{0, kMidiDefaultTempo};
    if (score.tempo.empty() || score.tempo.front().tick != 0)
        first[0].tempo.push_back(&midi_default);
    for (const TempoChange& t : score.tempo) first[t.tick].tempo.push_back(&t);
    for (const TimeSignature& t : score.time_signatures) first[t.tick].time.push_back(&t);

    // The piece's end must fall on every section's grid, so that no section's last line runs
    // past it and the last section can rest up to it exactly.
    std::int64_t end_tick = score.end_tick;
    for (const TimedNote& n : score.notes) end_tick = std::max(end_tick, n.end);
    for (auto& [voice, moments] : sections)
        if (!moments.empty()) end_tick = std::max(end_tick, moments.rbegin()->first);

    int track = 0, channel = 0, velocity = kScriptDefaultVelocity;
    std::int64_t step = ppq % 2 == 0 ? ppq / 2 : 0;
    for (auto& [voice, moments] : sections) {
        if (voice.first != track) out += fmt::format("track {}\n", track = voice.first);
        if (voice.second != channel)
            out += fmt::format("channel {}\n", (channel = voice.second) + 1);

        // The most common velocity becomes the default; the others are written per note.
        std::map<int, std::size_t> counts;
        for (auto& [tick, m] : moments)
            for (const TimedNote* n : m.notes) ++counts[n->velocity];
        if (!counts.empty()) {
            int common = std::max_element(counts.begin(), counts.end(), [](auto a, auto b) {
                             return a.second < b.second;
                         })->first;
            if (common != velocity) out += fmt::format("velocity {}\n", velocity = common);
        }

        // The longest step (up to a whole note) that puts every event on a line.
        std::int64_t g = std::gcd(4 * std::int64_t{ppq}, end_tick);
        for (auto& [tick, m] : moments) g = std::gcd(g, tick);
        if (g != step) out += fmt::format("step {}\n", duration_text(step = g, ppq));

        std::int64_t cursor = 0;
        auto rest_until = [&](std::int64_t tick) {
            const std::int64_t empty_steps = (tick - cursor) / step;
            if (empty_steps <= 3) {
                for (std::int64_t i = 0; i < empty_steps; ++i) out += "Empty\n";
            } else {
                // A tick count in a duration is at most kMaxTicksTerm; longer rests take more.
                for (std::int64_t left = tick - cursor; left > 0;) {
                    const std::int64_t wait = std::min(left, kMaxTicksTerm);
                    out += fmt::format("wait {}\n", duration_text(wait, ppq));
                    left -= wait;
                }
            }
            cursor = tick;
        };
        for (auto& [tick, m] : moments) {
            rest_until(tick);
            for (const TempoChange* t : m.tempo)
                out += fmt::format("tempo {}\n", tempo_text(t->us_per_quarter));
            for (const TimeSignature* t : m.time)
                out += fmt::format("time {}/{}\n", t->numerator, t->denominator);
            for (const PedalChange* p : m.pedal)
                out += fmt::format("pedal {}\n", pedal_text(p->value));
            if (m.notes.empty()) continue;

            // Groups by length, shortest first; keys ascending within a group.
            std::stable_sort(m.notes.begin(), m.notes.end(),
                             [](const TimedNote* a, const TimedNote* b) {
                                 return std::pair(a->end - a->start, a->key) <
                                        std::pair(b->end - b->start, b->key);
                             });
            std::string line;
            for (std::size_t i = 0; i < m.notes.size(); ++i) {
                const TimedNote& n = *m.notes[i];
                const std::int64_t length = n.end - n.start;
                if (i == 0 || length != m.notes[i - 1]->end - m.notes[i - 1]->start) {
                    if (i > 0) line += '|';
                    line += duration_text(length, ppq);
                    line += ':';
                } else {
                    line += ',';
                }
                line += key_name(n.key);
                if (n.velocity != velocity) line += fmt::format("@{}", n.velocity);
            }
            out += line;
            out += '\n';
            cursor = tick + step;
        }
        if (voice == sections.rbegin()->first) rest_until(end_tick);
    }
    return out;
}

}  // namespace toonray
