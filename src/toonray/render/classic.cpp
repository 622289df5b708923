// Compiled with -fno-trapping-math (top-level CMakeLists.txt), so that GCC if-converts the float
// comparisons (the clamps and selects in to_byte, round_half_away and the maps) and the
// per-pixel loops vectorise. It changes no result, only which floating-point exception flags
// may be raised, and nothing in toonray reads those.
#include "toonray/render/classic.h"

#include "toonray/core/simd_sse.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "toonray/core/parallel.h"

// How these stay exactly the seed's pipeline while running as row loops GCC vectorises:
// - Sobel and the blur only ever see small integers (8-bit values, 0/1 edge flags), so they run
//   in int16/int32, where every sum and square is exact; the seed's float arithmetic on the same
//   integers was exact too (all values stay below 2^24), so the results are identical.
// - Both filters are separable. Sobel: gx = V(x+1) - V(x-1) and gy = D(x-1) + 2 D(x) + D(x+1),
//   with V = up + 2 mid + down and D = down - up per column; the blur is [1 2 1] across the
//   column sums [1 2 1]. Each row first builds V and D (or the column sums) in a scratch row
//   padded by one pixel on each side with the border values repeated, which is exactly the
//   clamped border, so the inner loops have no branches and no per-pixel clamping.
// - Each row's work is a function of plain pointers and counts: a loop bound read through a
//   lambda's closure or a reference could alias the byte stores, which stops GCC vectorising.
// - lroundf (a libm call per pixel) is replaced by round_half_away, which is bit-identical.
// - The float-to-byte conversions of the normal map and the compose step are explicit SSE
//   (four floats per vector, sixteen bytes per store), each the same IEEE operations in the same
//   order as its scalar form, which still handles the tail of each row.

namespace toonray {
namespace {

constexpr int kRowGrain = 16;

// Rows of Vec3f and Rgb8 pixels are also read and written as flat arrays of 3w channel values,
// which the per-value loops below vectorise without shuffling.
static_assert(sizeof(Vec3f) == 3 * sizeof(float) && sizeof(Rgb8) == 3);

inline int clampi(int v, int lo, int hi) { return v < lo ? lo : (v > hi ? hi : v); }

// Rows y - 1, y, y + 1 with the image's top and bottom rows repeated past its borders.
template <typename T>
struct RowTriple {
    const T *up, *mid, *down;
    RowTriple(const Image<T>& image, int y)
        : up(image.row(clampi(y - 1, 0, image.height() - 1))),
          mid(image.row(y)),
          down(image.row(clampi(y + 1, 0, image.height() - 1))) {}
};

// Copies the first and last `stride` values of padded[stride, stride + n) into the `stride`
// values of padding on each side: the clamped border.
template <typename T>
void pad_clamped(T* padded, int n, int stride) {
    for (int c = 0; c < stride; ++c) {
        padded[c] = padded[stride + c];
        padded[stride + n + c] = padded[n + c];
    }
}

// Edge test on the exact integer squared magnitude m (m < 2^24, so float(m) is exact): the
// seed's `threshold < 0 || m > threshold^2` in float is `m > limit` with this integer limit.
// For an integer m and a float t2 >= 0, m > t2 <=> m > floor(t2); a NaN or huge t2 never fires.
std::int32_t sobel_limit(float threshold) {
    if (threshold < 0.0f) return -1;  // every pixel is an edge
    const float t2 = threshold * threshold;
    if (!(t2 < 16777216.0f)) return std::numeric_limits<std::int32_t>::max();  // NaN or >= 2^24
    return static_cast<std::int32_t>(std::floor(t2));
}

void depth_row(const float* distance, int w, float divisor, std::uint8_t* out) {
    for (int x = 0; x < w; ++x) {
        const float t = distance[x];
        const float scaled = std::isfinite(t) ? t / divisor * 255.0f : 255.0f;
        out[x] = static_cast<std::uint8_t>(round_half_away(scaled));
    }
}

// Sixteen values in 0..255, four per vector, packed to bytes and stored.
inline void store_bytes_x16(std::uint8_t* out, __m128i a, __m128i b, __m128i c, __m128i d) {
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out),
                     _mm_packus_epi16(_mm_packs_epi32(a, b), _mm_packs_epi32(c, d)));
}

