#pragma once
/// The textures (map_Kd) of a scene's materials, read from their PNG files.

#include <map>
#include <memory>
#include <string>

#include "toonray/core/error.h"
#include "toonray/render/shading.h"
#include "toonray/scene/scene.h"

namespace toonray {

/// Decodes each texture file once and keeps it for the frames that follow, so an animation
/// whose frames share materials reads each file once. A texture that is missing or not a PNG is
/// reported once as a warning and left out (the material keeps its Kd).
class TextureCache {
public:
    /// The textures of `scene`'s materials (index = material), valid until the next call.
    const TextureSet& load(const Scene& scene, Warnings& warnings);

private:
    TextureSet textures_;
    std::map<std::string, std::shared_ptr<const ImageRgb8>> decoded_;  ///< by path
    std::map<std::string, bool> failed_;
};

}  // namespace toonray
