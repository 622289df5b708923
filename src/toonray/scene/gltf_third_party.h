#pragma once
/// The third-party code the glTF reader builds on, compiled once in gltf_third_party.cpp
/// (internal to the scene module): tinygltf's implementation (Debian's libtinygltf-dev
/// header, without its image code) and stb_image's PNG and JPEG decoders, kept static so they
/// never clash with another copy in the process.

#include <cstddef>
#include <cstdint>
#include <string>

#include "toonray/core/image.h"

namespace toonray::gltf_detail {

/// Decodes a PNG or JPEG image of at most `max_pixels` pixels to 8-bit RGB. Returns false with
/// `error` set when the bytes are not such an image or it is larger.
bool decode_image(const std::uint8_t* bytes, std::size_t size, std::uint64_t max_pixels,
                  ImageRgb8& image, std::string& error);

}  // namespace toonray::gltf_detail
