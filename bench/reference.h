#pragma once
/// The reference implementations the benchmark compares our stages against: tinyobjloader for
/// OBJ parsing and libpng (at its default settings) for PNG encoding.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "toonray/scene/scene.h"

namespace toonray::bench {

/// Loads `path` with tinyobjloader (triangulating, materials from the OBJ's directory), the way
/// an application would; returns the triangle count. Throws std::runtime_error on failure.
std::size_t tinyobj_load(const std::filesystem::path& path);

/// Loads `path` with tinyobjloader and compares with our scene triangle by triangle: positions
/// and normals bit-equal per corner, the material by name and Kd. Returns the differences found
/// (empty when they agree), at most `max_lines`.
std::vector<std::string> compare_with_tinyobj(const Scene& ours, const std::filesystem::path& path,
                                              std::size_t max_lines = 5);

/// Encodes 8-bit RGB with libpng at its default settings (zlib level 6, adaptive filters).
std::vector<std::uint8_t> libpng_encode_rgb(int width, int height, const std::uint8_t* pixels);

}  // namespace toonray::bench
