// Sample directions must round exactly as written (the tests compare them bit for bit with
// normalize(view.pixel_point(...) - view.eye)): the project compiles with -ffp-contract=off.
#include "toonray/render/trace.h"

#include "toonray/core/simd_sse.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "toonray/core/parallel.h"

namespace toonray {
namespace {

constexpr int kTile = TriangleAccel::kTileSize;
// grid_directions' columns per pass (its stack buffer), a multiple of 4.
constexpr int kColumnBlock = 64;

// The sample coordinate of fine index i on the image plane, in pixels: (i + 0.5) / sub.
inline float sample_coordinate(int i, int sub) {
    return sub == 1 ? static_cast<float>(i) + 0.5f
                    : (static_cast<float>(i) + 0.5f) * (1.0f / static_cast<float>(sub));
}

}  // namespace

Vec3f sample_direction(const ViewPlane& view, int x, int y, int sub) {
    const float fx = sample_coordinate(x, sub), fy = sample_coordinate(y, sub);
    // The operations of grid_directions in its order: the column's point, then the row's step,
    // then the eye; the length as (dx^2 + dy^2) + dz^2.
    float d[3];
    for (int c = 0; c < 3; ++c) {
        const float column = view.upper_left[c] + view.step_x[c] * fx;
        d[c] = (column + view.step_y[c] * fy) - view.eye[c];
    }
    const float len = std::sqrt((d[0] * d[0] + d[1] * d[1]) + d[2] * d[2]);
    return {d[0] / len, d[1] / len, d[2] / len};
}

void grid_directions(const ViewPlane& view, int sub, const int* xs, int nx, const int* ys, int ny,
                     Vec3f* dirs) {
    const __m128 ex = _mm_set1_ps(view.eye.x), ey = _mm_set1_ps(view.eye.y),
                 ez = _mm_set1_ps(view.eye.z);
    for (int c0 = 0; c0 < nx; c0 += kColumnBlock) {
        const int cw = std::min(kColumnBlock, nx - c0);
        // upper_left + step_x * fx, per column (pixel_point adds step_y * fy to it afterwards).
        alignas(16) float col[3][kColumnBlock] = {};
        for (int i = 0; i < cw; ++i) {
            const float fx = sample_coordinate(xs[c0 + i], sub);
            for (int c = 0; c < 3; ++c) col[c][i] = view.upper_left[c] + view.step_x[c] * fx;
        }
        for (int j = 0; j < ny; ++j) {
            const float fy = sample_coordinate(ys[j], sub);
            const __m128 sy_x = _mm_set1_ps(view.step_y.x * fy),
                         sy_y = _mm_set1_ps(view.step_y.y * fy),
                         sy_z = _mm_set1_ps(view.step_y.z * fy);
            Vec3f* out = dirs + static_cast<std::size_t>(j) * nx + c0;
            for (int i = 0; i < cw; i += 4) {
                const __m128 dx = _mm_sub_ps(_mm_add_ps(_mm_load_ps(col[0] + i), sy_x), ex);
                const __m128 dy = _mm_sub_ps(_mm_add_ps(_mm_load_ps(col[1] + i), sy_y), ey);
                const __m128 dz = _mm_sub_ps(_mm_add_ps(_mm_load_ps(col[2] + i), sy_z), ez);
                const __m128 len = _mm_sqrt_ps(_mm_add_ps(
                    _mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz)));
                alignas(16) float ux[4], uy[4], uz[4];
                _mm_store_ps(ux, _mm_div_ps(dx, len));
                _mm_store_ps(uy, _mm_div_ps(dy, len));
                _mm_store_ps(uz, _mm_div_ps(dz, len));
                const int n = std::min(4, cw - i);
                for (int l = 0; l < n; ++l) out[i + l] = Vec3f(ux[l], uy[l], uz[l]);
            }
        }
    }
}

void trace_primary(const TriangleAccel& accel, const ViewPlane& view, int width, int height,
                   int sub, int threads, const TileShader& shade) {
    const int w = width * sub, h = height * sub;
    const int tiles_x = (w + kTile - 1) / kTile, tiles_y = (h + kTile - 1) / kTile;
    parallel_for(tiles_x * tiles_y, 1, threads, [&](int begin, int end) {
        std::array<Vec3f, kTile * kTile> dirs;
        std::array<Hit, kTile * kTile> hits;
        std::array<bool, kTile * kTile> found;
        std::array<int, kTile> xs, ys;
        for (int tile = begin; tile < end; ++tile) {
            SampleTile t;
            t.x0 = (tile % tiles_x) * kTile;
            t.y0 = (tile / tiles_x) * kTile;
            t.x1 = std::min(t.x0 + kTile, w);
            t.y1 = std::min(t.y0 + kTile, h);
            for (int i = 0; i < t.x1 - t.x0; ++i) xs[i] = t.x0 + i;
            for (int j = 0; j < t.y1 - t.y0; ++j) ys[j] = t.y0 + j;
            grid_directions(view, sub, xs.data(), t.x1 - t.x0, ys.data(), t.y1 - t.y0, dirs.data());
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
