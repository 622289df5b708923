// GLB files. An input that starts with the GLB magic is read as it is (the header and chunk
// checks); any other is "JSON\nBIN\nbinary", wrapped in a valid GLB header so that mutations
// reach the JSON and the binary chunk rather than break the lengths.

#include <string>
#include <string_view>

#include "gltf_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view input = toonray_fuzz::as_text(data, size);
    if (input.substr(0, 4) == "glTF") {
        toonray_fuzz::load_and_pose_gltf(toonray_fuzz::as_bytes(data, size), "fuzz.glb");
        return 0;
    }
    const std::size_t cut = input.find("\nBIN\n");
    std::string json(input.substr(0, cut));
    std::string bin(cut == std::string_view::npos ? std::string_view() : input.substr(cut + 5));
    while (json.size() % 4) json.push_back(' ');
    while (bin.size() % 4) bin.push_back('\0');
    std::string glb = "glTF";
    auto put = [&](std::size_t v) {
        for (int i = 0; i < 4; ++i) glb.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
    };
    put(2);
    put(12 + 8 + json.size() + (bin.empty() ? 0 : 8 + bin.size()));
    put(json.size());
    glb += "JSON" + json;
    if (!bin.empty()) {
        put(bin.size());
        glb += std::string("BIN\0", 4) + bin;
    }
    toonray_fuzz::load_and_pose_gltf(
        toonray_fuzz::as_bytes(reinterpret_cast<const std::uint8_t*>(glb.data()), glb.size()),
        "fuzz.glb");
    return 0;
}
