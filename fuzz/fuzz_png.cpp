// PNG decoding (batch --resume decodes every existing output to decide whether to redo it).

#include "fuzz_util.h"
#include "toonray/core/error.h"
#include "toonray/core/limits.h"
#include "toonray/io/png.h"

using namespace toonray;

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    // A header may announce up to the limit; keep each run's allocation small.
    Limits l = limits();
    l.max_image_pixels = 1 << 20;
    set_limits(l);
    return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        DecodedPng png = decode_png(toonray_fuzz::as_bytes(data, size), "fuzz.png");
        FUZZ_CHECK(png.width > 0 && png.height > 0);
        FUZZ_CHECK(png.rgb.size() == static_cast<std::size_t>(png.width) * png.height);
    } catch (const Error&) {
    }
    return 0;
}
