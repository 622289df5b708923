// Command-line values: --size, --light, --background, --camera, frame patterns, --shard. The
// first byte picks the parser; the rest is the value.

#include <string>

#include "fuzz_util.h"
#include "toonray/anim/batch.h"
#include "toonray/anim/frame_pattern.h"
#include "toonray/core/error.h"
#include "toonray/core/parse.h"
#include "toonray/scene/camera.h"

using namespace toonray;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
    try {
        switch (data[0] % 7) {
            case 0: {
                ImageSize s = parse_image_size(text, "--size");
                FUZZ_CHECK(s.width >= 1 && s.height >= 1 && s.width <= 32768 && s.height <= 32768);
                break;
            }
            case 1: FUZZ_CHECK(is_finite(parse_vec3(text, "--light"))); break;
            case 2: {
                Vec3f c = parse_colour(text, "--background");
                for (int i = 0; i < 3; ++i) FUZZ_CHECK(c[i] >= 0.0f && c[i] <= 1.0f);
                break;
            }
            case 3: {
                CameraSpec c = parse_camera_spec(text);
                FUZZ_CHECK(is_finite(c.eye) && is_finite(c.gaze) && is_finite(c.up));
                break;
            }
            case 4: {
                FramePattern p(text);
                for (int frame : {0, 1, 7, 123456, 2147483647}) {
                    std::string name = p.format(frame);
                    // A pattern names a file in the output directory, never a path out of it.
                    FUZZ_CHECK(name.find('/') == std::string::npos);
                    FUZZ_CHECK(name.find('\0') == std::string::npos ||
                               text.find('\0') != std::string::npos);
                }
                break;
            }
            case 5: {
                Shard s = parse_shard(text);
                FUZZ_CHECK(s.index >= 1 && s.index <= s.count);
                auto frames = shard_frames(1, 1000, s);
                FUZZ_CHECK(frames.size() <= 1000);
                break;
            }
            case 6: {
                for (const FramePattern& p : default_input_patterns(text)) {
                    std::string name = p.format(42);
                    FUZZ_CHECK(name.find('/') == std::string::npos);
                }
                break;
            }
        }
    } catch (const Error&) {
    }
    return 0;
}