// round_half_away on four values (compare masks are -1 where true, so subtracting the "up" mask
// adds one and adding the "down" mask subtracts one), reduced to its low byte as a cast to
// uint8_t would; the result is ready for packing.
inline __m128i round_half_away_low_byte_x4(__m128 x) {
    const __m128i i = _mm_cvttps_epi32(x);
    const __m128 fraction = _mm_sub_ps(x, _mm_cvtepi32_ps(i));
    const __m128i up = _mm_castps_si128(_mm_cmpge_ps(fraction, _mm_set1_ps(0.5f)));
    const __m128i down = _mm_castps_si128(_mm_cmple_ps(fraction, _mm_set1_ps(-0.5f)));
    return _mm_and_si128(_mm_add_epi32(_mm_sub_epi32(i, up), down), _mm_set1_epi32(0xff));
}

void normal_row(const Vec3f* normals, const float* distance, int w, Rgb8* out) {
    // Every channel as one flat row of 3w values, sixteen at a time (GCC vectorises
    // round_half_away poorly), then the misses are blackened in a second, scalar pass.
    const float* n = &normals->x;
    std::uint8_t* bytes = out->data();
    const int values = 3 * w;
    int i = 0;
    for (; i + 16 <= values; i += 16) {
        auto channel = [&](int j) {
            // (n * 0.5 + 0.5) * 255 as normal_channel_to_byte computes it.
            const __m128 scaled =
                _mm_mul_ps(_mm_add_ps(_mm_mul_ps(_mm_loadu_ps(n + i + j), _mm_set1_ps(0.5f)),
                                      _mm_set1_ps(0.5f)),
                           _mm_set1_ps(255.0f));
            return round_half_away_low_byte_x4(scaled);
        };
        store_bytes_x16(bytes + i, channel(0), channel(4), channel(8), channel(12));
    }
    for (; i < values; ++i) bytes[i] = normal_channel_to_byte(n[i]);
    for (int x = 0; x < w; ++x)
        if (!std::isfinite(distance[x])) out[x] = {0, 0, 0};
}

// Squared Sobel magnitudes gx^2 + gy^2 of one row of n values interleaved `stride` to a pixel
// (one per channel), from the three rows around it. vert and diff are scratch of n + 2 stride.
void sobel_row(const std::uint8_t* up, const std::uint8_t* mid, const std::uint8_t* down, int n,
               int stride, std::int16_t* vert, std::int16_t* diff, std::int32_t* magnitude2) {
    std::int16_t* v = vert + stride;
    std::int16_t* d = diff + stride;
    for (int i = 0; i < n; ++i) {
        v[i] = static_cast<std::int16_t>(up[i] + 2 * mid[i] + down[i]);
        d[i] = static_cast<std::int16_t>(down[i] - up[i]);
    }
    pad_clamped(vert, n, stride);
    pad_clamped(diff, n, stride);
    for (int i = 0; i < n; ++i) {
        const std::int32_t gx = v[i + stride] - v[i - stride];
        const std::int32_t gy = d[i - stride] + 2 * d[i] + d[i + stride];
        magnitude2[i] = gx * gx + gy * gy;
    }
}

void threshold_row(const std::int32_t* magnitude2, int w, std::int32_t limit, std::uint8_t* edges) {
    for (int x = 0; x < w; ++x) edges[x] = magnitude2[x] > limit ? 0 : 255;
}

void threshold_rgb_row(const std::int32_t* magnitude2, int w, std::int32_t limit,
                       std::uint8_t* edges) {
    for (int x = 0; x < w; ++x)
        edges[x] =
            magnitude2[3 * x] + magnitude2[3 * x + 1] + magnitude2[3 * x + 2] > limit ? 0 : 255;
}

