#include "toonray/core/parse.h"

#include <charconv>
#include <cmath>
#include <fmt/format.h>
#include <vector>

#include "toonray/core/error.h"

namespace toonray {
namespace {

std::vector<float> parse_floats(std::string_view text, std::string_view option) {
    std::vector<float> values;
    const char* p = text.data();
    const char* end = p + text.size();
    while (true) {
        float v;
        if (p < end && *p == '+') ++p;
        auto [next, ec] = std::from_chars(p, end, v);
        if (ec != std::errc() || !std::isfinite(v))
            throw Error(fmt::format("{}: malformed number in '{}'", option, text));
        values.push_back(v);
        p = next;
        if (p == end) break;
        if (*p != ',') throw Error(fmt::format("{}: expected ',' in '{}'", option, text));
        ++p;
    }
    return values;
}

}  // namespace

ImageSize parse_image_size(std::string_view text, std::string_view option) {
    ImageSize size;
    const char* p = text.data();
    const char* end = p + text.size();
    auto [mid, ec1] = std::from_chars(p, end, size.width);
    if (ec1 != std::errc() || mid == end || (*mid != 'x' && *mid != 'X'))
        throw Error(fmt::format("{}: expected WIDTHxHEIGHT, got '{}'", option, text));
    auto [last, ec2] = std::from_chars(mid + 1, end, size.height);
    if (ec2 != std::errc() || last != end)
        throw Error(fmt::format("{}: expected WIDTHxHEIGHT, got '{}'", option, text));
    if (size.width < 1 || size.height < 1 || size.width > 32768 || size.height > 32768)
        throw Error(fmt::format("{}: {}x{} is outside 1x1 to 32768x32768", option, size.width,
                                size.height));
    return size;
}

Vec3f parse_vec3(std::string_view text, std::string_view option) {
    auto v = parse_floats(text, option);
    if (v.size() != 3) throw Error(fmt::format("{}: expected x,y,z, got '{}'", option, text));
    return {v[0], v[1], v[2]};
}

Vec3f parse_colour(std::string_view text, std::string_view option) {
    if (!text.empty() && text[0] == '#') {
        unsigned value = 0;
        auto [p, ec] = std::from_chars(text.data() + 1, text.data() + text.size(), value, 16);
        if (text.size() != 7 || ec != std::errc() || p != text.data() + text.size())
            throw Error(fmt::format("{}: expected #rrggbb, got '{}'", option, text));
        return {((value >> 16) & 255) / 255.0f, ((value >> 8) & 255) / 255.0f,
                (value & 255) / 255.0f};
    }
    Vec3f c = parse_vec3(text, option);
    for (int i = 0; i < 3; ++i)
        if (c[i] < 0.0f || c[i] > 1.0f)
            throw Error(
                fmt::format("{}: colour components must be in [0, 1], got '{}'", option, text));
    return c;
}

std::vector<float> parse_number_list(std::string_view text, std::string_view what) {
    std::vector<float> out;
    if (text.empty()) return out;
    for (;;) {
        const std::size_t comma = text.find(',');
        const std::string_view item = text.substr(0, comma);
        float v = 0.0f;
        const char* b = item.data();
        auto [p, ec] = std::from_chars(b, b + item.size(), v);
        if (item.empty() || ec != std::errc() || p != b + item.size() || !std::isfinite(v))
            throw Error(fmt::format("{}: malformed number '{}'", what, item));
        out.push_back(v);
        if (comma == std::string_view::npos) return out;
        text.remove_prefix(comma + 1);
    }
}

std::string format_number(float value) { return fmt::format("{}", value); }

std::string format_vec3(const Vec3f& v) {
    return fmt::format("{},{},{}", format_number(v.x), format_number(v.y), format_number(v.z));
}

std::string format_colour(const Vec3f& colour) {
    std::string hex = "#";
    for (int i = 0; i < 3; ++i) {
        const float scaled = colour[i] * 255.0f;
        const int byte = static_cast<int>(std::lround(scaled));
        if (byte < 0 || byte > 255 || static_cast<float>(byte) / 255.0f != colour[i])
            return format_vec3(colour);
        hex += fmt::format("{:02x}", byte);
    }
    return hex;
}

}  // namespace toonray
