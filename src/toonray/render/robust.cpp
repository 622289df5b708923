#include "toonray/render/robust.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/core/parallel.h"
#include "toonray/core/portable_math.h"
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

// Sizes an image that is about to be overwritten completely; Image::resize would also fill it.
template <typename T>
void size_for_overwrite(Image<T>& image, int width, int height) {
    if (image.width() != width || image.height() != height) image.resize(width, height);
}

// ---- Line seeds ----------------------------------------------------------------------------
// find_line_seeds works one row at a time, in separate loops over the row without branches,
// so that the compiler vectorises them: conditions are combined with & and | on bools rather
// than && and || (which branch) and turned into bits by multiplying, and output pointers are
// __restrict (without it, GCC needs more run-time overlap checks than it is willing to emit).
struct SeedTests {
    unsigned types;
    float cos_crease;
    float depth_threshold;
    float silhouette_ratio;
};

// One row of inputs in the form the loops want: 1/z once per pixel (rather than once per use)
// and the geometric normals split into x, y and z arrays, so that a dot product loads four
// neighbouring pixels at once instead of shuffling Vec3f triples apart.
struct PreparedRow {
    explicit PreparedRow(int w) : inv(w), nx(w), ny(w), nz(w) {}
    void prepare(const FineBuffers& fine, int y) {
        const float* z = fine.depth.row(y);
        const Vec3f* n = fine.geometric_normal.row(y);
        for (std::size_t x = 0; x < inv.size(); ++x) {
            inv[x] = 1.0f / z[x];
            nx[x] = n[x].x;
            ny[x] = n[x].y;
            nz[x] = n[x].z;
        }
    }
    // dot(normal i, normal j of row b): the operations of dot() in its order, so the same float.
    [[nodiscard]] float normal_dot(int i, const PreparedRow& b, int j) const {
        return nx[i] * b.nx[j] + ny[i] * b.ny[j] + nz[i] * b.nz[j];
    }
    std::vector<float> inv, nx, ny, nz;
};

// The line bits between 4-neighbours a and b that need no depth test: background next to a
// surface, different objects or materials, a crease.
inline unsigned pair_bits(float za, float zb, std::uint32_t object_a, std::uint32_t object_b,
                          std::uint32_t material_a, std::uint32_t material_b, float normal_dot,
                          const SeedTests& t) {
    const bool hit_a = za != kInf, hit_b = zb != kInf;
    const unsigned silhouette = unsigned(hit_a != hit_b) * kLineSilhouette;
    const unsigned surface = unsigned(object_a != object_b) * kLineObject |
                             unsigned(material_a != material_b) * kLineMaterial |
                             unsigned(normal_dot < t.cos_crease) * kLineCrease;
    return t.types & (silhouette | unsigned(hit_a & hit_b) * surface);
}

// Which of two 4-neighbours a and b (a first in scan order) owns a line between them: the
// nearer one. Depths within a hair of each other (a crease or an id boundary on one surface,
// where rounding decides which is "nearer") count as equal and go to a, so such lines come
// out straight rather than hopping sides. The tie test is symmetric (|a - b| = |b - a|), so
// at most one owns it (none only for a NaN depth).
struct LineOwner {
    LineOwner(float za, float zb) {
        const bool tie = std::abs(za - zb) <= kTieTolerance * std::min(za, zb);
        first = tie | (za < zb);
        second = !tie & (zb < za);
    }
    bool first, second;
};

// Depth discontinuities across a pixel (depth z, inverse inv) along one axis, between the
// neighbours before and after it: the second difference of 1/z relative to 1/z. It is zero on
// any plane (1/z is affine in screen space for a pinhole camera) however steep the view, and
// large at a step. The pixel is on the near side of a step (and owns the line) when the
// neighbour across the larger jump in 1/z is farther. Background neighbours never count
// (silhouettes against it are pair tests).
inline float depth_across(float z_before, float z_after, float inv_before, float inv,
                          float inv_after) {
    return std::abs(inv_before - inv) > std::abs(inv_after - inv) ? z_before : z_after;
}
inline bool near_side_of_step(float z_before, float z, float z_after, float inv_before, float inv,
                              float inv_after, float depth_threshold) {
    const bool both_hit = (z_before != kInf) & (z_after != kInf);
    const bool jump = std::abs(inv_before - 2.0f * inv + inv_after) > depth_threshold * inv;
    return both_hit & jump & (depth_across(z_before, z_after, inv_before, inv, inv_after) > z);
}

