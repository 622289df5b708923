#pragma once
/// The benchmark's larger scene, generated: no ~35k-triangle OBJ ships with the repository, and
/// generating one keeps the repository small while every machine times the same bytes.

#include <cstddef>
#include <filesystem>

namespace toonray::bench {

/// Writes `<dir>/scene35k.obj` and `<dir>/scene35k.mtl` and returns the OBJ path. The scene is
/// 34,968 triangles over four objects and four materials, with a camera block framing them:
///   blob    a displaced icosphere (subdivision level 5, 20,480 triangles, `f v//vn` with
///           per-vertex normals)
///   teapot  tests/data/teapot.obj, moved (6,320 triangles, `f v`)
///   spot    tests/data/spot.obj, scaled and moved (5,856 triangles, `f v/vt`)
///   ground  a 34 x 34 grid of quads split into triangles (2,312 triangles, `f v`)
/// Only IEEE arithmetic (+ - * / sqrt; no other libm calls) goes into the numbers, printed with 6
/// decimals, so the file is the same byte for byte wherever it is generated. `data_dir` holds
/// teapot.obj and spot.obj. Rewrites the files only when their content would change.
std::filesystem::path write_bench_scene(const std::filesystem::path& dir,
                                        const std::filesystem::path& data_dir);

/// Writes `<dir>/scan70k.obj` and returns its path: tests/data/spot.obj (in `data_dir`) with
/// each triangle cut into 4 at its edge midpoints (one vertex per edge, shared by the triangles
/// on both sides), then each of those into 3 at its centroid: 70,272 triangles over 35,138
/// vertices, `f v` only (no normals, no texture coordinates, one object, no materials), like a
/// scan, with a camera block framing the cow in a 16:9 frame. The same IEEE-only arithmetic
/// and printing as write_bench_scene, so the file is the same bytes everywhere; rewritten only
/// when its content would change.
std::filesystem::path write_scan_scene(const std::filesystem::path& dir,
                                       const std::filesystem::path& data_dir);

}  // namespace toonray::bench
