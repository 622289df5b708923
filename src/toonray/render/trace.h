#pragma once
/// Primary rays: one per sample on a regular grid of sub x sub samples per pixel. Sample
/// (x, y) of the fine grid goes through view.pixel_point((x + 0.5) / sub, (y + 0.5) / sub)
/// (exactly the pixel centre when sub = 1) from view.eye, with a unit direction. Tracing runs
/// tile by tile; each finished tile is handed to a callback that shades it, so tracing can
/// batch rays however it likes (packets, frustums) while shading stays per sample.

#include <functional>

#include "toonray/accel/triangle_accel.h"
#include "toonray/scene/camera.h"

namespace toonray {

/// A finished tile: samples [x0, x1) x [y0, y1) of the fine grid, row-major, with each ray's
/// unit direction, whether it hit, and the hit.
struct SampleTile {
    int x0, y0, x1, y1;
    const Vec3f* dirs;
    const Hit* hits;
    const bool* found;

    [[nodiscard]] int width() const { return x1 - x0; }
};

using TileShader = std::function<void(const SampleTile&)>;

/// The unit direction of fine-grid sample (x, y) with `sub` samples per pixel side:
/// normalize(view.pixel_point(fx, fy) - view.eye), fx = (x + 0.5) / sub (x + 0.5 when sub is
/// 1), rounded exactly as every other way this file makes directions.
Vec3f sample_direction(const ViewPlane& view, int x, int y, int sub);

/// The directions of every fine-grid sample (xs[i], ys[j]), row by row (j outer), into dirs
/// (nx * ny of them): bit-identical to sample_direction, four at a time.
void grid_directions(const ViewPlane& view, int sub, const int* xs, int nx, const int* ys, int ny,
                     Vec3f* dirs);

/// Traces the samples of a width x height image with sub x sub samples per pixel. Tiles run
/// in parallel on `threads` threads (0 = all); each is shaded by exactly one call, so results
/// never depend on the thread count.
void trace_primary(const TriangleAccel& accel, const ViewPlane& view, int width, int height,
                   int sub, int threads, const TileShader& shade);

}  // namespace toonray
