#include "toonray/media/audio.h"


#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fmt/format.h>
#include <limits>
#include <memory>
#include <mutex>
#include <numbers>
#include <vector>

#include "toonray/media/fluidsynth_library.h"

namespace toonray {

namespace {

// FluidSynth reports problems through a process-wide log callback. We route them to whichever
// render is running on this thread, so an error loading a SoundFont ends up in our Error message
// instead of on stderr, and warnings end up in AudioResult::warnings.
thread_local std::vector<std::string>* tl_fluid_messages = nullptr;

void fluid_log_to_collector(int level, const char* message, void*) {
    if (level > FLUID_WARN) return;  // info and debug chatter
    if (tl_fluid_messages) {
        tl_fluid_messages->emplace_back(message);
    } else {
        std::fprintf(stderr, "fluidsynth: %s\n", message);
    }
}

void install_fluid_logging() {
    static std::once_flag once;
    std::call_once(once, [] {
        for (int level = FLUID_PANIC; level < LAST_LOG_LEVEL; ++level)
            fluidsynth().fluid_set_log_function(level, fluid_log_to_collector, nullptr);
    });
}

/// Sets tl_fluid_messages for the lifetime of one render.
class FluidMessageScope {
public:
    explicit FluidMessageScope(std::vector<std::string>* messages) : saved_(tl_fluid_messages) {
        tl_fluid_messages = messages;
    }
    ~FluidMessageScope() { tl_fluid_messages = saved_; }
    FluidMessageScope(const FluidMessageScope&) = delete;
    FluidMessageScope& operator=(const FluidMessageScope&) = delete;

private:
    std::vector<std::string>* saved_;
};

struct SettingsDeleter {
    void operator()(fluid_settings_t* s) const { fluidsynth().delete_fluid_settings(s); }
};
struct SynthDeleter {
    void operator()(fluid_synth_t* s) const { fluidsynth().delete_fluid_synth(s); }
};

std::string joined(const std::vector<std::string>& messages) {
    std::string out;
    for (const std::string& m : messages) {
        if (!out.empty()) out += "; ";
        out += m;
    }
    return out;
}

/// Checks the file before FluidSynth sees it: FluidSynth's own failure is a bare "not a
/// SoundFont" on its log, without saying whether the file was missing.
void check_soundfont_file(const std::filesystem::path& path) {
    std::error_code ec;
    auto status = std::filesystem::status(path, ec);
    if (!std::filesystem::exists(status))
        throw Error(fmt::format(
            "{}: SoundFont not found{}", path.string(),
            path == default_soundfont()
                ? " (the default SoundFont, installed by the Debian package fluid-soundfont-gm)"
                : ""));
    if (!std::filesystem::is_regular_file(status))
        throw Error(fmt::format("{}: SoundFont is not a regular file", path.string()));
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f)
        throw Error(
            fmt::format("{}: cannot open SoundFont: {}", path.string(), std::strerror(errno)));
    std::array<char, 12> header{};
    std::size_t n = std::fread(header.data(), 1, header.size(), f);
    std::fclose(f);
    if (n != header.size() || std::memcmp(header.data(), "RIFF", 4) != 0 ||
        std::memcmp(header.data() + 8, "sfbk", 4) != 0)
        throw Error(fmt::format("{}: not a SoundFont 2 file (no RIFF sfbk header)", path.string()));
    // A truncated download is the common way to get a bad .sf2; FluidSynth would then hand it to
    // its DLS loader, whose complaints are less clear than this.
    const std::uint64_t riff_size =
        static_cast<std::uint8_t>(header[4]) | static_cast<std::uint8_t>(header[5]) << 8 |
        static_cast<std::uint8_t>(header[6]) << 16 |
        static_cast<std::uint64_t>(static_cast<std::uint8_t>(header[7])) << 24;
    const std::uint64_t file_size = std::filesystem::file_size(path, ec);
    if (!ec && riff_size + 8 != file_size)
        throw Error(
            fmt::format("{}: SoundFont is truncated or corrupt (its header says {} bytes, "
                        "the file has {})",
                        path.string(), riff_size + 8, file_size));
}

/// One thing to tell the synthesiser, at a sample of the output.
struct SynthEvent {
    enum Kind { NoteOff = 0, Pedal = 1, NoteOn = 2 };  // order within one sample
    std::int64_t sample;
    Kind kind;
    int key;    ///< MIDI key, or the CC64 value for Pedal
    int value;  ///< velocity for NoteOn

