// Standard MIDI Files. A file that reads must write back to MIDI that reads the same, and to a
// note script that parses the same (both promised by score_io.h and normalize()).

#include "fuzz_util.h"
#include "toonray/core/error.h"
#include "toonray/score/midi.h"
#include "toonray/score/note_script.h"
#include "toonray/score/timed_score.h"

using namespace toonray;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    TimedScore score;
    Warnings warnings;
    MidiLimits limits;
    limits.max_events = 200'000;  // keep single runs fast; the limit itself is tested elsewhere
    try {
        score = read_midi(toonray_fuzz::as_bytes(data, size), "fuzz.mid", &warnings, limits);
    } catch (const Error&) {
        return 0;
    }
    (void)to_score(score);
    std::vector<std::uint8_t> midi;
    bool written = true;
    try {
        midi = write_midi(score);
    } catch (const Error&) {
        written = false;  // write_midi refuses what MIDI cannot hold
    }
    if (written) {
        // read_midi must accept whatever write_midi made, and read back the same score.
        TimedScore again = read_midi(midi, "rewritten.mid");
        FUZZ_CHECK(again == score);
    }
    const std::string text = write_note_script(score);
    TimedScore from_script = parse_note_script(text, "rewritten.notes");
    FUZZ_CHECK(from_script == score);
    return 0;
}