// Per-row buffers of find_line_seeds, for one task's rows.
struct SeedRowScratch {
    explicit SeedRowScratch(int w)
        : above(w),
          centre(w),
          below(w),
          step(w),
          farthest_step(w),
          from_right_pair(w),
          from_left_pair(w),
          from_pair_below(w),
          to_row_below(w),
          from_pair_above(w) {}
    PreparedRow above, centre, below;  // rows y - 1, y, y + 1 (those that exist)
    std::vector<float> step;           // (depth across - z) / z along one axis
    std::vector<float> farthest_step;  // largest near-side step of row y, or -1
    // Bits each pixel of row y owns from its pair with the right neighbour, the left one, the
    // one below; bits the pixel below owns from that pair (row y + 1's from_pair_above), and
    // row y's own from_pair_above (row y - 1's to_row_below).
    std::vector<std::uint8_t> from_right_pair, from_left_pair, from_pair_below, to_row_below,
        from_pair_above;
};

// The pairs between rows y (prepared as a) and y + 1 (b): bits the upper pixel owns go to
// from_upper, those the lower one owns to from_lower.
void vertical_pairs(const FineBuffers& fine, int y, const PreparedRow& a, const PreparedRow& b,
                    const SeedTests& t, std::uint8_t* __restrict from_upper,
                    std::uint8_t* __restrict from_lower) {
    const int w = fine.depth.width();
    const float *za = fine.depth.row(y), *zb = fine.depth.row(y + 1);
    const std::uint32_t *oa = fine.object.row(y), *ob = fine.object.row(y + 1);
    const std::uint32_t *ma = fine.material.row(y), *mb = fine.material.row(y + 1);
    for (int x = 0; x < w; ++x) {
        const unsigned bits =
            pair_bits(za[x], zb[x], oa[x], ob[x], ma[x], mb[x], a.normal_dot(x, b, x), t);
        const LineOwner owner(za[x], zb[x]);
        from_upper[x] = static_cast<std::uint8_t>(unsigned(owner.first) * bits);
        from_lower[x] = static_cast<std::uint8_t>(unsigned(owner.second) * bits);
    }
}

// The pairs (x, x + 1) of row y: bits the left pixel owns go to from_right_pair[x], those the
// right one owns to from_left_pair[x + 1]; the row's ends have no pair beyond them.
void horizontal_pairs(const FineBuffers& fine, int y, const PreparedRow& row, const SeedTests& t,
                      std::uint8_t* __restrict from_right_pair,
                      std::uint8_t* __restrict from_left_pair) {
    const int w = fine.depth.width();
    const float* z = fine.depth.row(y);
    const std::uint32_t* object = fine.object.row(y);
    const std::uint32_t* material = fine.material.row(y);
    from_left_pair[0] = 0;
    from_right_pair[w - 1] = 0;
    for (int x = 0; x + 1 < w; ++x) {
        const unsigned bits = pair_bits(z[x], z[x + 1], object[x], object[x + 1], material[x],
                                        material[x + 1], row.normal_dot(x, row, x + 1), t);
        const LineOwner owner(z[x], z[x + 1]);
        from_right_pair[x] = static_cast<std::uint8_t>(unsigned(owner.first) * bits);
        from_left_pair[x + 1] = static_cast<std::uint8_t>(unsigned(owner.second) * bits);
    }
}

