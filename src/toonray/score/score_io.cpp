#include "toonray/score/score_io.h"

#include <algorithm>
#include <fmt/format.h>
#include <span>
#include <string>

#include "toonray/io/file.h"

namespace toonray {
namespace {

enum class ScoreFormat { midi, note_script };

ScoreFormat format_for(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (ext == ".mid" || ext == ".midi") return ScoreFormat::midi;
    if (ext == ".notes") return ScoreFormat::note_script;
    throw Error(fmt::format("{}: unknown score extension '{}' (use .mid, .midi or .notes)",
                            path.string(), ext));
}

}  // namespace

TimedScore load_timed_score(const std::filesystem::path& path, Warnings* warnings,
                            const MidiLimits& limits) {
    const std::string data = read_file(path);
    const std::string name = path.string();
    // An empty file is a failed download or export, not a score.
    if (data.find_first_not_of(" \t\r\n\f\v") == std::string::npos)
        throw Error(located(name, 0,
                            data.empty() ? "empty file: not a score (MIDI file or note script)"
                                         : "blank file: not a score (MIDI file or note script)"));
    const std::span bytes(reinterpret_cast<const std::uint8_t*>(data.data()), data.size());
    if (is_midi(bytes)) return read_midi(bytes, name, warnings, limits);
    return parse_note_script(data, name, warnings);
}

Score load_score(const std::filesystem::path& path, Warnings* warnings, const MidiLimits& limits) {
    return to_score(load_timed_score(path, warnings, limits));
}

void save_score(const TimedScore& score, const std::filesystem::path& path) {
    if (format_for(path) == ScoreFormat::midi) {
        std::vector<std::uint8_t> bytes;
        try {
            bytes = write_midi(score);
        } catch (const Error& e) {
            throw Error(fmt::format("{}: {}", path.string(), e.what()));
        }
        write_file_atomic(path, bytes);
    } else {
        const std::string text = write_note_script(score);
        write_file_atomic(
            path, std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
    }
}

void convert_score(const std::filesystem::path& in, const std::filesystem::path& out,
                   Warnings* warnings) {
    format_for(out);  // refuse a bad output name before reading anything
    save_score(load_timed_score(in, warnings), out);
}

}  // namespace toonray
