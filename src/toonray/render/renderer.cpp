#include "toonray/render/renderer.h"

#include <cmath>
#include <limits>

#include "toonray/core/parallel.h"
#include "toonray/render/classic.h"

namespace toonray {
namespace {

constexpr int kTile = 16;

// Shading normal at a hit: interpolated vertex normals when all three corners have one,
// else the geometric normal; turned to face the viewer.
Vec3f shading_normal(const Scene& scene, const Hit& hit, const Vec3f& dir) {
    const auto& tri = scene.tri_positions[hit.prim];
    const auto& tn = scene.tri_normals[hit.prim];
    Vec3f n;
    bool interpolated = false;
    if (tn[0] != kNoIndex && tn[1] != kNoIndex && tn[2] != kNoIndex) {
        float w0 = 1.0f - hit.u - hit.v;
        n = scene.normals[tn[0]] * w0 + scene.normals[tn[1]] * hit.u + scene.normals[tn[2]] * hit.v;
        float len = length(n);
        if (len > 0.0f && std::isfinite(len)) {
            n = n / len;
            interpolated = true;
        }
    }
    if (!interpolated) {
        const Vec3f& p0 = scene.positions[tri[0]];
        n = cross(scene.positions[tri[1]] - p0, scene.positions[tri[2]] - p0);
        float len = length(n);
        n = len > 0.0f ? n / len : -normalize(dir);
    }
    return dot(n, dir) > 0.0f ? -n : n;
}

}  // namespace

Vec3f default_light(const Scene& scene, const ViewPlane& view) {
    BBox b = scene.bounds();
    float radius = b.empty() ? 1.0f : 0.5f * length(b.extent());
    return view.eye + (view.up + view.right) * (0.5f * radius);
}

void Renderer::trace(const Scene& scene, const TriangleAccel& accel, const ViewPlane& view,
                     const RenderSettings& settings) {
    const int w = settings.width, h = settings.height;
    const float inf = std::numeric_limits<float>::infinity();
    gbuffer_.distance.resize(w, h, inf);
    gbuffer_.normal.resize(w, h);
    gbuffer_.colour.resize(w, h);
    gbuffer_.material.resize(w, h, kNoIndex);
    gbuffer_.object.resize(w, h, kNoIndex);

    const int tiles_x = (w + kTile - 1) / kTile, tiles_y = (h + kTile - 1) / kTile;
    parallel_for(tiles_x * tiles_y, 1, settings.threads, [&](int begin, int end) {
        for (int tile = begin; tile < end; ++tile) {
            int x0 = (tile % tiles_x) * kTile, y0 = (tile / tiles_x) * kTile;
            int x1 = std::min(x0 + kTile, w), y1 = std::min(y0 + kTile, h);
            for (int y = y0; y < y1; ++y)
                for (int x = x0; x < x1; ++x) {
                    Vec3f target = view.pixel_point(x + 0.5f, y + 0.5f);
                    Vec3f dir = normalize(target - view.eye);
                    Ray ray{view.eye, dir};
                    Hit hit;
                    if (!accel.intersect(ray, hit)) {
                        gbuffer_.distance(x, y) = inf;
                        gbuffer_.normal(x, y) = Vec3f(0.0f);
                        gbuffer_.colour(x, y) = settings.background;
                        gbuffer_.material(x, y) = kNoIndex;
                        gbuffer_.object(x, y) = kNoIndex;
                        continue;
                    }
                    Vec3f n = shading_normal(scene, hit, dir);
                    Vec3f p = view.eye + dir * hit.t;
                    Vec3f to_light = light_ - p;
                    float len = length(to_light);
                    float l_dot_n = len > 0.0f ? dot(to_light, n) / len : 1.0f;
                    std::uint32_t m = scene.tri_material[hit.prim];
                    gbuffer_.distance(x, y) = hit.t;
                    gbuffer_.normal(x, y) = n;
                    gbuffer_.colour(x, y) = scene.materials[m].kd * classic_cel_level(l_dot_n);
                    gbuffer_.material(x, y) = m;
                    gbuffer_.object(x, y) = scene.tri_object[hit.prim];
                }
        }
    });
}

const ImageRgb8& Renderer::render(const Scene& scene, const TriangleAccel& accel,
                                  const CameraSpec& camera, const RenderSettings& settings) {
    ViewPlane view = make_view_plane(camera, settings.width, settings.height);
    light_ = settings.light ? *settings.light : default_light(scene, view);
    trace(scene, accel, view, settings);

    const int threads = settings.threads;
    classic_depth_map(gbuffer_.distance, aovs_.depth, threads);
    classic_normal_map(gbuffer_.normal, gbuffer_.distance, aovs_.normal, threads);
    sobel_edges(aovs_.depth, settings.depth_threshold, aovs_.edges_depth, threads);
    sobel_edges(aovs_.normal, settings.normal_threshold, aovs_.edges_normal, threads);
    merge_edges(aovs_.edges_depth, aovs_.edges_normal, aovs_.edges);
    compose_lines(gbuffer_.colour, aovs_.edges, final_, threads);

    aovs_.cel.resize(settings.width, settings.height);
    for (std::size_t i = 0; i < aovs_.cel.size(); ++i) {
        const Vec3f& c = gbuffer_.colour.data()[i];
        aovs_.cel.data()[i] = {to_byte(c.x), to_byte(c.y), to_byte(c.z)};
    }
    return final_;
}

}  // namespace toonray
