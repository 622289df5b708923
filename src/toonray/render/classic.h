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

/// lroundf(x) (halves away from zero) as plain float operations that vectorise, for
/// |x| < 2^23: x - trunc(x) is exact there, so the result is bit-identical to lroundf.
inline int round_half_away(float x) {
    const int i = static_cast<int>(x);
    const float fraction = x - static_cast<float>(i);
    return i + static_cast<int>(fraction >= 0.5f) - static_cast<int>(fraction <= -0.5f);
}

/// The largest finite value of an image, or 0 when there is none (or all are negative).
float largest_finite(const ImageF& image);

/// round(t / t_max * 255) over hits (t_max = largest hit distance); misses (t = inf) are 255.
void classic_depth_map(const ImageF& distance, ImageGray8& out, int threads);

/// round((n * 0.5 + 0.5) * 255) per channel; misses (zero normal) are (0, 0, 0).
/// One channel of the normal map: round((n * 0.5 + 0.5) * 255).
inline std::uint8_t normal_channel_to_byte(float n) {
    return static_cast<std::uint8_t>(round_half_away((n * 0.5f + 0.5f) * 255.0f));
}

void classic_normal_map(const Image<Vec3f>& normals, const ImageF& distance, ImageRgb8& out,
                        int threads);

/// Sobel magnitude sqrt(gx^2 + gy^2) with clamped borders; edge pixels (magnitude > threshold)
/// become 0, others 255 (black lines on white).
void sobel_edges(const ImageGray8& in, float threshold, ImageGray8& edges, int threads);

/// As above for RGB: magnitude is sqrt of the sum over channels of gx^2 + gy^2.
void sobel_edges(const ImageRgb8& in, float threshold, ImageGray8& edges, int threads);

/// Merged edges: a pixel is an edge (0) when it is one in either image.
void merge_edges(const ImageGray8& a, const ImageGray8& b, ImageGray8& out);

/// final = colour * blur(E), E = 0 on edges and 1 elsewhere, blur [1 2 1; 2 4 2; 1 2 1] / 16
/// with clamped borders; written as round(clamp(c, 0, 1) * 255). With `cel`, also writes the
/// colours without lines there (to_byte(c)) in the same pass, so the colours are read once.
void compose_lines(const Image<Vec3f>& colour, const ImageGray8& edges, ImageRgb8& out, int threads,
                   ImageRgb8* cel = nullptr);

/// 8-bit conversion used for every colour output: round(clamp(c, 0, 1) * 255).
inline std::uint8_t to_byte(float c) {
    c = c < 0.0f ? 0.0f : (c > 1.0f ? 1.0f : c);
    return static_cast<std::uint8_t>(c * 255.0f + 0.5f);
}

/// to_byte over n values, sixteen at a time (the same bytes).
void to_bytes(const float* values, int n, std::uint8_t* bytes);

}  // namespace toonray
