// Note scripts. A script that parses must write back to a script that parses to the same score
// (note_script.h promises this for any normalized score the parser makes), and to MIDI that
// reads back the same (score_io.h: MIDI -> note script -> MIDI keeps every note).

#include "fuzz_util.h"
#include "toonray/core/error.h"
#include "toonray/score/midi.h"
#include "toonray/score/note_script.h"
#include "toonray/score/timed_score.h"

using namespace toonray;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    TimedScore score;
    Warnings warnings;
    try {
        score = parse_note_script(toonray_fuzz::as_text(data, size), "fuzz.notes", &warnings);
    } catch (const Error&) {
        return 0;
    }
    (void)to_score(score);
    const std::string text = write_note_script(score);
    TimedScore again = parse_note_script(text, "rewritten.notes");
    FUZZ_CHECK(again == score);

    std::vector<std::uint8_t> midi;
    try {
        midi = write_midi(score);
    } catch (const Error&) {
        return 0;  // not every script fits MIDI (gaps longer than 2^28 - 1 ticks)
    }
    TimedScore from_midi = read_midi(midi, "rewritten.mid");
    // A MIDI file has no room for the script's default tempo when none is given, but the
    // script always sets one at tick 0, so the scores compare equal.
    FUZZ_CHECK(from_midi == score);
    return 0;
}
