#include "toonray/frame/feature_images.h"

#include <fmt/format.h>
#include <limits>

#include "toonray/core/error.h"
#include "toonray/ink/draw.h"
#include "toonray/render/classic.h"
#include "toonray/render/surface.h"

namespace toonray {
namespace {

// A normal's bytes: each channel's n * 0.5 + 0.5.
Rgb8 normal_colour(const Vec3f& n) {
    return {to_byte(n.x * 0.5f + 0.5f), to_byte(n.y * 0.5f + 0.5f), to_byte(n.z * 0.5f + 0.5f)};
}

std::string fmt_layer_size(std::string_view what, int w, int h, int frame_w, int frame_h) {
    return fmt::format(
        "feature images: the {} layer is {}x{} in a {}x{} frame (the frame was "
        "rendered without its layers)",
        what, w, h, frame_w, frame_h);
}

std::string fmt_missing_layer(std::string_view name) {
    return fmt::format("feature images: the frame has no {} line layer", name);
}

template <typename T>
const T& sized(const T& image, const FrameLayers& layers, std::string_view what) {
    if (image.width() != layers.image.width() || image.height() != layers.image.height())
        throw Error(fmt_layer_size(what, image.width(), image.height(), layers.image.width(),
                                   layers.image.height()));
    return image;
}

void gray(const ImageF& coverage, FeatureBytes& out) {
    out.channels = 1;
    ink::coverage_to_gray(coverage, out.gray);
}

void line_type(const FrameLayers& layers, std::string_view name, FeatureBytes& out) {
    const LineLayer* layer = layers.line_type(name);
    if (!layer) throw Error(fmt_missing_layer(name));
    gray(sized(layer->coverage, layers, name), out);
}

// The depth map: classic's distances, the other modes' view depths (lighter is farther, scaled
// by the frame's farthest surface, 255 where nothing is seen).
void depth(const FrameLayers& l, int threads, FeatureBytes& out) {
    out.channels = 1;
    classic_depth_map(sized(l.mode == LineMode::Classic ? l.distance : l.view_depth, l, "depth"),
                      out.gray, threads);
}

// The normal map: classic's, of the shading normals, as its lines see it; the other modes'
// geometric normals.
void normal(const FrameLayers& l, int threads, FeatureBytes& out) {
    out.channels = 3;
    if (l.mode == LineMode::Classic) {
        classic_normal_map(sized(l.normal, l, "normal"), l.distance, out.rgb, threads);
        return;
    }
    const Image<Vec3f>& n = sized(l.geometric_normal, l, "geometric normal");
    out.rgb.reshape(n.width(), n.height());
    for (std::size_t i = 0; i < n.size(); ++i)
        out.rgb.data()[i] =
            l.object.data()[i] == kNoIndex ? Rgb8{0, 0, 0} : normal_colour(n.data()[i]);
}

void ids(const Image<std::uint32_t>& ids, const FrameLayers& l, std::string_view what,
         FeatureBytes& out) {
    out.channels = 3;
    sized(ids, l, what);
    out.rgb.reshape(ids.width(), ids.height());
    for (std::size_t i = 0; i < ids.size(); ++i) out.rgb.data()[i] = id_colour(ids.data()[i]);
}

constexpr FeatureImage kImages[] = {
    {"depth", true, true, true, depth},
    {"normal", true, true, true, normal},
    {"edges_depth", true, false, false,
     [](const FrameLayers& l, int, FeatureBytes& out) { line_type(l, "depth", out); }},
    {"edges_normal", true, false, false,
     [](const FrameLayers& l, int, FeatureBytes& out) { line_type(l, "normal", out); }},
    {"edges", true, true, true,
     [](const FrameLayers& l, int, FeatureBytes& out) { gray(sized(l.lines, l, "lines"), out); }},
    {"tone", false, false, true,
     [](const FrameLayers& l, int, FeatureBytes& out) { gray(sized(l.tone, l, "tone"), out); }},
    {"cel", true, true, true,
     [](const FrameLayers& l, int, FeatureBytes& out) {
         out.channels = 3;
         out.rgb = sized(l.cel, l, "cel");
     }},
    {"lines_silhouette", false, true, true,
     [](const FrameLayers& l, int, FeatureBytes& out) { line_type(l, "silhouette", out); }},
    {"lines_crease", false, true, true,
     [](const FrameLayers& l, int, FeatureBytes& out) { line_type(l, "crease", out); }},
    {"lines_depth", false, true, false,
     [](const FrameLayers& l, int, FeatureBytes& out) { line_type(l, "depth", out); }},
    {"lines_object", false, true, false,
     [](const FrameLayers& l, int, FeatureBytes& out) { line_type(l, "object", out); }},
    {"lines_material", false, true, true,
     [](const FrameLayers& l, int, FeatureBytes& out) { line_type(l, "material", out); }},
    {"lines_border", false, false, true,
     [](const FrameLayers& l, int, FeatureBytes& out) { line_type(l, "border", out); }},
    {"lines_intersection", false, false, true,
     [](const FrameLayers& l, int, FeatureBytes& out) { line_type(l, "intersection", out); }},
    {"lines_polyline", false, false, true,
     [](const FrameLayers& l, int, FeatureBytes& out) { line_type(l, "polyline", out); }},
    {"lines_band", false, false, true,
     [](const FrameLayers& l, int, FeatureBytes& out) { line_type(l, "band", out); }},
    {"lines_shadow", false, false, true,
     [](const FrameLayers& l, int, FeatureBytes& out) { line_type(l, "shadow", out); }},
    {"object_id", false, true, true,
     [](const FrameLayers& l, int, FeatureBytes& out) { ids(l.object, l, "object", out); }},
    {"material_id", false, true, true,
     [](const FrameLayers& l, int, FeatureBytes& out) { ids(l.material, l, "material", out); }},
    {"samples", false, true, true,
     [](const FrameLayers& l, int, FeatureBytes& out) {
         const Image<std::uint8_t>& refined = sized(l.refined, l, "refined");
         out.channels = 1;
         out.gray.reshape(refined.width(), refined.height());
         for (std::size_t i = 0; i < refined.size(); ++i)
             out.gray.data()[i] = refined.data()[i] ? 0 : 255;
     }},
};

}  // namespace

Rgb8 id_colour(std::uint32_t id) {
    if (id == kNoIndex) return {0, 0, 0};
    std::uint32_t h = id * 2654435761u;
    h ^= h >> 15;
    return {static_cast<std::uint8_t>(64 + (h & 127)),
            static_cast<std::uint8_t>(64 + ((h >> 8) & 127)),
            static_cast<std::uint8_t>(64 + ((h >> 16) & 127))};
}

std::span<const FeatureImage> feature_images() { return kImages; }

std::uint64_t feature_image_bytes_per_pixel() { return sizeof(Rgb8); }

}  // namespace toonray