// The blur weights k = blur(E) / 16 of one row, from the 0/1 edge flags of the rows around it,
// once per channel (3w values) so the colour rows can be weighted as flat arrays. column is
// scratch of w + 2.
void blur_weight_row(const std::uint8_t* up, const std::uint8_t* mid, const std::uint8_t* down,
                     int w, std::int16_t* column, float* weight3) {
    std::int16_t* c = column + 1;
    for (int x = 0; x < w; ++x)
        c[x] = static_cast<std::int16_t>((up[x] != 0) + 2 * (mid[x] != 0) + (down[x] != 0));
    pad_clamped(column, w, 1);
    for (int x = 0; x < w; ++x) {
        const float k = static_cast<float>(c[x - 1] + 2 * c[x] + c[x + 1]) / 16.0f;
        weight3[3 * x] = weight3[3 * x + 1] = weight3[3 * x + 2] = k;
    }
}

// to_byte on four values: maxps/minps are to_byte's clamp for every number (for a NaN they
// give 0, which is also what to_byte's conversion of a NaN yields on x86), then the same scale,
// offset and truncation. Explicit SSE because GCC vectorises to_byte's nested selects as compares
// and blends, about three times the instructions.
inline __m128i to_byte_x4(__m128 c) {
    c = _mm_min_ps(_mm_max_ps(c, _mm_setzero_ps()), _mm_set1_ps(1.0f));
    return _mm_cvttps_epi32(_mm_add_ps(_mm_mul_ps(c, _mm_set1_ps(255.0f)), _mm_set1_ps(0.5f)));
}

// out = to_byte(colour * k) over a row's 3w channel values.
void compose_row(const float* colour, const float* weight3, int values, std::uint8_t* out) {
    int i = 0;
    for (; i + 16 <= values; i += 16) {
        auto weighted = [&](int j) {
            return to_byte_x4(
                _mm_mul_ps(_mm_loadu_ps(colour + i + j), _mm_loadu_ps(weight3 + i + j)));
        };
        store_bytes_x16(out + i, weighted(0), weighted(4), weighted(8), weighted(12));
    }
    for (; i < values; ++i) out[i] = to_byte(colour[i] * weight3[i]);
}


}  // namespace

void to_bytes(const float* values, int n, std::uint8_t* bytes) {
    int i = 0;
    for (; i + 16 <= n; i += 16) {
        auto plain = [&](int j) { return to_byte_x4(_mm_loadu_ps(values + i + j)); };
        store_bytes_x16(bytes + i, plain(0), plain(4), plain(8), plain(12));
    }
    for (; i < n; ++i) bytes[i] = to_byte(values[i]);
}

float classic_cel_level(float l_dot_n) {
    static constexpr float kRamp[16] = {0.5f, 0.5f, 0.5f, 0.5f, 0.75f, 0.75f, 0.75f, 0.75f,
                                        1.0f, 1.0f, 1.0f, 1.0f, 1.0f,  1.0f,  1.0f,  1.0f};
    float scaled = l_dot_n * 16.0f;
    // int() truncates toward zero as in the seed; clamp before converting so NaN or huge
    // values cannot overflow the conversion.
    int k = scaled >= 15.0f ? 15 : (scaled > 0.0f ? static_cast<int>(scaled) : 0);
    return kRamp[k];
}

float largest_finite(const ImageF& image) {
    // max(0, every finite value): four lanes of maxps over values with non-finite ones zeroed.
    // Max is exact and order-free, so the lanes give the same result as a serial loop.
    const float* p = image.data();
    const std::size_t n = image.size();
    const __m128 inf = _mm_set1_ps(std::numeric_limits<float>::infinity());
    const __m128 abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
    __m128 best = _mm_setzero_ps();
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4) {
        const __m128 t = _mm_loadu_ps(p + i);
        const __m128 finite = _mm_cmplt_ps(_mm_and_ps(t, abs_mask), inf);  // false for NaN
        best = _mm_max_ps(best, _mm_and_ps(t, finite));
    }
    alignas(16) float lanes[4];
    _mm_store_ps(lanes, best);
    float t_max = std::max(std::max(lanes[0], lanes[1]), std::max(lanes[2], lanes[3]));
    for (; i < n; ++i)
        if (std::isfinite(p[i])) t_max = std::max(t_max, p[i]);
    return t_max;
}