// Row y of the seed image. The scratch holds rows y - 1 .. y + 1 prepared (those that exist)
// and row y's from_pair_above; leaves to_row_below for row y + 1.
void seed_row(const FineBuffers& fine, int y, const SeedTests& t, SeedRowScratch& r,
              std::uint8_t* __restrict seeds) {
    const int w = fine.depth.width(), h = fine.depth.height();
    horizontal_pairs(fine, y, r.centre, t, r.from_right_pair.data(), r.from_left_pair.data());
    if (y + 1 < h) {
        vertical_pairs(fine, y, r.centre, r.below, t, r.from_pair_below.data(),
                       r.to_row_below.data());
    } else {
        std::fill(r.from_pair_below.begin(), r.from_pair_below.end(), 0);
        std::fill(r.to_row_below.begin(), r.to_row_below.end(), 0);
    }

    // Depth steps along x (pixels with both horizontal neighbours), then along y (rows with
    // both vertical neighbours): the largest relative step (z_across - z) / z where the pixel
    // is on the near side, -1 for none. The step is computed for every pixel in a loop of its
    // own and selected in a second one: a division used only under a condition would be
    // moved under it, and then (it could trap) the loop would not be vectorised.
    const float* z = fine.depth.row(y);
    const float* inv = r.centre.inv.data();
    float* __restrict step = r.step.data();
    float* __restrict farthest_step = r.farthest_step.data();
    auto add_steps = [&](const float* z_before, const float* z_after, const float* inv_before,
                         const float* inv_after, int x_begin, int x_end) {
        for (int x = x_begin; x < x_end; ++x)
            step[x] = (depth_across(z_before[x], z_after[x], inv_before[x], inv[x], inv_after[x]) -
                       z[x]) /
                      z[x];
        for (int x = x_begin; x < x_end; ++x) {
            const float s = step[x];
            const bool near_side = near_side_of_step(z_before[x], z[x], z_after[x], inv_before[x],
                                                     inv[x], inv_after[x], t.depth_threshold);
            farthest_step[x] = std::max(farthest_step[x], near_side ? s : -1.0f);
        }
    };
    std::fill(farthest_step, farthest_step + w, -1.0f);
    add_steps(z - 1, z + 1, inv - 1, inv + 1, 1, w - 1);
    if (y > 0 && y + 1 < h)
        add_steps(fine.depth.row(y - 1), fine.depth.row(y + 1), r.above.inv.data(),
                  r.below.inv.data(), 0, w);

    // A step by more than silhouette_ratio of the depth is a silhouette (one thing in front of
    // another), a smaller one a depth line (a fold of the same surface).
    const unsigned depth_silhouette = t.types & kLineSilhouette, depth_fold = t.types & kLineDepth;
    for (int x = 0; x < w; ++x) {
        const float s = farthest_step[x];
        const bool has_step = (z[x] != kInf) & (s >= 0.0f);
        const bool silhouette = s > t.silhouette_ratio;
        const unsigned depth_bits = unsigned(has_step) * (unsigned(silhouette) * depth_silhouette |
                                                          unsigned(!silhouette) * depth_fold);
        seeds[x] =
            static_cast<std::uint8_t>(depth_bits | r.from_right_pair[x] | r.from_left_pair[x] |
                                      r.from_pair_below[x] | r.from_pair_above[x]);
    }
}

// ---- Distances to seeds within a band -----------------------------------------------------
// distance_to_seeds_banded and resolve_lines_from_seeds compute, for the rows they need,
//   min over |dx| <= band of dx^2 + v(x + dx)^2,
// where v is the distance to the nearest seed in the same column, capped at band + 1. Every
// term is the squared distance to a seed or at least (band + 1)^2, and the dx = 0 term is at
// most (band + 1)^2, so the result is min(d^2, (band + 1)^2) exactly when the nearest seed
// lies within the (2 band + 1)^2 window. It does whenever d <= band, or more generally
// d^2 < (band + 1)^2: such a seed is less than band + 1 away along each axis. And when
// d^2 >= (band + 1)^2, every term is at least (band + 1)^2 and the result is that bound.

// v for the rows [y0, y1) of `seeds` into out ((y1 - y0) rows of the seed width), by a sweep
// down and a sweep up. Seeds more than band rows beyond [y0, y1) cannot be within the band of
// it, so the sweeps start band rows out (the halo). `running` holds one row.
void capped_vertical_distance(const Image<std::uint8_t>& seeds, int y0, int y1, int band,
                              std::uint8_t* out, std::uint8_t* running) {
    const int w = seeds.width(), h = seeds.height();
    const int capped = band + 1;
    auto step = [&](int y) {  // running := the distance one row further on, or 0 on a seed
        const std::uint8_t* s = seeds.row(y);
        for (int x = 0; x < w; ++x)
            running[x] = static_cast<std::uint8_t>(s[x] ? 0 : std::min(running[x] + 1, capped));
    };
    std::fill(running, running + w, static_cast<std::uint8_t>(capped));
    for (int y = std::max(0, y0 - band); y < y1; ++y) {
        step(y);
        if (y >= y0) std::copy(running, running + w, out + static_cast<std::size_t>(y - y0) * w);
    }
    std::fill(running, running + w, static_cast<std::uint8_t>(capped));
    for (int y = std::min(h, y1 + band) - 1; y >= y0; --y) {
        step(y);
        if (y < y1) {
            std::uint8_t* o = out + static_cast<std::size_t>(y - y0) * w;
            for (int x = 0; x < w; ++x) o[x] = std::min(o[x], running[x]);
        }
    }
}