    bool operator<(const SynthEvent& o) const {
        if (sample != o.sample) return sample < o.sample;
        if (kind != o.kind) return kind < o.kind;
        return key < o.key;
    }
};

/// Seconds to a sample index. Rounding to nearest is what "the exact sample" means here; the
/// times come from a MIDI tick grid and are not sample-aligned anyway.
std::int64_t to_sample(double seconds, int rate) {
    return static_cast<std::int64_t>(std::llround(seconds * rate));
}

double score_end(const Score& score) {
    double end = 0.0;
    for (const Note& n : score.notes) end = std::max({end, n.start, n.end});
    for (const PedalEvent& p : score.sustain) end = std::max(end, p.time);
    return end;
}

void validate(const Score& score, const AudioOptions& o) {
    if (o.sample_rate < 8000 || o.sample_rate > 192000)
        throw Error(fmt::format("audio: sample rate {} outside 8000..192000", o.sample_rate));
    if (!std::isfinite(o.start) || o.start < 0)
        throw Error(fmt::format("audio: start {} s must be a finite time >= 0", o.start));
    if (o.length && (!std::isfinite(*o.length) || *o.length <= 0))
        throw Error(fmt::format("audio: length {} s must be positive", *o.length));
    if (!std::isfinite(o.tail) || o.tail < 0)
        throw Error(fmt::format("audio: tail {} s must be >= 0", o.tail));
    if (!std::isfinite(o.fade) || o.fade < 0)
        throw Error(fmt::format("audio: fade {} s must be >= 0", o.fade));
    if (!std::isfinite(o.gain) || o.gain <= 0 || o.gain > 10)
        throw Error(fmt::format("audio: gain {} outside (0, 10]", o.gain));
    if (o.bank < 0 || o.bank > 16383 || o.program < 0 || o.program > 127)
        throw Error(
            fmt::format("audio: bank {} / program {} out of MIDI range", o.bank, o.program));
    for (std::size_t i = 0; i < score.notes.size(); ++i) {
        const Note& n = score.notes[i];
        if (!std::isfinite(n.start) || !std::isfinite(n.end) || n.start < 0)
            throw Error(fmt::format("audio: note {} (key {}) has an invalid time {} .. {}", i,
                                    n.key, n.start, n.end));
        if (n.key < 0 || n.key > 127)
            throw Error(fmt::format("audio: note {} at {:.3f} s has key {} outside MIDI 0..127", i,
                                    n.start, n.key));
    }
    for (const PedalEvent& p : score.sustain)
        if (!std::isfinite(p.time))
            throw Error("audio: sustain pedal event with a non-finite time");
}

/// Selects bank/program from our SoundFont on channel 0; falls back to its first preset (with a
/// warning) so a single-instrument piano SoundFont works without knowing its preset number.
std::string select_preset(fluid_synth_t* synth, int sfont_id, const AudioOptions& o,
                          const std::filesystem::path& path, Warnings& warnings) {
    const FluidSynthLibrary& fs = fluidsynth();
    fluid_sfont_t* sfont = fs.fluid_synth_get_sfont_by_id(synth, sfont_id);
    if (!sfont) throw Error(fmt::format("{}: SoundFont vanished after loading", path.string()));
    if (fluid_preset_t* p = fs.fluid_sfont_get_preset(sfont, o.bank, o.program)) {
        fs.fluid_synth_program_select(synth, 0, sfont_id, o.bank, o.program);
        return fs.fluid_preset_get_name(p);
    }
    fs.fluid_sfont_iteration_start(sfont);
    fluid_preset_t* first = fs.fluid_sfont_iteration_next(sfont);
    if (!first) throw Error(fmt::format("{}: SoundFont has no presets", path.string()));
    const int bank = fs.fluid_preset_get_banknum(first), program = fs.fluid_preset_get_num(first);
    std::string name = fs.fluid_preset_get_name(first);
    warnings.push_back(
        fmt::format("{}: no preset at bank {} program {}; using '{}' (bank {} "
                    "program {})",
                    path.string(), o.bank, o.program, name, bank, program));
    fs.fluid_synth_program_select(synth, 0, sfont_id, bank, program);
    return name;
}

}  // namespace

