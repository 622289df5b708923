#include "toonray/render/robust.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <sstream>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/core/parallel.h"
#include "toonray/render/classic.h"

namespace toonray {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr int kRowGrain = 16;
constexpr float kTieTolerance = 1e-5f;

// 1-D squared distance transform of f (n samples, +inf = no seed) into d, using v and z as
// scratch (Felzenszwalb & Huttenlocher 2012, "Distance Transforms of Sampled Functions").
void dt_1d(const float* f, int n, float* d, int* v, float* z) {
    int first = 0;
    while (first < n && f[first] == kInf) ++first;
    if (first == n) {
        std::fill(d, d + n, kInf);
        return;
    }
    // Lower envelope of the parabolas (x - q)^2 + f[q] over the finite samples.
    int k = 0;
    v[0] = first;
    z[0] = -kInf;
    z[1] = kInf;
    for (int q = first + 1; q < n; ++q) {
        if (f[q] == kInf) continue;
        float s;
        while (true) {
            int p = v[k];
            s = ((f[q] + static_cast<float>(q) * q) - (f[p] + static_cast<float>(p) * p)) /
                (2.0f * static_cast<float>(q - p));
            if (s > z[k]) break;
            --k;  // z[0] = -inf stops this at k = 0
        }
        ++k;
        v[k] = q;
        z[k] = s;
        z[k + 1] = kInf;
    }
    k = 0;
    for (int q = 0; q < n; ++q) {
        while (z[k + 1] < static_cast<float>(q)) ++k;
        float dq = static_cast<float>(q - v[k]);
        d[q] = dq * dq + f[v[k]];
    }
}

}  // namespace

unsigned parse_line_types(const std::string& text) {
    if (text == "all") return kLineAll;
    if (text == "none") return 0;
    unsigned types = 0;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) {
        if (item == "silhouette") types |= kLineSilhouette;
        else if (item == "crease") types |= kLineCrease;
        else if (item == "depth") types |= kLineDepth;
        else if (item == "object") types |= kLineObject;
        else if (item == "material") types |= kLineMaterial;
        else
            throw Error(fmt::format("--lines: unknown line type '{}' (choose from silhouette, crease, "
                                    "depth, object, material, all, none)", item));
    }
    return types;
}

void find_line_seeds(const FineBuffers& fine, const RobustLineSettings& s, Image<std::uint8_t>& seeds,
                     int threads) {
    const int w = fine.depth.width(), h = fine.depth.height();
    seeds.resize(w, h, 0);
    const float cos_crease = std::cos(s.crease_angle * 3.14159265f / 180.0f);
    const unsigned types = s.types;

    // The line bits between 4-neighbours a and b that need no depth test: background next to
    // a surface, different objects or materials, a crease. (Which of the two gets them is
    // decided by the caller.)
    auto pair_bits = [&](int ax, int ay, int bx, int by) -> unsigned {
        float za = fine.depth(ax, ay), zb = fine.depth(bx, by);
        bool hit_a = za != kInf, hit_b = zb != kInf;
        if (!hit_a && !hit_b) return 0;
        if (hit_a != hit_b) return types & kLineSilhouette;
        unsigned bits = 0;
        if ((types & kLineObject) && fine.object(ax, ay) != fine.object(bx, by)) bits |= kLineObject;
        if ((types & kLineMaterial) && fine.material(ax, ay) != fine.material(bx, by)) bits |= kLineMaterial;
        if ((types & kLineCrease) &&
            dot(fine.geometric_normal(ax, ay), fine.geometric_normal(bx, by)) < cos_crease)
            bits |= kLineCrease;
        return bits;
    };

    // Depth discontinuities: the second difference of 1/z across the pixel, along x and along
    // y, relative to 1/z. It is zero on any plane (1/z is affine in screen space for a pinhole
    // camera) however steep the view, and large at a step. The seed goes on the near side only
    // (the neighbour across the larger jump in 1/z is the farther one). A step by more than
    // silhouette_ratio of the depth is a silhouette (one thing in front of another), a smaller
    // one a depth line (a fold of the same surface).
    auto depth_bits = [&](int x, int y) -> unsigned {
        float z = fine.depth(x, y);
        if (z == kInf) return 0;
        const float inv = 1.0f / z;
        float farthest_step = -1.0f;  // (z_far - z) / z of the largest near-side step found
        auto along = [&](int x0, int y0, int x1, int y1) {
            float z0 = fine.depth(x0, y0), z1 = fine.depth(x1, y1);
            if (z0 == kInf || z1 == kInf) return;  // silhouettes against the background are found above
            float i0 = 1.0f / z0, i1 = 1.0f / z1;
            if (!(std::abs(i0 - 2.0f * inv + i1) > s.depth_threshold * inv)) return;
            bool first = std::abs(i0 - inv) > std::abs(i1 - inv);
            float z_across = first ? z0 : z1;
            if (z_across > z) farthest_step = std::max(farthest_step, (z_across - z) / z);
        };
        if (x > 0 && x + 1 < w) along(x - 1, y, x + 1, y);
        if (y > 0 && y + 1 < h) along(x, y - 1, x, y + 1);
        if (farthest_step < 0.0f) return 0;
        return types & (farthest_step > s.silhouette_ratio ? kLineSilhouette : kLineDepth);
    };

    parallel_for(h, kRowGrain, threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < w; ++x) {
                unsigned bits = 0;
                // Each pair is examined from both sides, and the nearer one keeps the bits.
                const int nx[4] = {x - 1, x + 1, x, x};
                const int ny[4] = {y, y, y - 1, y + 1};
                for (int i = 0; i < 4; ++i) {
                    if (nx[i] < 0 || nx[i] >= w || ny[i] < 0 || ny[i] >= h) continue;
                    unsigned b = pair_bits(x, y, nx[i], ny[i]);
                    if (!b) continue;
                    // The nearer pixel owns the line. Depths within a hair of each other (a
                    // crease or an id boundary on one surface, where rounding decides which
                    // is "nearer") count as equal and go to the pixel first in scan order,
                    // so such lines come out straight rather than hopping sides.
                    float z_self = fine.depth(x, y), z_other = fine.depth(nx[i], ny[i]);
                    bool tie = std::abs(z_self - z_other) <= kTieTolerance * std::min(z_self, z_other);
                    bool first_in_scan = ny[i] > y || (ny[i] == y && nx[i] > x);
                    bool mine = tie ? first_in_scan : z_self < z_other;
                    if (mine) bits |= b;
                }
                bits |= depth_bits(x, y);
                seeds(x, y) = static_cast<std::uint8_t>(bits);
            }
    });
}

