#pragma once
/// The seed's line pipeline, exactly (the `--edges classic` mode): 8-bit depth and normal maps,
/// a Sobel filter on each with its own threshold, the two edge images merged, softened by a
/// 3x3 binomial blur and multiplied onto the colours. Each step is its own function so tests
/// can pin it down.

#include <cstdint>

#include "toonray/core/image.h"
#include "toonray/core/math.h"

namespace toonray {

/// Cel band for a diffuse term: k = clamp(int(l.n * 16), 0, 15) into {0.5 x4, 0.75 x4, 1.0 x8}.
float classic_cel_level(float l_dot_n);

/// round(t / t_max * 255) over hits (t_max = largest hit distance); misses (t = inf) are 255.
void classic_depth_map(const ImageF& distance, ImageGray8& out, int threads);

/// round((n * 0.5 + 0.5) * 255) per channel; misses (zero normal) are (0, 0, 0).
void classic_normal_map(const Image<Vec3f>& normals, const ImageF& distance, ImageRgb8& out, int threads);

/// Sobel magnitude sqrt(gx^2 + gy^2) with clamped borders; edge pixels (magnitude > threshold)
/// become 0, others 255 (black lines on white).
void sobel_edges(const ImageGray8& in, float threshold, ImageGray8& edges, int threads);

/// As above for RGB: magnitude is sqrt of the sum over channels of gx^2 + gy^2.
void sobel_edges(const ImageRgb8& in, float threshold, ImageGray8& edges, int threads);

/// Merged edges: a pixel is an edge (0) when it is one in either image.
void merge_edges(const ImageGray8& a, const ImageGray8& b, ImageGray8& out);

/// final = colour * blur(E), E = 0 on edges and 1 elsewhere, blur [1 2 1; 2 4 2; 1 2 1] / 16
/// with clamped borders; written as round(clamp(c, 0, 1) * 255).
void compose_lines(const Image<Vec3f>& colour, const ImageGray8& edges, ImageRgb8& out, int threads);

/// 8-bit conversion used for every colour output: round(clamp(c, 0, 1) * 255).
inline std::uint8_t to_byte(float c) {
    c = c < 0.0f ? 0.0f : (c > 1.0f ? 1.0f : c);
    return static_cast<std::uint8_t>(c * 255.0f + 0.5f);
}

}  // namespace toonray