void classic_depth_map(const ImageF& distance, ImageGray8& out, int threads) {
    const int w = distance.width(), h = distance.height();
    out.reshape(w, h);  // every pixel is written below
    const float t_max = largest_finite(distance);
    // With no positive hit distance every hit maps to 0: dividing by infinity gives exactly
    // that (t / inf = 0) without a test per pixel. Misses map to 255 as round(255).
    const float divisor = t_max > 0.0f ? t_max : std::numeric_limits<float>::infinity();
    parallel_for(h, kRowGrain, threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y) depth_row(distance.row(y), w, divisor, out.row(y));
    });
}

void classic_normal_map(const Image<Vec3f>& normals, const ImageF& distance, ImageRgb8& out,
                        int threads) {
    const int w = normals.width(), h = normals.height();
    out.reshape(w, h);  // every pixel is written below
    parallel_for(h, kRowGrain, threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y) normal_row(normals.row(y), distance.row(y), w, out.row(y));
    });
}

void sobel_edges(const ImageGray8& in, float threshold, ImageGray8& edges, int threads) {
    const int w = in.width(), h = in.height();
    edges.reshape(w, h);  // every pixel is written below
    const std::int32_t limit = sobel_limit(threshold);
    parallel_for(h, kRowGrain, threads, [&](int y0, int y1) {
        std::vector<std::int16_t> vert(w + 2), diff(w + 2);
        std::vector<std::int32_t> magnitude2(w);
        for (int y = y0; y < y1; ++y) {
            const RowTriple<std::uint8_t> rows(in, y);
            sobel_row(rows.up, rows.mid, rows.down, w, 1, vert.data(), diff.data(),
                      magnitude2.data());
            threshold_row(magnitude2.data(), w, limit, edges.row(y));
        }
    });
}

void sobel_edges(const ImageRgb8& in, float threshold, ImageGray8& edges, int threads) {
    const int w = in.width(), h = in.height();
    edges.reshape(w, h);  // every pixel is written below
    const std::int32_t limit = sobel_limit(threshold);
    parallel_for(h, kRowGrain, threads, [&](int y0, int y1) {
        // The row as 3w interleaved values: channel c of pixel x is value 3x + c, and its
        // horizontal neighbours are 3 values away, so one flat pass handles all channels.
        std::vector<std::int16_t> vert(3 * w + 6), diff(3 * w + 6);
        std::vector<std::int32_t> magnitude2(3 * static_cast<std::size_t>(w));
        for (int y = y0; y < y1; ++y) {
            const RowTriple<Rgb8> rows(in, y);
            sobel_row(rows.up->data(), rows.mid->data(), rows.down->data(), 3 * w, 3, vert.data(),
                      diff.data(), magnitude2.data());
            threshold_rgb_row(magnitude2.data(), w, limit, edges.row(y));
        }
    });
}

void merge_edges(const ImageGray8& a, const ImageGray8& b, ImageGray8& out) {
    out.reshape(a.width(), a.height());  // every pixel is written below
    const std::uint8_t* pa = a.data();
    const std::uint8_t* pb = b.data();
    std::uint8_t* po = out.data();
    const std::size_t n = a.size();
    for (std::size_t i = 0; i < n; ++i) po[i] = std::min(pa[i], pb[i]);
}

void compose_lines(const Image<Vec3f>& colour, const ImageGray8& edges, ImageRgb8& out, int threads,
                   ImageRgb8* cel) {
    const int w = colour.width(), h = colour.height();
    out.reshape(w, h);  // every pixel is written below
    if (cel) cel->reshape(w, h);
    parallel_for(h, kRowGrain, threads, [&](int y0, int y1) {
        std::vector<std::int16_t> column(w + 2);
        std::vector<float> weight3(3 * static_cast<std::size_t>(w));
        for (int y = y0; y < y1; ++y) {
            const RowTriple<std::uint8_t> rows(edges, y);
            blur_weight_row(rows.up, rows.mid, rows.down, w, column.data(), weight3.data());
            const float* c = &colour.row(y)->x;
            compose_row(c, weight3.data(), 3 * w, out.row(y)->data());
            if (cel) to_bytes(c, 3 * w, cel->row(y)->data());
        }
    });
}

}  // namespace toonray
