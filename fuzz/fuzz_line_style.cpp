// Line style files. Checks that every parsed rule is within the documented ranges, that a
// style resolved from them is too, and that each rule written back as (key, value) entries
// (as a settings document holds it) reads back to an equal rule.

#include <cmath>

#include "fuzz_util.h"
#include "toonray/core/error.h"
#include "toonray/ink/line_style.h"

using namespace toonray;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    ink::LineStyleSet set;
    try {
        set = ink::parse_line_styles(toonray_fuzz::as_text(data, size), "fuzz.style");
    } catch (const Error&) {
        return 0;
    }
    for (const ink::LineStyleRule& rule : set.rules) {
        // Whatever parsed must round-trip: a failure to read the entries back is a bug too.
        const std::vector<ink::RuleEntry> entries = ink::line_style_rule_entries(rule);
        const ink::LineStyleRule back =
            ink::make_line_style_rule(entries, {"fuzz.toml: lines.rule[1]", ".", rule.line});
        FUZZ_CHECK(back == rule);
    }
    for (int t = 0; t < ink::kEdgeTypeCount; ++t)
        for (bool visible : {false, true}) {
            const ink::LineStyle s = ink::resolve_line_style(
                set, ink::LineStyle{}, "w12", "ivory", static_cast<ink::EdgeType>(t), visible);
            FUZZ_CHECK(s.width >= 0.0f && s.width <= 1000.0f);
            FUZZ_CHECK(s.opacity >= 0.0f && s.opacity <= 1.0f);
            FUZZ_CHECK(s.taper >= 0.0f && s.taper <= 1e4f);
            FUZZ_CHECK(s.dash.size() % 2 == 0);
            float total = 0.0f;
            for (float d : s.dash) {
                FUZZ_CHECK(std::isfinite(d) && d >= 0.0f);
                total += d;
            }
            FUZZ_CHECK(s.dash.empty() || total > 0.0f);
            for (int c = 0; c < 3; ++c) FUZZ_CHECK(s.colour[c] >= 0.0f && s.colour[c] <= 1.0f);
            FUZZ_CHECK(s.pressure.empty() || (s.pressure.size() >= 2 && s.pressure.size() <= 16));
            for (float f : s.pressure) FUZZ_CHECK(f >= 0.0f && f <= 10.0f);
            FUZZ_CHECK(s.calligraphy >= 0.0f && s.calligraphy <= 1.0f);
            FUZZ_CHECK(s.nib_angle >= -360.0f && s.nib_angle <= 360.0f);
            FUZZ_CHECK(s.brush.find_first_of(" \t\r\n") == std::string::npos);
            for (float count : {s.sketch, s.sketch_seed, s.boil})
                FUZZ_CHECK(count >= 0.0f && count == std::floor(count));
            FUZZ_CHECK(s.sketch <= 16.0f);
        }
    return 0;
}
