#pragma once
/// The robust line mode (`--edges robust`): lines found on a supersampled G-buffer
/// by tests that do not misfire on planes at grazing angles or on finely tessellated meshes,
/// drawn with a width that scales with the image height, and anti-aliased by filtering the
/// fine grid down. Everything is on a fixed sub-pixel grid, so animations do not flicker.

#include <cstdint>
#include <string>

#include "toonray/core/image.h"
#include "toonray/core/math.h"
#include "toonray/render/line_settings.h"

namespace toonray {

/// The fine-grid inputs of the line tests; misses have depth +inf.
struct FineBuffers {
    const ImageF& depth;                   ///< view-space depth z (along the view direction)
    const Image<Vec3f>& geometric_normal;  ///< unit, facing the viewer; zero where the ray misses
    const Image<std::uint32_t>& object;
    const Image<std::uint32_t>& material;
};

/// Marks line seeds: each fine pixel gets the bits of the line types found between it and a
/// 4-neighbour, on the nearer of the two (the foreground owns the line). 0 = no line.
void find_line_seeds(const FineBuffers& fine, const LineSettings& settings,
                     Image<std::uint8_t>& seeds, int threads);

/// Squared Euclidean distance (in fine pixels) from every pixel to the nearest non-zero seed
/// (Felzenszwalb and Huttenlocher's linear-time transform, exact). +inf where there is none.
void distance_to_seeds(const Image<std::uint8_t>& seeds, ImageF& squared_distance, int threads);

/// The widest band distance_to_seeds_banded accepts. Its cost grows with the band (a window of
/// 2 * band + 1 columns), so beyond this the linear-time full transform is the faster one.
inline constexpr int kMaxDistanceBand = 64;

/// min(d^2, (band + 1)^2), d the Euclidean distance (in fine pixels) to the nearest non-zero
/// seed: the exact d^2 wherever d < band + 1, else (band + 1)^2 (also where there is no seed).
/// Looks only band pixels around each pixel, so it costs O(band) per pixel. Throws Error for a
/// band outside [0, kMaxDistanceBand].
void distance_to_seeds_banded(const Image<std::uint8_t>& seeds, int band,
                              Image<std::uint16_t>& squared_distance, int threads);

/// Line thickness in fine pixels for `width` (pixels at 720 lines), an image `height` pixels
/// tall and `sub` x `sub` samples per pixel: width * height / 720 * sub.
float line_thickness(float width, int height, int sub);

/// Filters the fine grid down. A fine sample at distance d from the nearest seed is covered by
/// clamp(thickness / 2 + 0.5 - d, 0, 1), which integrates to exactly `thickness` across a
/// straight line, so widths scale smoothly with resolution; a pixel's coverage is the mean
/// over its samples, and its colour the mean fine colour. Writes
/// final = colour * (1 - coverage) + line * coverage and, where not null, the mean colour
/// (`cel`) and the coverage as 8-bit (`lines`, 255 = no line: black lines on white).
void resolve_lines(const Image<Vec3f>& fine_colour, const ImageF& squared_distance, float thickness,
                   int sub, const Vec3f& line_colour, ImageRgb8& final_image, ImageRgb8* cel,
                   ImageGray8* lines, int threads);

/// Pixels around a bucket whose samples its lines depend on. A line covers fine samples
/// nearer than thickness / 2 + 0.5 to its seeds, and a seed depends on the samples next to it,
/// so the bucket's fine grid is grown by that reach plus one sample, in whole pixels.
[[nodiscard]] int robust_halo(float thickness, int sub);

/// The band of distance_to_seeds_banded that covers every fine pixel a line of `thickness`
/// reaches. Above kMaxDistanceBand, resolve_lines_from_seeds uses the full distance image.
int line_distance_band(float thickness);

/// Exactly distance_to_seeds followed by resolve_lines (the same bytes), without the full-size
/// distance image unless line_distance_band(thickness) > kMaxDistanceBand: strips of rows get
/// their distances from distance_to_seeds_banded's method, over the few pixels a line can reach
/// (see robust.cpp for why that is exact).
void resolve_lines_from_seeds(const Image<Vec3f>& fine_colour, const Image<std::uint8_t>& seeds,
                              float thickness, int sub, const Vec3f& line_colour,
                              ImageRgb8& final_image, ImageRgb8* cel, ImageGray8* lines,
                              int threads);

/// One line type's seeds filtered down to pixels (255 = none, 0 = a seed in every sample), for AOVs.
void resolve_seed_type(const Image<std::uint8_t>& seeds, unsigned type, int sub, ImageGray8& out,
                       int threads);

}  // namespace toonray
