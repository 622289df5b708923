#pragma once
/// Toon lights: what a scene is lit by, as the command line, lights files and glTF files give
/// them, and the default light of a scene that brings none.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "toonray/core/math.h"
#include "toonray/scene/camera.h"

namespace toonray {

struct Scene;

struct Light {
    enum class Kind { Point, Directional };
    Kind kind = Kind::Point;
    Vec3f vector;  ///< point: position; directional: direction the light travels
    float intensity = 1.0f;
    bool operator==(const Light&) const = default;
};

/// Parses "x,y,z" or "point:x,y,z" (a point light) or "dir:x,y,z" (a directional light,
/// shining along the vector), each optionally followed by "@intensity". Throws Error
/// ("light '...': ...").
[[nodiscard]] Light parse_light(const std::string& text);

/// The text parse_light reads back as `light` exactly: "point:x,y,z@i" or "dir:x,y,z@i", with
/// the shortest decimal forms that round trip.
[[nodiscard]] std::string format_light(const Light& light);

/// The lights of a lights file's text: one light per line, `point x y z [intensity]` or
/// `directional dx dy dz [intensity]`, `#` comments. `file` names it in errors. Throws
/// Error("file:line: ...").
[[nodiscard]] std::vector<Light> parse_lights(std::string_view text, const std::string& file);

/// Reads a lights file. Throws Error("file:line: ...").
[[nodiscard]] std::vector<Light> load_lights(const std::filesystem::path& path);

/// The lights file that goes with a scene file: the same name with the extension `.lights`
/// (`keys_000030.obj` -> `keys_000030.lights`), as the Blender add-on writes it.
[[nodiscard]] std::filesystem::path scene_lights_path(const std::filesystem::path& scene_file);

/// The lights of the scene file's own lights file when it exists, else none. Throws
/// Error("file:line: ...") for a bad lights file.
[[nodiscard]] std::vector<Light> scene_file_lights(const std::filesystem::path& scene_file);

/// The default light: one point light at the eye moved by half the scene's radius along the
/// camera's up and right (a radius of 1 for an empty scene).
[[nodiscard]] Light default_light(const Scene& scene, const CameraSpec& camera);

}  // namespace toonray