void distance_to_seeds(const Image<std::uint8_t>& seeds, ImageF& out, int threads) {
    const int w = seeds.width(), h = seeds.height();
    out.resize(w, h);
    // Columns first, then rows; each pass is independent per line, so threads never share data.
    parallel_for(w, 64, threads, [&](int x0, int x1) {
        std::vector<float> f(h), d(h), z(h + 1);
        std::vector<int> v(h);
        for (int x = x0; x < x1; ++x) {
            for (int y = 0; y < h; ++y) f[y] = seeds(x, y) ? 0.0f : kInf;
            dt_1d(f.data(), h, d.data(), v.data(), z.data());
            for (int y = 0; y < h; ++y) out(x, y) = d[y];
        }
    });
    parallel_for(h, kRowGrain, threads, [&](int y0, int y1) {
        std::vector<float> f(w), d(w), z(w + 1);
        std::vector<int> v(w);
        for (int y = y0; y < y1; ++y) {
            std::copy(out.row(y), out.row(y) + w, f.begin());
            dt_1d(f.data(), w, d.data(), v.data(), z.data());
            std::copy(d.begin(), d.end(), out.row(y));
        }
    });
}

float line_thickness(float width, int height, int sub) {
    return std::max(0.0f, width * static_cast<float>(height) / 720.0f * static_cast<float>(sub));
}

void resolve_lines(const Image<Vec3f>& fine_colour, const ImageF& squared_distance, float thickness, int sub,
                   const Vec3f& line_colour, ImageRgb8& final_image, ImageRgb8& cel, ImageGray8& lines,
                   int threads) {
    const int w = fine_colour.width() / sub, h = fine_colour.height() / sub;
    final_image.resize(w, h);
    cel.resize(w, h);
    lines.resize(w, h);
    const float reach = thickness > 0.0f ? thickness * 0.5f + 0.5f : 0.0f;
    const float reach2 = reach * reach;
    const float inv_n = 1.0f / static_cast<float>(sub * sub);
    parallel_for(h, kRowGrain, threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < w; ++x) {
                Vec3f sum(0.0f);
                float covered = 0.0f;
                for (int j = 0; j < sub; ++j)
                    for (int i = 0; i < sub; ++i) {
                        int fx = x * sub + i, fy = y * sub + j;
                        sum += fine_colour(fx, fy);
                        float d2 = squared_distance(fx, fy);
                        if (d2 < reach2) covered += std::min(1.0f, reach - std::sqrt(d2));
                    }
                Vec3f colour = sum * inv_n;
                float a = covered * inv_n;
                Vec3f out = colour * (1.0f - a) + line_colour * a;
                final_image(x, y) = {to_byte(out.x), to_byte(out.y), to_byte(out.z)};
                cel(x, y) = {to_byte(colour.x), to_byte(colour.y), to_byte(colour.z)};
                lines(x, y) = to_byte(1.0f - a);
            }
    });
}

void resolve_seed_type(const Image<std::uint8_t>& seeds, unsigned type, int sub, ImageGray8& out, int threads) {
    const int w = seeds.width() / sub, h = seeds.height() / sub;
    out.resize(w, h);
    const float inv_n = 1.0f / static_cast<float>(sub * sub);
    parallel_for(h, kRowGrain, threads, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < w; ++x) {
                int n = 0;
                for (int j = 0; j < sub; ++j)
                    for (int i = 0; i < sub; ++i)
                        if (seeds(x * sub + i, y * sub + j) & type) ++n;
                out(x, y) = to_byte(1.0f - static_cast<float>(n) * inv_n);
            }
    });
}

}  // namespace toonray
