#pragma once
/// Wavefront MTL reading: the materials of a library (newmtl, Kd, Ka, Ks, Ns, d, Tr, illum,
/// map_Kd; other statements are ignored by design).

#include <cstddef>
#include <filesystem>
#include <string_view>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/scene/scene.h"

namespace toonray {

/// Parses MTL text, appending its materials. A name already in `materials` (defined earlier in
/// this text or in an earlier library) keeps its first definition, with a warning. Throws
/// Error("file:line: reason") on malformed input.
void parse_mtl(std::string_view text, const std::filesystem::path& path,
               std::vector<Material>& materials, Warnings& warnings);

/// Reads the MTL file `path`, which line `obj_line` of `obj_file` names, and parses it. A file
/// that cannot be read is a warning (located at that OBJ line): its materials stay undefined.
void load_mtl_library(const std::filesystem::path& path, std::vector<Material>& materials,
                      Warnings& warnings, std::string_view obj_file, std::size_t obj_line);

}  // namespace toonray
