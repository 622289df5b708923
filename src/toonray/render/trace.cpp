// Sample directions must round exactly as written (the tests compare them bit for bit with
// normalize(view.pixel_point(...) - view.eye)): the project compiles with -ffp-contract=off.
#include "toonray/render/trace.h"

#include "toonray/core/simd_sse.h"

#include <algorithm>
#include <array>

#include "toonray/core/parallel.h"

namespace toonray {
namespace {

constexpr int kTile = 16;

// The directions of samples [x0, x1) x [y0, y1), row by row, four at a time: the same IEEE
// operations in the same order as normalize(view.pixel_point(fx, fy) - view.eye) with
// fx = x + 0.5 (times 1 / sub when sub > 1), so every direction is bit-identical to that.
void tile_dirs(const ViewPlane& view, int x0, int x1, int y0, int y1, int sub, float inv_sub,
               Vec3f* dirs) {
    const int tw = x1 - x0;
    // upper_left + step_x * fx, per column (pixel_point adds step_y * fy to it afterwards).
    alignas(16) float col[3][kTile] = {};
    for (int i = 0; i < tw; ++i) {
        const float fx = sub == 1 ? static_cast<float>(x0 + i) + 0.5f
                                  : (static_cast<float>(x0 + i) + 0.5f) * inv_sub;
        for (int c = 0; c < 3; ++c) col[c][i] = view.upper_left[c] + view.step_x[c] * fx;
    }
    const __m128 ex = _mm_set1_ps(view.eye.x), ey = _mm_set1_ps(view.eye.y),
                 ez = _mm_set1_ps(view.eye.z);
    int k = 0;
    for (int y = y0; y < y1; ++y) {
        const float fy =
            sub == 1 ? static_cast<float>(y) + 0.5f : (static_cast<float>(y) + 0.5f) * inv_sub;
        const __m128 sy_x = _mm_set1_ps(view.step_y.x * fy), sy_y = _mm_set1_ps(view.step_y.y * fy),
                     sy_z = _mm_set1_ps(view.step_y.z * fy);
        for (int i = 0; i < tw; i += 4) {
            const __m128 dx = _mm_sub_ps(_mm_add_ps(_mm_load_ps(col[0] + i), sy_x), ex);
            const __m128 dy = _mm_sub_ps(_mm_add_ps(_mm_load_ps(col[1] + i), sy_y), ey);
            const __m128 dz = _mm_sub_ps(_mm_add_ps(_mm_load_ps(col[2] + i), sy_z), ez);
            const __m128 len = _mm_sqrt_ps(
                _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz)));
            alignas(16) float nx[4], ny[4], nz[4];
            _mm_store_ps(nx, _mm_div_ps(dx, len));
            _mm_store_ps(ny, _mm_div_ps(dy, len));
            _mm_store_ps(nz, _mm_div_ps(dz, len));
            const int n = std::min(4, tw - i);
            for (int l = 0; l < n; ++l) dirs[k++] = Vec3f(nx[l], ny[l], nz[l]);
        }
    }
}

}  // namespace

void trace_primary(const TriangleAccel& accel, const ViewPlane& view, int width, int height,
                   int sub, int threads, const TileShader& shade) {
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
            tile_dirs(view, t.x0, t.x1, t.y0, t.y1, sub, inv_sub, dirs.data());
            // The whole tile at once: a frustum of ray packets, with exactly the hits that
            // accel.intersect gives ray by ray.
            accel.intersect_tile(view.eye, dirs.data(), t.x1 - t.x0, t.y1 - t.y0, hits.data(),
                                 found.data());
            t.dirs = dirs.data();
            t.hits = hits.data();
            t.found = found.data();
            shade(t);
        }
    });
}

}  // namespace toonray
