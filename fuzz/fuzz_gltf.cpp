// glTF JSON text (buffers as data URIs; external files are never read), loaded and posed.

#include "gltf_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    toonray_fuzz::load_and_pose_gltf(toonray_fuzz::as_bytes(data, size), "fuzz.gltf");
    return 0;
}
