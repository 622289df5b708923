#include "toonray/frame/feature_exr.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "toonray/core/error.h"
#include "toonray/core/index.h"
#include "toonray/core/saturating.h"
#include "toonray/io/exr.h"
#include "toonray/render/surface.h"

namespace toonray {

namespace {

// The sRGB transfer function undone: EXR colour is linear light, as compositors expect.
float srgb_to_linear(std::uint8_t byte) {
    const float c = static_cast<float>(byte) / 255.0f;
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

}  // namespace

const FeatureLayers::Layer* FeatureLayers::find(std::string_view name) const {
    for (const Layer& c : channels)
        if (c.name == name) return &c;
    return nullptr;
}

void gather_feature_layers(const FrameLayers& layers, FeatureLayers& out) {
    const int w = layers.image.width(), h = layers.image.height();
    const std::size_t pixels = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
    out.width = w;
    out.height = h;
    out.channels.clear();
    auto check = [&](const auto& image, std::string_view what) -> decltype(auto) {
        if (image.size() != pixels)
            throw Error(fmt::format("EXR layers: the {} layer is {}x{} in a {}x{} frame", what,
                                    image.width(), image.height(), w, h));
        return image.data();
    };
    auto add = [&](std::string name, bool half) -> std::vector<float>& {
        FeatureLayers::Layer& layer = out.channels.emplace_back();
        layer.name = std::move(name);
        layer.half = half;
        layer.values.resize(pixels);
        return layer.values;
    };
    // Each channel is filled before the next is added: the reference `add` returns is used
    // only until then.
    auto channel = [&](std::string name, bool half, auto&& value) {
        std::vector<float>& values = add(std::move(name), half);
        for (std::size_t i = 0; i < pixels; ++i) values[i] = value(i);
    };
    const std::uint32_t* object = check(layers.object, "object");
    const std::uint32_t* material = check(layers.material, "material");
    const Rgb8* cel = check(layers.cel, "cel");
    const float* distance = check(layers.distance, "distance");
    const float* view_depth = check(layers.view_depth, "view depth");
    const Vec3f* normal = check(layers.normal, "normal");
    const std::uint8_t* band = check(layers.band, "band");
    const float* light = check(layers.light, "light");
    const Vec3f* position = check(layers.position, "position");
    const Vec2f* uv = check(layers.uv, "uv");
    auto seen = [&](std::size_t i) { return object[i] != kNoIndex; };
    for (int c = 0; c < 3; ++c)
        channel(std::string(1, "RGB"[c]), true,
                [&](std::size_t i) { return srgb_to_linear(cel[i][c]); });
    channel("A", true, [&](std::size_t i) { return seen(i) ? 1.0f : 0.0f; });
    channel("Z", false, [&](std::size_t i) { return seen(i) ? distance[i] : kExrBackgroundDepth; });
    channel("view_depth.Z", false,
            [&](std::size_t i) { return seen(i) ? view_depth[i] : kExrBackgroundDepth; });
    for (int c = 0; c < 3; ++c)
        channel(std::string("N.") + "XYZ"[c], false, [&](std::size_t i) { return normal[i][c]; });
    // Ids are exact as floats up to 2^24 (docs/exr.md).
    channel("object_id.id", false, [&](std::size_t i) {
        return seen(i) ? static_cast<float>(object[i]) : kExrBackgroundId;
    });
    channel("material_id.id", false, [&](std::size_t i) {
        return seen(i) ? static_cast<float>(material[i]) : kExrBackgroundId;
    });
    channel("band.index", false, [&](std::size_t i) {
        return band[i] == kNoBand ? kExrBackgroundId : static_cast<float>(band[i]);
    });
    channel("light.L", false, [&](std::size_t i) { return light[i]; });
    for (int c = 0; c < 3; ++c)
        channel(std::string("P.") + "XYZ"[c], false, [&](std::size_t i) { return position[i][c]; });
    channel("uv.U", false, [&](std::size_t i) { return uv[i].x; });
    channel("uv.V", false, [&](std::size_t i) { return uv[i].y; });
    // Line coverage: all lines, then each type the mode tells apart.
    const float* all = check(layers.lines, "lines");
    channel("lines.all", true, [&](std::size_t i) { return all[i]; });
    for (const LineLayer& type : layers.line_types) {
        const float* coverage = check(type.coverage, type.name);
        channel("lines." + std::string(type.name), true,
                [&](std::size_t i) { return coverage[i]; });
    }
    // The tone look's coverage, where the mode draws one (ink).
    if (layers.mode == LineMode::Ink) {
        const float* tone = check(layers.tone, "tone");
        channel("tone.coverage", true, [&](std::size_t i) { return tone[i]; });
    }
}

void write_feature_exr(const std::filesystem::path& path, const FeatureLayers& layers,
                       const OutputRecord& record) {
    std::vector<ExrChannel> channels;
    channels.reserve(layers.channels.size());
    for (const FeatureLayers::Layer& layer : layers.channels)
        channels.push_back(
            {layer.name, layer.half ? ExrSample::Half : ExrSample::Float, layer.values});
    std::vector<ExrAttribute> attributes;
    if (!record.software.empty()) attributes.emplace_back("software", record.software);
    if (!record.settings.empty()) attributes.emplace_back("toonraySettings", record.settings);
    write_exr(path, layers.width, layers.height, channels, attributes);
}

std::uint64_t feature_exr_bytes(std::uint64_t pixels) {
    // Up to 30 channels of 4 bytes, their half copies and the compressed file (at most about
    // the raw size again).
    return mul_saturated(pixels, 30 * 4 * 3);
}

}  // namespace toonray