// One row's min(d^2, (band + 1)^2) from its capped vertical distances. `padded` holds w +
// 2 band values: v^2 with (band + 1)^2 beyond the image's sides, so the window needs no
// bounds checks. band <= kMaxDistanceBand keeps every sum below 2^16.
void banded_squared_distance_row(const std::uint8_t* vertical, int w, int band,
                                 std::uint16_t* padded, std::uint16_t* out) {
    const auto capped_squared = static_cast<std::uint16_t>((band + 1) * (band + 1));
    std::fill(padded, padded + band, capped_squared);
    std::fill(padded + band + w, padded + 2 * band + w, capped_squared);
    std::uint16_t* centre = padded + band;
    for (int x = 0; x < w; ++x)
        out[x] = centre[x] = static_cast<std::uint16_t>(vertical[x] * vertical[x]);
    for (int dx = 1; dx <= band; ++dx) {
        const auto dx_squared = static_cast<std::uint16_t>(dx * dx);
        for (int x = 0; x < w; ++x)
            out[x] = std::min(out[x], static_cast<std::uint16_t>(
                                          std::min(centre[x - dx], centre[x + dx]) + dx_squared));
    }
}

// out[x] = in[x * sub] + ... + in[x * sub + sub - 1] for x in [0, w). With sub known at
// compile time the compiler vectorises the loop; sub is 1 to 4 (samples_per_side).
template <int Sub>
void sum_groups_of(const std::uint8_t* __restrict in, int w, std::uint8_t* __restrict out) {
    for (int x = 0; x < w; ++x) {
        unsigned n = 0;
        for (int i = 0; i < Sub; ++i) n += in[x * Sub + i];
        out[x] = static_cast<std::uint8_t>(n);
    }
}
void sum_groups(const std::uint8_t* in, int w, int sub, std::uint8_t* out) {
    switch (sub) {
        case 1: std::copy(in, in + w, out); break;
        case 2: sum_groups_of<2>(in, w, out); break;
        case 3: sum_groups_of<3>(in, w, out); break;
        case 4: sum_groups_of<4>(in, w, out); break;
        default:
            for (int x = 0; x < w; ++x) {
                unsigned n = 0;
                for (int i = 0; i < sub; ++i) n += in[static_cast<std::size_t>(x) * sub + i];
                out[x] = static_cast<std::uint8_t>(n);
            }
    }
}

// ---- Filtering the fine grid down ---------------------------------------------------------

// to_byte (classic.h) over an array, in two loops so that they vectorise: clamp to [0, 1],
// then scale, round and convert. The result is to_byte's for every float, NaN included
// (std::max and std::min clamp exactly as its nested condition does). In one loop, GCC turns
// the clamp into branches with the conversion (which may trap) under one of them, and then
// keeps the loop scalar.
void to_bytes(float* __restrict values, std::size_t n, std::uint8_t* __restrict bytes) {
    for (std::size_t i = 0; i < n; ++i) values[i] = std::min(std::max(values[i], 0.0f), 1.0f);
    for (std::size_t i = 0; i < n; ++i)
        bytes[i] = static_cast<std::uint8_t>(values[i] * 255.0f + 0.5f);
}

// out[i] = value(i) for i in [0, n); a function so that __restrict is honoured.
template <typename Value>
void fill_plane(float* __restrict out, std::size_t n, const Value& value) {
    for (std::size_t i = 0; i < n; ++i) out[i] = value(i);
}

// Sums the samples of one row of output pixels, fine row by fine row, in the order of the
// per-pixel loop resolve_lines was written as (j outer, i inner), so the float sums are the
// same. Channels are kept in separate arrays so that the loops vectorise.
class PixelRowSums {
public:
    explicit PixelRowSums(int w)
        : red_(w),
          green_(w),
          blue_(w),
          covered_(w),
          values_(7 * static_cast<std::size_t>(w)),
          bytes_(7 * static_cast<std::size_t>(w)) {}

