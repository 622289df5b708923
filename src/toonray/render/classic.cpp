#include "toonray/render/classic.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "toonray/core/parallel.h"

namespace toonray {
namespace {

constexpr int kRowGrain = 16;

inline int clampi(int v, int lo, int hi) { return v < lo ? lo : (v > hi ? hi : v); }

// Sobel gradients of one channel at (x, y) with clamped borders. `at(x, y)` reads a value.
template <typename At>
inline void sobel_at(const At& at, int x, int y, int w, int h, float& gx, float& gy) {
    int x0 = clampi(x - 1, 0, w - 1), x2 = clampi(x + 1, 0, w - 1);
    int y0 = clampi(y - 1, 0, h - 1), y2 = clampi(y + 1, 0, h - 1);
    float a = at(x0, y0), b = at(x, y0), c = at(x2, y0);
    float d = at(x0, y), f = at(x2, y);
    float g = at(x0, y2), hh = at(x, y2), i = at(x2, y2);
    gx = (c + 2 * f + i) - (a + 2 * d + g);
    gy = (g + 2 * hh + i) - (a + 2 * b + c);
}

}  // namespace

float classic_cel_level(float l_dot_n) {
    static constexpr float kRamp[16] = {0.5f,  0.5f,  0.5f,  0.5f,  0.75f, 0.75f, 0.75f, 0.75f,
                                        1.0f,  1.0f,  1.0f,  1.0f,  1.0f,  1.0f,  1.0f,  1.0f};
    float scaled = l_dot_n * 16.0f;
    // int() truncates toward zero as in the seed; clamp before converting so NaN or huge
    // values cannot overflow the conversion.
    int k = scaled >= 15.0f ? 15 : (scaled > 0.0f ? static_cast<int>(scaled) : 0);
    return kRamp[k];
}

void classic_depth_map(const ImageF& distance, ImageGray8& out, int threads) {
    const int w = distance.width(), h = distance.height();
    out.resize(w, h);
    float t_max = 0.0f;
    for (std::size_t i = 0; i < distance.size(); ++i) {
        float t = distance.data()[i];
        if (std::isfinite(t)) t_max = std::max(t_max, t);
    }
    parallel_for(h, kRowGrain, threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y) {
            const float* src = distance.row(y);
            std::uint8_t* dst = out.row(y);
            for (int x = 0; x < w; ++x) {
                float t = src[x];
                dst[x] = std::isfinite(t) && t_max > 0.0f
                             ? static_cast<std::uint8_t>(std::lround(t / t_max * 255.0f))
                             : (std::isfinite(t) ? 0 : 255);
            }
        }
    });
}

void classic_normal_map(const Image<Vec3f>& normals, const ImageF& distance, ImageRgb8& out, int threads) {
    const int w = normals.width(), h = normals.height();
    out.resize(w, h);
    parallel_for(h, kRowGrain, threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y) {
            for (int x = 0; x < w; ++x) {
                if (!std::isfinite(distance(x, y))) {
                    out(x, y) = {0, 0, 0};
                    continue;
                }
                const Vec3f& n = normals(x, y);
                out(x, y) = {static_cast<std::uint8_t>(std::lround((n.x * 0.5f + 0.5f) * 255.0f)),
                             static_cast<std::uint8_t>(std::lround((n.y * 0.5f + 0.5f) * 255.0f)),
                             static_cast<std::uint8_t>(std::lround((n.z * 0.5f + 0.5f) * 255.0f))};
            }
        }
    });
}

void sobel_edges(const ImageGray8& in, float threshold, ImageGray8& edges, int threads) {
    const int w = in.width(), h = in.height();
    edges.resize(w, h);
    const float t2 = threshold * threshold;
    auto at = [&](int x, int y) { return static_cast<float>(in(x, y)); };
    parallel_for(h, kRowGrain, threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < w; ++x) {
                float gx, gy;
                sobel_at(at, x, y, w, h, gx, gy);
                // magnitude > threshold  <=>  magnitude^2 > threshold^2 (both non-negative)
                edges(x, y) = (threshold < 0.0f || gx * gx + gy * gy > t2) ? 0 : 255;
            }
    });
}

void sobel_edges(const ImageRgb8& in, float threshold, ImageGray8& edges, int threads) {
    const int w = in.width(), h = in.height();
    edges.resize(w, h);
    const float t2 = threshold * threshold;
    parallel_for(h, kRowGrain, threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < w; ++x) {
                float sum = 0.0f;
                for (int c = 0; c < 3; ++c) {
                    auto at = [&](int xx, int yy) { return static_cast<float>(in(xx, yy)[c]); };
                    float gx, gy;
                    sobel_at(at, x, y, w, h, gx, gy);
                    sum += gx * gx + gy * gy;
                }
                edges(x, y) = (threshold < 0.0f || sum > t2) ? 0 : 255;
            }
    });
}

void merge_edges(const ImageGray8& a, const ImageGray8& b, ImageGray8& out) {
    out.resize(a.width(), a.height());
    for (std::size_t i = 0; i < a.size(); ++i) out.data()[i] = std::min(a.data()[i], b.data()[i]);
}

void compose_lines(const Image<Vec3f>& colour, const ImageGray8& edges, ImageRgb8& out, int threads) {
    const int w = colour.width(), h = colour.height();
    out.resize(w, h);
    parallel_for(h, kRowGrain, threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y) {
            int ya = clampi(y - 1, 0, h - 1), yc = clampi(y + 1, 0, h - 1);
            for (int x = 0; x < w; ++x) {
                int xa = clampi(x - 1, 0, w - 1), xc = clampi(x + 1, 0, w - 1);
                auto e = [&](int xx, int yy) { return edges(xx, yy) ? 1 : 0; };
                int sum = e(xa, ya) + 2 * e(x, ya) + e(xc, ya) + 2 * e(xa, y) + 4 * e(x, y) +
                          2 * e(xc, y) + e(xa, yc) + 2 * e(x, yc) + e(xc, yc);
                float k = static_cast<float>(sum) / 16.0f;
                const Vec3f& c = colour(x, y);
                out(x, y) = {to_byte(c.x * k), to_byte(c.y * k), to_byte(c.z * k)};
            }
        }
    });
}

}  // namespace toonray
