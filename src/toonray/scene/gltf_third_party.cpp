// tinygltf's implementation and stb_image's decoders, compiled once (gltf_third_party.h).
// Third-party code: built without the project's warnings (src/toonray/CMakeLists.txt).

#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#define STBI_ONLY_JPEG
#define STBI_NO_STDIO
#define STBI_NO_LINEAR
#define STBI_NO_HDR
#include <stb_image.h>

// TINYGLTF_NO_STB_IMAGE, _NO_STB_IMAGE_WRITE and _NO_EXTERNAL_IMAGE are set for the whole
// module (src/toonray/CMakeLists.txt): the declarations must agree in every file.
#define TINYGLTF_IMPLEMENTATION
#include <tiny_gltf.h>

#include "toonray/scene/gltf_third_party.h"

namespace toonray::gltf_detail {

bool decode_image(const std::uint8_t* bytes, std::size_t size, std::uint64_t max_pixels,
                  ImageRgb8& image, std::string& error) {
    if (size > static_cast<std::size_t>(INT32_MAX)) {
        error = "the image is larger than 2 GiB";
        return false;
    }
    int width = 0, height = 0, channels = 0;
    const int length = static_cast<int>(size);
    if (!stbi_info_from_memory(bytes, length, &width, &height, &channels)) {
        error = std::string("not a PNG or JPEG image (") + stbi_failure_reason() + ")";
        return false;
    }
    if (width < 1 || height < 1 ||
        static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height) > max_pixels) {
        error = "the image is " + std::to_string(width) + "x" + std::to_string(height) +
                " pixels, more than the limit of " + std::to_string(max_pixels);
        return false;
    }
    unsigned char* rgb = stbi_load_from_memory(bytes, length, &width, &height, &channels, 3);
    if (!rgb) {
        error = std::string("cannot decode the image (") + stbi_failure_reason() + ")";
        return false;
    }
    image.resize(width, height);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const unsigned char* p = rgb + (static_cast<std::size_t>(y) * width + x) * 3;
            image(x, y) = {p[0], p[1], p[2]};
        }
    stbi_image_free(rgb);
    return true;
}

}  // namespace toonray::gltf_detail
