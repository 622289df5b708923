#include "toonray/scene/light.h"

#include <charconv>
#include <cmath>
#include <fmt/format.h>
#include <sstream>

#include "toonray/core/error.h"
#include "toonray/core/parse.h"
#include "toonray/io/file.h"
#include "toonray/scene/scene.h"

namespace toonray {

Light parse_light(const std::string& text) {
    Light light;
    std::string body = text;
    if (body.rfind("point:", 0) == 0) {
        body = body.substr(6);
    } else if (body.rfind("dir:", 0) == 0) {
        light.kind = Light::Kind::Directional;
        body = body.substr(4);
    }
    const std::string what = fmt::format("light '{}'", text);
    auto at = body.find('@');
    if (at != std::string::npos) {
        auto v = parse_number_list(body.substr(at + 1), what);
        if (v.size() != 1 || v[0] < 0)
            throw Error(fmt::format("{}: intensity must be one number >= 0", what));
        light.intensity = v[0];
        body = body.substr(0, at);
    }
    light.vector = parse_vec3(body, what);
    if (light.kind == Light::Kind::Directional && !(length(light.vector) > 0))
        throw Error(fmt::format("{}: a directional light needs a non-zero direction", what));
    return light;
}

std::string format_light(const Light& light) {
    return fmt::format("{}:{}@{}", light.kind == Light::Kind::Point ? "point" : "dir",
                       format_vec3(light.vector), format_number(light.intensity));
}

std::vector<Light> parse_lights(std::string_view text, const std::string& file) {
    std::vector<Light> lights;
    std::string s(text);
    std::stringstream in(s);
    std::string line;
    std::size_t number = 0;
    while (std::getline(in, line)) {
        ++number;
        if (auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
        std::stringstream words(line);
        std::string kind;
        if (!(words >> kind)) continue;
        Light light;
        if (kind == "point") light.kind = Light::Kind::Point;
        else if (kind == "directional") light.kind = Light::Kind::Directional;
        else throw_at(file, number, fmt::format("unknown light '{}' (point or directional)", kind));
        std::vector<float> v;
        std::string word;
        while (words >> word) {
            float f;
            auto [p, ec] = std::from_chars(word.data(), word.data() + word.size(), f);
            if (ec != std::errc() || p != word.data() + word.size() || !std::isfinite(f))
                throw_at(file, number, fmt::format("malformed number '{}'", word));
            v.push_back(f);
        }
        if (v.size() != 3 && v.size() != 4) throw_at(file, number, "expected x y z [intensity]");
        light.vector = {v[0], v[1], v[2]};
        if (v.size() == 4) {
            if (v[3] < 0) throw_at(file, number, "intensity must not be negative");
            light.intensity = v[3];
        }
        if (light.kind == Light::Kind::Directional && !(length(light.vector) > 0))
            throw_at(file, number, "a directional light needs a non-zero direction");
        lights.push_back(light);
    }
    if (lights.empty()) throw Error(fmt::format("{}: no lights", file));
    return lights;
}

std::vector<Light> load_lights(const std::filesystem::path& path) {
    return parse_lights(read_file(path), path.string());
}

std::filesystem::path scene_lights_path(const std::filesystem::path& scene_file) {
    std::filesystem::path path = scene_file;
    return path.replace_extension(".lights");
}

std::vector<Light> scene_file_lights(const std::filesystem::path& scene_file) {
    const std::filesystem::path path = scene_lights_path(scene_file);
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) return {};
    return load_lights(path);
}

Light default_light(const Scene& scene, const CameraSpec& camera) {
    // The view's unit up and right do not depend on the image size.
    const ViewPlane view = make_view_plane(camera, 1, 1);
    const BBox b = scene.bounds();
    const float radius = b.empty() ? 1.0f : 0.5f * length(b.extent());
    return Light{Light::Kind::Point, view.eye + (view.up + view.right) * (0.5f * radius), 1.0f};
}

}  // namespace toonray
