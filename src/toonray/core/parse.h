#pragma once
/// Parsers for command-line values. Each throws Error naming the option and the bad text.

#include <string>
#include <string_view>

#include "toonray/core/math.h"

namespace toonray {

struct ImageSize {
    int width = 0, height = 0;
};

/// "1920x1080" -> {1920, 1080}; both within [1, 32768].
ImageSize parse_image_size(std::string_view text, std::string_view option);

/// "4,6,10" -> Vec3f; finite numbers only.
Vec3f parse_vec3(std::string_view text, std::string_view option);

/// "1,1,1" (components in [0, 1]) or "#rrggbb" -> linear colour as written (no gamma).
Vec3f parse_colour(std::string_view text, std::string_view option);

}  // namespace toonray
