// The tone look's values and the line types: `--tone`, `--tone-anchor`, `--hatch-direction`
// and `--lines` texts. Whatever parses must write back to a text that parses to the same
// value, and a hatch direction's axis must be a finite vector that is not zero.

#include <cmath>
#include <string>

#include "fuzz_util.h"
#include "toonray/core/error.h"
#include "toonray/ink/tone.h"
#include "toonray/render/line_settings.h"

using namespace toonray;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(toonray_fuzz::as_text(data, size));
    try {
        const ink::ToneMode mode = ink::parse_tone_mode(text);
        FUZZ_CHECK(ink::parse_tone_mode(ink::tone_mode_name(mode)) == mode);
    } catch (const Error&) {
    }
    try {
        const ink::ToneAnchor anchor = ink::parse_tone_anchor(text);
        FUZZ_CHECK(ink::parse_tone_anchor(ink::tone_anchor_name(anchor)) == anchor);
    } catch (const Error&) {
    }
    try {
        const ink::HatchDirection d = ink::parse_hatch_direction(text);
        FUZZ_CHECK(std::isfinite(d.axis.x) && std::isfinite(d.axis.y) && std::isfinite(d.axis.z));
        FUZZ_CHECK(length(d.axis) > 0.0f && std::isfinite(length(d.axis)));
        FUZZ_CHECK(ink::parse_hatch_direction(ink::format_hatch_direction(d)) == d);
    } catch (const Error&) {
    }
    try {
        const unsigned types = parse_line_types(text);
        FUZZ_CHECK((types & ~(kLineAll | kLineBand | kLineShadow)) == 0);
        FUZZ_CHECK(parse_line_types(format_line_types(types)) == types);
    } catch (const Error&) {
    }
    return 0;
}
