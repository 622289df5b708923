#pragma once
/// Parsers for command-line values. Each throws Error naming the option and the bad text.

#include <string>
#include <string_view>
#include <vector>

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

/// "0.5,0.75,1": comma-separated finite numbers; none for "". Throws Error
/// ("WHAT: malformed number 'x'").
std::vector<float> parse_number_list(std::string_view text, std::string_view what);

/// The shortest decimal text that reads back as exactly `value` (std::from_chars).
std::string format_number(float value);

/// "x,y,z" of format_number.
std::string format_vec3(const Vec3f& v);

/// "#rrggbb" when the colour is exactly one parse_colour reads from that form, else "r,g,b".
std::string format_colour(const Vec3f& colour);

}  // namespace toonray
