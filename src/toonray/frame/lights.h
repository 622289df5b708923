#pragma once
/// Lights files: one light per line, `point x y z [intensity]` or
/// `directional dx dy dz [intensity]`, `#` comments.

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "toonray/render/shading.h"

namespace toonray {

/// Reads a lights file. Throws Error("file:line: ...").
std::vector<Light> load_lights(const std::filesystem::path& path);

/// The lights of a lights file's text; `file` names it in errors. Throws Error("file:line: ...").
std::vector<Light> parse_lights(std::string_view text, const std::string& file);

/// The lights file that goes with a scene file: the same name with the extension `.lights`
/// (`keys_000030.obj` -> `keys_000030.lights`), as the Blender add-on writes it.
std::filesystem::path scene_lights_path(const std::filesystem::path& scene_file);

/// The lights a frame of `scene_file` is lit by: `given` (the command line's) when not empty,
/// else the scene's lights file when it exists, else empty (the renderer's default light).
/// Throws Error("file:line: ...") for a bad lights file.
std::vector<Light> frame_lights(const std::filesystem::path& scene_file,
                                const std::vector<Light>& given);

}  // namespace toonray
