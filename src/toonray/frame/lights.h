#pragma once
/// Lights files: one light per line, `point x y z [intensity]` or
/// `directional dx dy dz [intensity]`, `#` comments.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "toonray/render/shading.h"

namespace toonray {

/// Reads a lights file. Throws Error("file:line: ...").
std::vector<Light> load_lights(const std::filesystem::path& path);

/// The lights of a lights file's text; `file` names it in errors. Throws Error("file:line: ...").
std::vector<Light> parse_lights(std::string_view text, const std::string& file);

}  // namespace toonray
