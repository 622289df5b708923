// Settings documents (TOML, frame/settings.h). Whatever reads must write back as a document
// that reads back to the same settings, and must be settings a frame can be rendered with.

#include "fuzz_util.h"
#include "toonray/core/error.h"
#include "toonray/frame/settings.h"

using namespace toonray;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    Settings settings;
    try {
        read_settings(toonray_fuzz::as_text(data, size), "fuzz.toml", settings);
        check_settings(settings);
        (void)settings.applied_limits(Limits{});
    } catch (const Error&) {
        return 0;
    }
    const std::string text = settings_toml(settings);
    Settings back;
    read_settings(text, "fuzz-written.toml", back);  // throws (a bug) if it does not read back
    FUZZ_CHECK(settings_toml(back) == text);
    const RenderSettings& r = settings.render;
    FUZZ_CHECK(r.width >= 1 && r.height >= 1 && r.width <= 32768 && r.height <= 32768);
    FUZZ_CHECK(samples_per_side(r.sampling.samples) >= 1);
    FUZZ_CHECK(r.lines.width >= 0.0f && r.lines.width <= 100.0f);
    FUZZ_CHECK(!r.shading.ramp.levels.empty() &&
               r.shading.ramp.levels.size() == r.shading.ramp.thresholds.size() + 1);
    return 0;
}