    void clear() {
        for (auto* sums : {&red_, &green_, &blue_, &covered_})
            std::fill(sums->begin(), sums->end(), 0.0f);
    }

    // One fine row: its colours and each sample's line coverage (0 where uncovered: adding
    // +0 leaves a sum that is never -0 unchanged, so this equals skipping those samples).
    void add(const Vec3f* fine_colour, const float* fine_coverage, int sub) {
        switch (sub) {  // a fixed sub lets the compiler vectorise the inner loop away
            case 1: add_samples<1>(fine_colour, fine_coverage, sub); break;
            case 2: add_samples<2>(fine_colour, fine_coverage, sub); break;
            case 3: add_samples<3>(fine_colour, fine_coverage, sub); break;
            case 4: add_samples<4>(fine_colour, fine_coverage, sub); break;
            default: add_samples<0>(fine_colour, fine_coverage, sub);
        }
    }

    // Writes row y of resolve_lines' outputs from the sums of its sub x sub samples: colour =
    // sum * (1 / n), a = covered * (1 / n), final = colour * (1 - a) + line_colour * a (the
    // same float operations as with Vec3f), each to_byte'd. One loop per plane keeps each
    // loop's possible overlaps few enough for GCC to vectorise it.
    void write(int y, int sub, const Vec3f& line_colour, ImageRgb8& final_image, ImageRgb8* cel,
               ImageGray8* lines) {
        const float inv_n = 1.0f / static_cast<float>(sub * sub);
        const std::size_t w = covered_.size();
        // The arithmetic, into planes: final r, g, b, then (for the feature images) cel r, g,
        // b and lines ...
        const float *red = red_.data(), *green = green_.data(), *blue = blue_.data(),
                    *covered = covered_.data();
        const Vec3f line = line_colour;
        auto a = [&](std::size_t x) { return covered[x] * inv_n; };
        auto plane = [&](int i) { return values_.data() + i * w; };
        fill_plane(plane(0), w,
                   [&](std::size_t x) { return red[x] * inv_n * (1.0f - a(x)) + line.x * a(x); });
        fill_plane(plane(1), w,
                   [&](std::size_t x) { return green[x] * inv_n * (1.0f - a(x)) + line.y * a(x); });
        fill_plane(plane(2), w,
                   [&](std::size_t x) { return blue[x] * inv_n * (1.0f - a(x)) + line.z * a(x); });
        int planes = 3;
        if (cel) {
            fill_plane(plane(3), w, [&](std::size_t x) { return red[x] * inv_n; });
            fill_plane(plane(4), w, [&](std::size_t x) { return green[x] * inv_n; });
            fill_plane(plane(5), w, [&](std::size_t x) { return blue[x] * inv_n; });
            planes = 6;
        }
        const int lines_plane = planes;
        if (lines) {
            fill_plane(plane(lines_plane), w, [&](std::size_t x) { return 1.0f - a(x); });
            ++planes;
        }
        // ... converted to bytes ...
        std::uint8_t* byte = bytes_.data();
        to_bytes(values_.data(), static_cast<std::size_t>(planes) * w, byte);
        // ... and interleaved into RGB.
        Rgb8* __restrict final_row = final_image.row(y);
        for (std::size_t x = 0; x < w; ++x) final_row[x] = {byte[x], byte[w + x], byte[2 * w + x]};
        if (cel) {
            Rgb8* __restrict cel_row = cel->row(y);
            for (std::size_t x = 0; x < w; ++x)
                cel_row[x] = {byte[3 * w + x], byte[4 * w + x], byte[5 * w + x]};
        }
        if (lines) std::copy(byte + lines_plane * w, byte + (lines_plane + 1) * w, lines->row(y));
    }

private:
    // Sub = 0: any sub, given at run time.
    template <int Sub>
    void add_samples(const Vec3f* __restrict fine_colour, const float* __restrict fine_coverage,
                     int sub) {
        const int n = Sub > 0 ? Sub : sub;
        float* __restrict red = red_.data();
        float* __restrict green = green_.data();
        float* __restrict blue = blue_.data();
        float* __restrict covered = covered_.data();
        for (std::size_t x = 0; x < covered_.size(); ++x)
            for (int i = 0; i < n; ++i) {
                const std::size_t fx = x * n + i;
                red[x] += fine_colour[fx].x;
                green[x] += fine_colour[fx].y;
                blue[x] += fine_colour[fx].z;
                covered[x] += fine_coverage[fx];
            }
    }

