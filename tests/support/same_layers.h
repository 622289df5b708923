#pragma once
/// Whether two frames' layers (render/frame_layers.h) are the same, bit for bit.

#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "toonray/render/frame_layers.h"

namespace toonray::test_support {

template <typename T>
::testing::AssertionResult same_image(const Image<T>& a, const Image<T>& b, const char* what) {
    if (a.width() != b.width() || a.height() != b.height())
        return ::testing::AssertionFailure() << what << ": sizes differ";
    if (a.size() > 0 && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) != 0)
        return ::testing::AssertionFailure() << what << ": pixels differ";
    return ::testing::AssertionSuccess();
}

/// Every image of two frames' layers, bit for bit.
inline ::testing::AssertionResult same_layers(const FrameLayers& a, const FrameLayers& b) {
    for (auto result :
         {same_image(a.image, b.image, "image"), same_image(a.cel, b.cel, "cel"),
          same_image(a.distance, b.distance, "distance"),
          same_image(a.view_depth, b.view_depth, "view depth"),
          same_image(a.normal, b.normal, "normal"),
          same_image(a.geometric_normal, b.geometric_normal, "geometric normal"),
          same_image(a.object, b.object, "object"), same_image(a.material, b.material, "material"),
          same_image(a.band, b.band, "band"), same_image(a.light, b.light, "light"),
          same_image(a.position, b.position, "position"), same_image(a.uv, b.uv, "uv"),
          same_image(a.refined, b.refined, "refined"), same_image(a.lines, b.lines, "lines")})
        if (!result) return result;
    if (a.line_types.size() != b.line_types.size())
        return ::testing::AssertionFailure() << "line type counts differ";
    for (std::size_t t = 0; t < a.line_types.size(); ++t) {
        if (a.line_types[t].name != b.line_types[t].name)
            return ::testing::AssertionFailure() << "line types differ";
        auto result = same_image(a.line_types[t].coverage, b.line_types[t].coverage,
                                 std::string(a.line_types[t].name).c_str());
        if (!result) return result;
    }
    return ::testing::AssertionSuccess();
}

}  // namespace toonray::test_support
