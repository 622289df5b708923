#include "toonray/frame/feature_exr.h"

#include <algorithm>
#include <cmath>

#include "toonray/core/saturating.h"
#include "toonray/ink/draw.h"
#include "toonray/io/exr.h"
#include "toonray/render/shading.h"
#include "toonray/render/trace.h"

namespace toonray {

namespace {

// The sRGB transfer function undone: EXR colour is linear light, as compositors expect.
float srgb_to_linear(std::uint8_t byte) {
    const float c = static_cast<float>(byte) / 255.0f;
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

// Coverage 0..1 from a black-on-white line image (255 = no line).
void coverage_of(const ImageGray8& lines, std::vector<float>& out) {
    out.resize(lines.size());
    for (std::size_t i = 0; i < lines.size(); ++i)
        out[i] = 1.0f - static_cast<float>(lines.data()[i]) / 255.0f;
}

FeatureLayers::Layer* find_mutable(FeatureLayers& layers, std::string_view name) {
    for (FeatureLayers::Layer& c : layers.channels)
        if (c.name == name) return &c;
    return nullptr;
}

}  // namespace

const FeatureLayers::Layer* FeatureLayers::find(std::string_view name) const {
    for (const Layer& c : channels)
        if (c.name == name) return &c;
    return nullptr;
}

void gather_feature_layers(const Scene& scene, const TriangleAccel& accel, const CameraSpec& camera,
                           const RenderSettings& settings, const Renderer& renderer,
                           FeatureLayers& out, const ImageF* polylines) {
    const int w = settings.width, h = settings.height;
    const std::size_t pixels = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
    out.width = w;
    out.height = h;
    out.channels.clear();
    auto add = [&](std::string name, bool half, float fill = 0.0f) -> std::vector<float>& {
        FeatureLayers::Layer& layer = out.channels.emplace_back();
        layer.name = std::move(name);
        layer.half = half;
        layer.values.assign(pixels, fill);
        return layer.values;
    };
    // Reserve first: the references `add` returns must stay valid.
    out.channels.reserve(24);

    // Geometry at each pixel's centre, one ray a pixel.
    std::vector<float>& alpha = add("A", true);
    std::vector<float>& distance = add("Z", false, kExrBackgroundDepth);
    std::vector<float>& view_depth = add("view_depth.Z", false, kExrBackgroundDepth);
    std::vector<float>& nx = add("N.X", false);
    std::vector<float>& ny = add("N.Y", false);
    std::vector<float>& nz = add("N.Z", false);
    std::vector<float>& object = add("object_id.id", false, kExrBackgroundId);
    std::vector<float>& material = add("material_id.id", false, kExrBackgroundId);
    const ViewPlane view = make_view_plane(camera, w, h);
    trace_primary(accel, view, w, h, 1, settings.threads, [&](const SampleTile& t) {
        for (int y = t.y0; y < t.y1; ++y)
            for (int x = t.x0; x < t.x1; ++x) {
                const std::size_t s = static_cast<std::size_t>(y - t.y0) * t.width() + (x - t.x0);
                if (!t.found[s]) continue;
                const Hit& hit = t.hits[s];
                const std::size_t i = static_cast<std::size_t>(y) * w + x;
                const Vec3f n = shading_normal(scene, hit, t.dirs[s]);
                alpha[i] = 1.0f;
                distance[i] = hit.t;
                view_depth[i] = hit.t * dot(t.dirs[s], view.forward);
                nx[i] = n.x;
                ny[i] = n.y;
                nz[i] = n.z;
                // Exact as floats up to 2^24 ids (docs/exr.md).
                object[i] = static_cast<float>(scene.tri_object[hit.prim]);
                material[i] = static_cast<float>(scene.tri_material[hit.prim]);
            }
    });

    // The cel colour, from the renderer's feature image.
    const Aovs& aovs = renderer.aovs();
    std::vector<float>& r = add("R", true);
    std::vector<float>& g = add("G", true);
    std::vector<float>& b = add("B", true);
    if (aovs.cel.size() == pixels)
        for (std::size_t i = 0; i < pixels; ++i) {
            const Rgb8 c = aovs.cel.data()[i];
            r[i] = srgb_to_linear(c[0]);
            g[i] = srgb_to_linear(c[1]);
            b[i] = srgb_to_linear(c[2]);
        }

    // Line coverage: all lines, then each type the mode tells apart.
    auto add_lines = [&](const char* type, const ImageGray8& image) {
        if (image.size() != pixels) return;
        coverage_of(image, add(std::string("lines.") + type, true));
    };
    if (settings.edges == EdgeMode::Ink) {
        const ink::InkLines& ink = renderer.ink_lines();
        std::vector<float>& all = add("lines.all", true);
        if (ink.coverage.size() == pixels)
            all.assign(ink.coverage.data(), ink.coverage.data() + pixels);
        // Each type drawn on its own, as the renderer draws all visible strokes together.
        const float thickness = ink::stroke_thickness(settings.lines.width, h);
        for (int type = 0; type < ink::kEdgeTypeCount; ++type) {
            std::vector<ink::Stroke> strokes;
            for (const ink::Stroke& s : ink.strokes)
                if (s.visible && static_cast<int>(s.type) == type) strokes.push_back(s);
            ImageF coverage(w, h, 0.0f);
            ink::draw_strokes(strokes, thickness, coverage, settings.threads);
            add(std::string("lines.") + ink::edge_type_name(static_cast<ink::EdgeType>(type)), true)
                .assign(coverage.data(), coverage.data() + pixels);
        }
    } else {
        add_lines("all", aovs.edges);
        if (settings.edges == EdgeMode::Classic) {
            add_lines("depth", aovs.edges_depth);
            add_lines("normal", aovs.edges_normal);
        } else {
            add_lines("silhouette", aovs.lines_silhouette);
            add_lines("crease", aovs.lines_crease);
            add_lines("depth", aovs.lines_depth);
            add_lines("object", aovs.lines_object);
            add_lines("material", aovs.lines_material);
        }
        if (polylines && polylines->size() == pixels) {
            add("lines.polyline", true).assign(polylines->data(), polylines->data() + pixels);
            if (FeatureLayers::Layer* all = find_mutable(out, "lines.all"))
                for (std::size_t i = 0; i < pixels; ++i)
                    all->values[i] = std::max(all->values[i], polylines->data()[i]);
        }
    }
}

void write_feature_exr(const std::filesystem::path& path, const FeatureLayers& layers) {
    std::vector<ExrChannel> channels;
    channels.reserve(layers.channels.size());
    for (const FeatureLayers::Layer& layer : layers.channels)
        channels.push_back(
            {layer.name, layer.half ? ExrSample::Half : ExrSample::Float, layer.values});
    write_exr(path, layers.width, layers.height, channels);
}

std::uint64_t feature_exr_bytes(std::uint64_t pixels) {
    // Up to 24 channels of 4 bytes, their half copies and the compressed file (at most about
    // the raw size again), and one ink coverage image while the types are drawn.
    return mul_saturated(pixels, 24 * 4 * 3 + 4);
}

}  // namespace toonray
