// Shading options and the lights file: --ramp, --light and --lights FILE. The first byte picks
// the parser; the rest is the value or the file's text.

#include <cmath>
#include <string>

#include "fuzz_util.h"
#include "toonray/core/error.h"
#include "toonray/scene/light.h"
#include "toonray/render/shading.h"

using namespace toonray;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
    try {
        switch (data[0] % 3) {
            case 0: {
                ToonRamp ramp = parse_ramp(text);
                FUZZ_CHECK(!ramp.levels.empty() &&
                           ramp.thresholds.size() + 1 == ramp.levels.size());
                for (float d : {-1.0f, 0.0f, 0.3f, 1.0f, 2.0f})
                    FUZZ_CHECK(std::isfinite(ramp.level(d)));
                FUZZ_CHECK(parse_ramp(format_ramp(ramp)) == ramp);
                break;
            }
            case 1: {
                Light l = parse_light(text);
                FUZZ_CHECK(is_finite(l.vector) && std::isfinite(l.intensity) && l.intensity >= 0);
                FUZZ_CHECK(parse_light(format_light(l)) == l);
                break;
            }
            case 2: {
                for (const Light& l : parse_lights(text, "fuzz.lights"))
                    FUZZ_CHECK(is_finite(l.vector) && std::isfinite(l.intensity) &&
                               l.intensity >= 0);
                break;
            }
        }
    } catch (const Error&) {
    }
    return 0;
}
