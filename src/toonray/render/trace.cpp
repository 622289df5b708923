#include "toonray/render/trace.h"

#include <algorithm>
#include <array>

#include "toonray/core/parallel.h"

namespace toonray {

void trace_primary(const TriangleAccel& accel, const ViewPlane& view, int width, int height, int sub,
                   int threads, const TileShader& shade) {
    constexpr int kTile = 16;
    const int w = width * sub, h = height * sub;
    const float inv_sub = 1.0f / static_cast<float>(sub);
    const int tiles_x = (w + kTile - 1) / kTile, tiles_y = (h + kTile - 1) / kTile;
    parallel_for(tiles_x * tiles_y, 1, threads, [&](int begin, int end) {
        std::array<Vec3f, kTile * kTile> dirs;
        std::array<Hit, kTile * kTile> hits;
        std::array<bool, kTile * kTile> found;
        for (int tile = begin; tile < end; ++tile) {
            SampleTile t;
            t.x0 = (tile % tiles_x) * kTile;
            t.y0 = (tile / tiles_x) * kTile;
            t.x1 = std::min(t.x0 + kTile, w);
            t.y1 = std::min(t.y0 + kTile, h);
            int i = 0;
            for (int y = t.y0; y < t.y1; ++y)
                for (int x = t.x0; x < t.x1; ++x, ++i) {
                    Vec3f target = sub == 1 ? view.pixel_point(x + 0.5f, y + 0.5f)
                                            : view.pixel_point((x + 0.5f) * inv_sub, (y + 0.5f) * inv_sub);
                    dirs[i] = normalize(target - view.eye);
                }
            // The whole tile at once: a frustum of ray packets, with exactly the hits that
            // accel.intersect gives ray by ray.
            accel.intersect_tile(view.eye, dirs.data(), t.x1 - t.x0, t.y1 - t.y0, hits.data(), found.data());
            t.dirs = dirs.data();
            t.hits = hits.data();
            t.found = found.data();
            shade(t);
        }
    });
}

}  // namespace toonray