    std::vector<float> red_, green_, blue_, covered_;
    std::vector<float> values_;        // write's values, 7 planes of a row
    std::vector<std::uint8_t> bytes_;  // and their bytes
};

// A fine sample at distance d from the nearest seed is covered by clamp(reach - d, 0, 1),
// reach = thickness / 2 + 0.5; counted where d^2 < reach^2 (as floats), as resolve_lines does.
struct LineReach {
    explicit LineReach(float thickness)
        : reach(thickness > 0.0f ? thickness * 0.5f + 0.5f : 0.0f), reach_squared(reach * reach) {}
    [[nodiscard]] float coverage(float squared_distance) const {
        return squared_distance < reach_squared
                   ? std::min(1.0f, reach - std::sqrt(squared_distance))
                   : 0.0f;
    }
    float reach, reach_squared;
};

void size_resolved_outputs(int w, int h, ImageRgb8& final_image, ImageRgb8* cel,
                           ImageGray8* lines) {
    size_for_overwrite(final_image, w, h);
    if (cel) size_for_overwrite(*cel, w, h);
    if (lines) size_for_overwrite(*lines, w, h);
}

}  // namespace

void find_line_seeds(const FineBuffers& fine, const LineSettings& s, Image<std::uint8_t>& seeds,
                     int threads) {
    const int w = fine.depth.width(), h = fine.depth.height();
    size_for_overwrite(seeds, w, h);
    if (w == 0 || h == 0) return;
    const SeedTests tests{s.types, portable::cos(s.crease_angle * 3.14159265f / 180.0f),
                          s.robust.depth_step, s.robust.silhouette_ratio};
    parallel_for(h, kRowGrain, threads, [&](int y0, int y1) {
        SeedRowScratch r(w);
        // Row y0's share of the pairs with the row above (computed again here, once per task).
        if (y0 > 0) {
            r.centre.prepare(fine, y0 - 1);
            r.below.prepare(fine, y0);
            vertical_pairs(fine, y0 - 1, r.centre, r.below, tests, r.to_row_below.data(),
                           r.from_pair_above.data());
        } else {
            r.below.prepare(fine, y0);
        }
        for (int y = y0; y < y1; ++y) {
            // Roll the prepared rows on by one: y - 1 and y are already there.
            std::swap(r.above, r.centre);
            std::swap(r.centre, r.below);
            if (y + 1 < h) r.below.prepare(fine, y + 1);
            if (y > y0) std::swap(r.from_pair_above, r.to_row_below);
            seed_row(fine, y, tests, r, seeds.row(y));
        }
    });
}

