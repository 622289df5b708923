// Camera path files (.campath). A path that parses must give a camera at any time: a finite
// pose, and a CameraSpec or an Error.

#include <cmath>
#include <limits>

#include "fuzz_util.h"
#include "toonray/anim/camera_path.h"
#include "toonray/core/error.h"

using namespace toonray;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    CameraPath path;
    try {
        path = parse_camera_path(toonray_fuzz::as_text(data, size), "fuzz.campath");
    } catch (const Error&) {
        return 0;
    }
    FUZZ_CHECK(!path.empty());
    std::vector<double> times = {-1e9,
                                 -1.0,
                                 0.0,
                                 0.5,
                                 1e9,
                                 std::numeric_limits<double>::infinity(),
                                 std::numeric_limits<double>::quiet_NaN()};
    for (const CameraKey& k : path.keys()) {
        times.push_back(k.time);
        times.push_back(k.time + 0.25);
        times.push_back(k.time - 1e-3);
    }
    if (times.size() > 64) times.resize(64);
    for (double t : times) {
        CameraPose pose = path.pose(t);
        FUZZ_CHECK(is_finite(pose.eye) && is_finite(pose.target) && is_finite(pose.up));
        FUZZ_CHECK(std::isfinite(pose.fov));
        try {
            CameraSpec spec = path.camera(t);
            FUZZ_CHECK(is_finite(spec.eye));
        } catch (const Error&) {
        }
    }
    return 0;
}