std::filesystem::path default_soundfont() { return "/usr/share/sounds/sf2/FluidR3_GM.sf2"; }

AudioResult synthesize_score(const Score& score, const AudioOptions& options) {
    validate(score, options);
    const int rate = options.sample_rate;
    const std::filesystem::path sf_path =
        options.soundfont.empty() ? default_soundfont() : options.soundfont;

    // --- Events, in output samples. ---
    const double window_start = options.start;
    const double window_end =
        options.length ? window_start + *options.length : std::numeric_limits<double>::infinity();
    std::vector<SynthEvent> events;
    AudioResult result;
    double last_end = window_start;  // score time at which the last played note ends
    for (const Note& n : score.notes) {
        if (n.start < window_start || n.start >= window_end) continue;
        const std::int64_t on = to_sample(n.start - window_start, rate);
        // A note always lasts at least one sample so its off sorts after its on.
        const std::int64_t off = std::max(on + 1, to_sample(n.end - window_start, rate));
        const int velocity = std::clamp(n.velocity, 1, 127);
        events.push_back({on, SynthEvent::NoteOn, n.key, velocity});
        events.push_back({off, SynthEvent::NoteOff, n.key, 0});
        last_end = std::max(last_end, n.end);
        ++result.notes;
    }
    if (result.notes == 0) {
        if (score.notes.empty()) throw Error("audio: the score has no notes");
        auto [first, last] =
            std::minmax_element(score.notes.begin(), score.notes.end(),
                                [](const Note& a, const Note& b) { return a.start < b.start; });
        throw Error(
            fmt::format("audio: no notes start in the window {:.3f} .. {:.3f} s (the "
                        "score's notes start at {:.3f} .. {:.3f} s)",
                        window_start, window_end, first->start, last->start));
    }
    // The pedal as it stands at the window start, then its changes inside the window.
    bool pedal_down = false;
    for (const PedalEvent& p : score.sustain)
        if (p.time <= window_start) pedal_down = p.down;
    if (pedal_down) events.push_back({0, SynthEvent::Pedal, 127, 0});
    for (const PedalEvent& p : score.sustain) {
        if (p.time <= window_start || p.time >= window_end) continue;
        events.push_back(
            {to_sample(p.time - window_start, rate), SynthEvent::Pedal, p.down ? 127 : 0, 0});
        last_end = std::max(last_end, p.time);
    }
    std::sort(events.begin(), events.end());

    const std::int64_t total =
        options.length
            ? to_sample(*options.length, rate)
            : to_sample(std::max(last_end, score_end(score)) - window_start + options.tail, rate);

    // --- The synthesiser. ---
    install_fluid_logging();
    const FluidSynthLibrary& fs = fluidsynth();
    std::vector<std::string> messages;
    FluidMessageScope scope(&messages);
    check_soundfont_file(sf_path);

    std::unique_ptr<fluid_settings_t, SettingsDeleter> settings(fs.new_fluid_settings());
    if (!settings) throw Error("audio: FluidSynth could not create its settings");
    fs.fluid_settings_setnum(settings.get(), "synth.sample-rate", rate);
    fs.fluid_settings_setnum(settings.get(), "synth.gain", options.gain);
    fs.fluid_settings_setint(settings.get(), "synth.reverb.active", options.reverb ? 1 : 0);
    fs.fluid_settings_setint(settings.get(), "synth.chorus.active", 0);
    // One rendering thread: FluidSynth's parallel voice mixing is not needed offline, and a
    // single thread keeps the output independent of scheduling.
    fs.fluid_settings_setint(settings.get(), "synth.cpu-cores", 1);
    // Load only the samples the selected preset uses (a few MB of FluidR3's 148 MB).
    fs.fluid_settings_setint(settings.get(), "synth.dynamic-sample-loading", 1);
    fs.fluid_settings_setint(settings.get(), "synth.polyphony", 256);

    std::unique_ptr<fluid_synth_t, SynthDeleter> synth(fs.new_fluid_synth(settings.get()));
    if (!synth) throw Error(fmt::format("audio: FluidSynth could not start: {}", joined(messages)));
    messages.clear();
    const int sfont_id = fs.fluid_synth_sfload(synth.get(), sf_path.c_str(), 1);
    if (sfont_id == FLUID_FAILED)
        throw Error(fmt::format("{}: FluidSynth could not load the SoundFont{}{}", sf_path.string(),
                                messages.empty() ? "" : ": ", joined(messages)));
    result.preset = select_preset(synth.get(), sfont_id, options, sf_path, result.warnings);

    // --- Render, splitting blocks at event samples. ---
    result.audio.sample_rate = rate;
    result.audio.channels = 2;
    result.audio.samples.resize(static_cast<std::size_t>(total) * 2);
    const std::int64_t fade_len = std::min<std::int64_t>(total, to_sample(options.fade, rate));
    const std::int64_t fade_start = total - fade_len;
    constexpr int kMaxBlock = 4096;
    std::vector<float> left(kMaxBlock), right(kMaxBlock);
    std::vector<int> held(128, 0);  // sounding notes per key: overlapping same-key notes
    float peak = 0.0f;
    std::int64_t pos = 0;

    auto render_until = [&](std::int64_t until) {
        until = std::min(until, total);
        while (pos < until) {
            const int n = static_cast<int>(std::min<std::int64_t>(kMaxBlock, until - pos));
            fs.fluid_synth_write_float(synth.get(), n, left.data(), 0, 1, right.data(), 0, 1);
            for (int i = 0; i < n; ++i) {
                const std::int64_t s = pos + i;
                float g = 1.0f;
                if (s >= fade_start && fade_len > 0) {
                    // Raised cosine from 1 down to 0 at the last sample.
                    const double x = static_cast<double>(s - fade_start + 1) / fade_len;
                    g = static_cast<float>(0.5 * (1.0 + std::cos(std::numbers::pi * x)));
                }
                const float lr[2] = {left[i] * g, right[i] * g};
                for (int c = 0; c < 2; ++c) {
                    peak = std::max(peak, std::abs(lr[c]));
                    float v = std::round(lr[c] * 32767.0f);
                    if (v > 32767.0f || v < -32768.0f) {
                        ++result.clipped;
                        v = std::clamp(v, -32768.0f, 32767.0f);
                    }
                    result.audio.samples[static_cast<std::size_t>(s) * 2 + c] =
                        static_cast<std::int16_t>(v);
                }
            }
            pos += n;
        }
    };

    for (const SynthEvent& e : events) {
        if (e.sample >= total) break;
        render_until(e.sample);
        switch (e.kind) {
            case SynthEvent::NoteOn:
                // A second strike of a key already sounding restarts it, as on a real piano;
                // FluidSynth releases the old voice.
                ++held[e.key];
                fs.fluid_synth_noteon(synth.get(), 0, e.key, e.value);
                break;
            case SynthEvent::NoteOff:
                // Only the last of overlapping same-key notes releases the key.
                if (held[e.key] > 0 && --held[e.key] == 0)
                    fs.fluid_synth_noteoff(synth.get(), 0, e.key);
                break;
            case SynthEvent::Pedal: fs.fluid_synth_cc(synth.get(), 0, 64, e.key); break;
        }
    }
    render_until(total);

    result.peak = peak;
    if (result.clipped > 0)
        result.warnings.push_back(fmt::format(
            "audio: {} samples clipped (peak {:.2f} of full scale); lower the gain (now {})",
            result.clipped, peak, options.gain));
    for (std::string& m : messages) result.warnings.push_back("fluidsynth: " + m);
    return result;
}

AudioResult render_audio(const Score& score, const std::filesystem::path& wav,
                         const AudioOptions& options) {
    AudioResult result = synthesize_score(score, options);
    write_wav(wav, result.audio);
    return result;
}

}  // namespace toonray