void distance_to_seeds(const Image<std::uint8_t>& seeds, ImageF& out, int threads) {
    const int w = seeds.width(), h = seeds.height();
    size_for_overwrite(out, w, h);
    // Columns first: the distance to the nearest seed in the column, by a sweep down (seeds
    // above) and a sweep up (seeds below) over rows, which reads memory in order; the same
    // exact squared distances (+inf for a column without seeds) as the 1-D transform of the
    // column. Columns are independent, so each task takes a range of them.
    parallel_for(w, 256, threads, [&](int x0, int x1) {
        std::vector<float> below(static_cast<std::size_t>(x1 - x0), kInf);
        for (int y = 0; y < h; ++y) {
            const std::uint8_t* s = seeds.row(y);
            const float* above = y > 0 ? out.row(y - 1) : nullptr;
            float* o = out.row(y);
            for (int x = x0; x < x1; ++x) o[x] = s[x] ? 0.0f : (above ? above[x] + 1.0f : kInf);
        }
        for (int y = h - 1; y >= 0; --y) {
            const std::uint8_t* s = seeds.row(y);
            float* o = out.row(y);
            for (int x = x0; x < x1; ++x) {
                float& b = below[x - x0];
                b = s[x] ? 0.0f : b + 1.0f;
                const float dy = std::min(o[x], b);
                o[x] = dy * dy;
            }
        }
    });
    // Then rows; each row is independent, so threads never share data.
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

void distance_to_seeds_banded(const Image<std::uint8_t>& seeds, int band, Image<std::uint16_t>& out,
                              int threads) {
    if (band < 0 || band > kMaxDistanceBand)
        throw Error(fmt::format("distance band {} outside [0, {}]", band, kMaxDistanceBand));
    const int w = seeds.width(), h = seeds.height();
    size_for_overwrite(out, w, h);
    parallel_for(h, kRowGrain, threads, [&](int y0, int y1) {
        // Strips of at most kRowGrain rows (however many a task gets) keep the buffers in cache.
        std::vector<std::uint8_t> vertical(static_cast<std::size_t>(kRowGrain) * w), running(w);
        std::vector<std::uint16_t> padded(w + 2 * band);
        for (int strip0 = y0; strip0 < y1; strip0 += kRowGrain) {
            const int strip1 = std::min(y1, strip0 + kRowGrain);
            capped_vertical_distance(seeds, strip0, strip1, band, vertical.data(), running.data());
            for (int y = strip0; y < strip1; ++y)
                banded_squared_distance_row(
                    vertical.data() + static_cast<std::size_t>(y - strip0) * w, w, band,
                    padded.data(), out.row(y));
        }
    });
}

float line_thickness(float width, int height, int sub) {
    return std::max(0.0f, width * static_cast<float>(height) / 720.0f * static_cast<float>(sub));
}

void resolve_lines(const Image<Vec3f>& fine_colour, const ImageF& squared_distance, float thickness,
                   int sub, const Vec3f& line_colour, ImageRgb8& final_image, ImageRgb8* cel,
                   ImageGray8* lines, int threads) {
    const int w = fine_colour.width() / sub, h = fine_colour.height() / sub;
    size_resolved_outputs(w, h, final_image, cel, lines);
    const LineReach reach(thickness);
    parallel_for(h, kRowGrain, threads, [&](int y0, int y1) {
        PixelRowSums sums(w);
        std::vector<float> coverage(static_cast<std::size_t>(w) * sub);
        for (int y = y0; y < y1; ++y) {
            sums.clear();
            for (int j = 0; j < sub; ++j) {
                const float* d2 = squared_distance.row(y * sub + j);
                for (std::size_t fx = 0; fx < coverage.size(); ++fx)
                    coverage[fx] = reach.coverage(d2[fx]);
                sums.add(fine_colour.row(y * sub + j), coverage.data(), sub);
            }
            sums.write(y, sub, line_colour, final_image, cel, lines);
        }
    });
}

int robust_halo(float thickness, int sub) {
    const float reach = thickness > 0.0f ? thickness * 0.5f + 0.5f : 0.0f;
    const int fine = static_cast<int>(std::ceil(reach)) + 1;
    return (fine + sub - 1) / sub;
}

int line_distance_band(float thickness) {
    const LineReach reach(thickness);
    int band = 0;
    while (band <= kMaxDistanceBand &&
           static_cast<float>((band + 1) * (band + 1)) < reach.reach_squared)
        ++band;
    return band;
}

void resolve_lines_from_seeds(const Image<Vec3f>& fine_colour, const Image<std::uint8_t>& seeds,
                              float thickness, int sub, const Vec3f& line_colour,
                              ImageRgb8& final_image, ImageRgb8* cel, ImageGray8* lines,
                              int threads) {
    const LineReach reach(thickness);
    // Why the banded distance gives the same bytes: a sample is covered only where
    // d^2 < reach^2 (compared as floats, d^2 an integer). Take band as the largest integer
    // with band^2 < reach^2, so (band + 1)^2 >= reach^2. The banded value min(d^2, (band + 1)^2)
    // then equals d^2 at every covered sample (d^2 < reach^2 <= (band + 1)^2), and at every
    // other one it is at least reach^2 (both d^2 and (band + 1)^2 are), so it stays
    // uncovered. Coverage, and so every output byte, is the same as with the exact distance.
    const int band = line_distance_band(thickness);
    if (band > kMaxDistanceBand) {  // very wide lines: the linear-time full transform is faster
        ImageF squared_distance;
        distance_to_seeds(seeds, squared_distance, threads);
        resolve_lines(fine_colour, squared_distance, thickness, sub, line_colour, final_image, cel,
                      lines, threads);
        return;
    }
    // Coverage for each possible banded squared distance.
    std::vector<float> coverage_of((band + 1) * (band + 1) + 1);
    for (std::size_t d2 = 0; d2 < coverage_of.size(); ++d2)
        coverage_of[d2] = reach.coverage(static_cast<float>(d2));

    if (seeds.width() != fine_colour.width() || seeds.height() != fine_colour.height())
        throw Error(fmt::format("line seeds are {}x{} but the fine colours {}x{}", seeds.width(),
                                seeds.height(), fine_colour.width(), fine_colour.height()));
    const int fine_w = fine_colour.width(), w = fine_w / sub, h = fine_colour.height() / sub;
    size_resolved_outputs(w, h, final_image, cel, lines);
    parallel_for(h, kRowGrain, threads, [&](int y0, int y1) {
        // Strips of at most kRowGrain pixel rows (however many a task gets) keep the buffers in
        // cache. Each strip's distances come from its seeds and a halo of band rows around it.
        std::vector<std::uint8_t> vertical(static_cast<std::size_t>(kRowGrain) * sub * fine_w),
            running(fine_w);
        std::vector<std::uint16_t> padded(fine_w + 2 * band), squared_distance(fine_w);
        std::vector<float> coverage(fine_w);
        PixelRowSums sums(w);
        for (int strip0 = y0; strip0 < y1; strip0 += kRowGrain) {
            const int strip1 = std::min(y1, strip0 + kRowGrain);
            capped_vertical_distance(seeds, strip0 * sub, strip1 * sub, band, vertical.data(),
                                     running.data());
            for (int y = strip0; y < strip1; ++y) {
                sums.clear();
                for (int j = 0; j < sub; ++j) {
                    const int fy = y * sub + j;
                    banded_squared_distance_row(
                        vertical.data() + static_cast<std::size_t>(fy - strip0 * sub) * fine_w,
                        fine_w, band, padded.data(), squared_distance.data());
                    for (int fx = 0; fx < fine_w; ++fx)
                        coverage[fx] = coverage_of[squared_distance[fx]];
                    sums.add(fine_colour.row(fy), coverage.data(), sub);
                }
                sums.write(y, sub, line_colour, final_image, cel, lines);
            }
        }
    });
}

void resolve_seed_type(const Image<std::uint8_t>& seeds, unsigned type, int sub, ImageGray8& out,
                       int threads) {
    const int w = seeds.width() / sub, h = seeds.height() / sub;
    size_for_overwrite(out, w, h);
    // The byte for each possible count of samples with the type.
    const float inv_n = 1.0f / static_cast<float>(sub * sub);
    std::vector<std::uint8_t> byte_of_count(sub * sub + 1);
    for (int n = 0; n <= sub * sub; ++n)
        byte_of_count[n] = to_byte(1.0f - static_cast<float>(n) * inv_n);
    // Per output row: first the samples with the type in each fine column (vectorised over
    // the row), then those column counts summed over each pixel's sub columns.
    parallel_for(h, kRowGrain, threads, [&](int y0, int y1) {
        // Locals rather than captured variables or .size(): byte stores may alias those, and the
        // compiler would then not vectorise the loops.
        const int width = w;
        const std::size_t fine_w = static_cast<std::size_t>(w) * sub;
        const unsigned type_bits = type;
        std::vector<std::uint8_t> column_counts(fine_w), pixel_counts(w);
        std::uint8_t* column_count = column_counts.data();
        for (int y = y0; y < y1; ++y) {
            std::fill(column_count, column_count + fine_w, 0);
            for (int j = 0; j < sub; ++j) {
                const std::uint8_t* s = seeds.row(y * sub + j);
                for (std::size_t fx = 0; fx < fine_w; ++fx)
                    column_count[fx] =
                        static_cast<std::uint8_t>(column_count[fx] + ((s[fx] & type_bits) != 0));
            }
            sum_groups(column_count, width, sub, pixel_counts.data());
            std::uint8_t* o = out.row(y);
            for (int x = 0; x < width; ++x) o[x] = byte_of_count[pixel_counts[x]];
        }
    });
}

}  // namespace toonray
