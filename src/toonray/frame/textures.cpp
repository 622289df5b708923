#include "toonray/frame/textures.h"

#include <fmt/format.h>

#include "toonray/io/png.h"

namespace toonray {

const TextureSet& TextureCache::load(const Scene& scene, Warnings& warnings) {
    textures_.assign(scene.materials.size(), nullptr);
    for (std::size_t m = 0; m < scene.materials.size(); ++m) {
        if (scene.materials[m].kd_image) {
            textures_[m] = scene.materials[m].kd_image;
            continue;
        }
        const std::string& path = scene.materials[m].map_kd;
        if (path.empty()) continue;
        if (auto it = decoded_.find(path); it != decoded_.end()) {
            textures_[m] = it->second;
            continue;
        }
        if (failed_.count(path)) continue;
        try {
            DecodedPng png = read_png(path);
            auto image = std::make_shared<const ImageRgb8>(std::move(png.rgb));
            decoded_[path] = image;
            textures_[m] = image;
        } catch (const Error& e) {
            failed_[path] = true;
            warnings.push_back(fmt::format("material '{}': texture not used: {}",
                                           scene.materials[m].name, e.what()));
        }
    }
    return textures_;
}

}  // namespace toonray
