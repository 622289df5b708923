#include "toonray/render/sampler.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "toonray/core/saturating.h"
#include "toonray/render/classic.h"
#include "toonray/render/shade_samples.h"
#include "toonray/render/trace.h"

namespace toonray {
namespace {

constexpr int kTile = TriangleAccel::kTileSize;
// Refined samples are traced as a grid this many rays wide, so that each 4 x 2 packet of
// intersect_tile holds 8 consecutive samples of the list (neighbouring pixels' samples).
constexpr int kListWidth = 4;
// Refined pixels are listed in blocks of this many pixels a side.
constexpr int kBlock = 16;

// The surface records and looks of n traced samples into out[offset, offset + n).
void shade_into(const SamplerFrame& f, int n, const Vec3f* dirs, const Hit* hits, const bool* found,
                SurfaceSamples& out, std::size_t offset) {
    shade_samples(f.shading, f.look, f.view, n, dirs, hits, found, out, offset);
}

// Where fine-grid sample (x, y) lies on the image, in pixels.
Vec2f image_position(int x, int y, int sub) {
    return {(static_cast<float>(x) + 0.5f) / static_cast<float>(sub),
            (static_cast<float>(y) + 0.5f) / static_cast<float>(sub)};
}

}  // namespace

PixelRect PixelRect::grown(int by, int width, int height) const {
    return {std::max(0, x0 - by), std::max(0, y0 - by), std::min(width, x1 + by),
            std::min(height, y1 + by)};
}

PixelRect BucketGrid::bucket(int index) const {
    const int cx = index % columns(), cy = index / columns();
    return {cx * size, cy * size, std::min(width, (cx + 1) * size),
            std::min(height, (cy + 1) * size)};
}

std::uint64_t BucketSampler::bytes() const {
    return first_.bytes() + rest_.bytes() + refine_.capacity() +
           (key_ids_.capacity() + key_shade_.capacity()) * sizeof(std::uint64_t) +
           differs_right_.capacity() + differs_below_.capacity() + no_differences_.capacity() +
           covered_.capacity() +
           (refined_pixels_.capacity() + refined_slot_.capacity()) * sizeof(std::uint32_t) +
           (dirs_.capacity() + rest_dirs_.capacity()) * sizeof(Vec3f) +
           hits_.capacity() * sizeof(Hit) + hit_found_size_ +
           (columns_.capacity() + rows_.capacity()) * sizeof(int);
}

std::uint64_t BucketSampler::max_bytes(std::uint64_t traced, std::uint64_t decided, int sub,
                                       unsigned first_fields, unsigned rest_fields, int lights) {
    const std::uint64_t tile_rays = static_cast<std::uint64_t>(kTile) * kTile;
    const std::uint64_t ray = sizeof(Vec3f) + sizeof(Hit) + 1;  // direction, hit, found flag
    const std::uint64_t others = static_cast<std::uint64_t>(sub) * sub - 1;
    // The rays of one traced tile and their sample columns and rows.
    std::uint64_t bytes = tile_rays * ray + 2 * kTile * sizeof(int);
    // The first samples, with their refine keys, the differences to their neighbours, whether
    // lines cover them, and a row of no differences.
    const unsigned first_kept = first_fields | (sub > 1 ? kSurfaceKeys : 0u);
    const std::uint64_t first = SurfaceSamples::bytes_per_sample(first_kept, lights) +
                                (sub > 1 ? sizeof(RefineKey) : 0) + 3;
    bytes = add_saturated(bytes, mul_saturated(traced, first));
    bytes = add_saturated(bytes, traced);
    // Every other sample of every decided pixel (its record and its ray, four rays a row at
    // most), with the pixel's slot, list entry and flag.
    const std::uint64_t rest = SurfaceSamples::bytes_per_sample(rest_fields, lights) + ray;
    bytes =
        add_saturated(bytes, mul_saturated(decided, add_saturated(mul_saturated(others, rest),
                                                                  1 + 2 * sizeof(std::uint32_t))));
    return add_saturated(bytes, kListWidth * ray);
}

void BucketSampler::sample(const SamplerFrame& frame, const PixelRect& traced,
                           const PixelRect& decided) {
    frame_ = &frame;
    traced_ = traced;
    decided_ = decided;
    sub_ = frame.sub;
    trace_first(frame);
    decide(frame);
    trace_refined(frame);
}

void BucketSampler::trace_first(const SamplerFrame& frame) {
    const int tw = traced_.width(), th = traced_.height();
    // One sample a pixel: nothing to refine, no keys to compare; else refinement compares the
    // first samples' keys.
    const bool keys = sub_ > 1;
    const std::uint64_t band_mask = frame.look.bands_shade ? 0xff : 0;
    first_.resize(static_cast<std::size_t>(tw) * th,
                  frame.first_fields | (keys ? kSurfaceKeys : 0u),
                  static_cast<int>(frame.shading.lights.size()));
    resize_exact(key_ids_, keys ? static_cast<std::size_t>(tw) * th : 0);
    resize_exact(key_shade_, keys ? static_cast<std::size_t>(tw) * th : 0);
    resize_exact(dirs_, kTile * kTile);
    resize_exact(hits_, std::max<std::size_t>(hits_.size(), kTile * kTile));
    if (hit_found_size_ < static_cast<std::size_t>(kTile * kTile)) {
        hit_found_size_ = kTile * kTile;
        hit_found_ = std::make_unique<bool[]>(hit_found_size_);
    }
    resize_exact(columns_, kTile);
    resize_exact(rows_, kTile);
    for (int ty = traced_.y0; ty < traced_.y1; ty += kTile) {
        const int rows = std::min(kTile, traced_.y1 - ty);
        for (int j = 0; j < rows; ++j) rows_[j] = (ty + j) * sub_;
        for (int tx = traced_.x0; tx < traced_.x1; tx += kTile) {
            const int cols = std::min(kTile, traced_.x1 - tx);
            for (int i = 0; i < cols; ++i) columns_[i] = (tx + i) * sub_;
            grid_directions(frame.view, sub_, columns_.data(), cols, rows_.data(), rows,
                            dirs_.data());
            frame.accel.intersect_tile(frame.view.eye, dirs_.data(), cols, rows, hits_.data(),
                                       hit_found_.get());
            for (int j = 0; j < rows; ++j) {
                const std::size_t at = static_cast<std::size_t>(j) * cols;
                const std::size_t to = first_index(tx, ty + j);
                if (first_.has(kSurfaceWhere))
                    for (int i = 0; i < cols; ++i)
                        first_.image[to + i] = image_position(columns_[i], rows_[j], sub_);
                shade_into(frame, cols, dirs_.data() + at, hits_.data() + at, hit_found_.get() + at,
                           first_, to);
                if (!keys) continue;
                // Two loops, so that the cel look's keys take no mask.
                if (band_mask == 0xff) {
                    for (int i = 0; i < cols; ++i) {
                        const RefineKey key = refine_key(first_, to + i);
                        key_ids_[to + i] = key.ids;
                        key_shade_[to + i] = key.shade;
                    }
                } else {
                    for (int i = 0; i < cols; ++i) {
                        const RefineKey key = refine_key(first_, to + i, band_mask);
                        key_ids_[to + i] = key.ids;
                        key_shade_[to + i] = key.shade;
                    }
                }
            }
        }
    }
}

namespace {

// Whether the surfaces seen by first samples a and b differ in geometry (for robust lines):
// both hit, and their geometric normals differ. Whether they hit at all, and their ids, are in
// their refine keys.
inline bool normals_differ(const SurfaceSamples& s, std::size_t a, std::size_t b,
                           const RefineRule& rule) {
    // Bitwise on 0/1 integers rather than &&: no branches in the caller's row loops.
    const int normals = int{dot(s.geometric_normal[a], s.geometric_normal[b]) < rule.cos_normal};
    return (s.found[a] & s.found[b] & normals) != 0;
}

}  // namespace

bool BucketSampler::depth_step(const SamplerFrame& frame, int x, int y) const {
    const SurfaceSamples& s = first_;
    const std::size_t centre = first_index(x, y);
    if (!s.found[centre]) return false;
    const float inv = 1.0f / s.view_depth[centre];
    auto step = [&](int dx, int dy) {
        const int ax = x - dx, ay = y - dy, bx = x + dx, by = y + dy;
        if (ax < 0 || ay < 0 || bx >= frame.width || by >= frame.height) return false;
        const std::size_t a = first_index(ax, ay), b = first_index(bx, by);
        if (!s.found[a] || !s.found[b]) return false;  // silhouettes differ in found
        const float second = 1.0f / s.view_depth[a] - 2.0f * inv + 1.0f / s.view_depth[b];
        return std::abs(second) > frame.rule.depth_step * inv;
    };
    return step(1, 0) || step(0, 1);
}

namespace {

// out[x] = whether pixel x of a row differs from a 4-neighbour: right[x] (with the pixel to
// its right), right[x - 1] (to its left; left_of_first for x = 0), below[x] and above[x] (the
// row above's flag with this row). Plain arrays so that the loop vectorises.
void neighbours_differ(const std::uint8_t* __restrict right, std::uint8_t left_of_first,
                       const std::uint8_t* __restrict below, const std::uint8_t* __restrict above,
                       int n, std::uint8_t* __restrict out) {
    out[0] = right[0] | left_of_first | below[0] | above[0];
    for (int x = 1; x < n; ++x) out[x] = right[x] | right[x - 1] | below[x] | above[x];
}

// out[x] = whether the refine keys of pixels x and x + offset differ, for x in [0, n): plain
// arrays and no branch, so that the loop vectorises.
void keys_differ(const std::uint64_t* __restrict ids, const std::uint64_t* __restrict shade,
                 int offset, int n, std::uint8_t* __restrict out) {
    for (int x = 0; x < n; ++x)
        out[x] = ((ids[x] ^ ids[x + offset]) | (shade[x] ^ shade[x + offset])) != 0;
}

// pair[x] = 0 where pixel x or its partner x + offset is covered, for x in [0, n).
void clear_covered_pairs(const std::uint8_t* __restrict covered, int offset, int n,
                         std::uint8_t* __restrict pair) {
    for (int x = 0; x < n; ++x) pair[x] = pair[x] & ((covered[x] | covered[x + offset]) ^ 1);
}

// Pixels the lines cover take no more samples.
void keep_uncovered(const std::uint8_t* __restrict covered, int n,
                    std::uint8_t* __restrict refine) {
    for (int x = 0; x < n; ++x) refine[x] = refine[x] & (covered[x] ^ 1);
}

}  // namespace

void BucketSampler::mark_differences(const RefineRule& rule, const std::uint8_t* covered,
                                     int width) {
    // Each pair of 4-neighbours of the traced pixels once: with the pixel to the right, and
    // with the one below. Pixels at the traced rectangle's edge have no pair beyond it.
    const int tw = traced_.width(), th = traced_.height();
    const std::size_t n = static_cast<std::size_t>(tw) * th;
    differs_right_.assign(n, 0);
    differs_below_.assign(n, 0);
    for (int y = 0; y < th; ++y) {
        const std::size_t row = static_cast<std::size_t>(y) * tw;
        const std::uint64_t* ids = key_ids_.data() + row;
        const std::uint64_t* shade = key_shade_.data() + row;
        std::uint8_t* right = differs_right_.data() + row;
        keys_differ(ids, shade, 1, tw - 1, right);
        if (y + 1 == th) continue;
        std::uint8_t* below = differs_below_.data() + row;
        keys_differ(ids, shade, tw, tw, below);
        if (!rule.surface) continue;
        for (int x = 0; x + 1 < tw; ++x)
            right[x] |= normals_differ(first_, row + x, row + x + 1, rule);
        for (int x = 0; x < tw; ++x)
            below[x] |= normals_differ(first_, row + x, row + x + tw, rule);
    }
    if (!covered) return;
    // A pixel that lines cover completely is not compared with its neighbours: lines are
    // centred on the edges they draw and cover a pixel only within half a pixel of their
    // centreline, so the edge between it and an uncovered neighbour lies under the line, beyond
    // that neighbour's own samples (at most 0.36 pixel from its centre).
    covered_.resize(n);
    for (int y = 0; y < th; ++y)
        std::memcpy(covered_.data() + static_cast<std::size_t>(y) * tw,
                    covered + static_cast<std::size_t>(traced_.y0 + y) * width + traced_.x0, tw);
    for (int y = 0; y < th; ++y) {
        const std::size_t row = static_cast<std::size_t>(y) * tw;
        clear_covered_pairs(covered_.data() + row, 1, tw - 1, differs_right_.data() + row);
        if (y + 1 < th)
            clear_covered_pairs(covered_.data() + row, tw, tw, differs_below_.data() + row);
    }
}

void BucketSampler::decide(const SamplerFrame& frame) {
    const int dw = decided_.width(), dh = decided_.height();
    const bool all = !frame.adaptive && sub_ > 1;
    refine_.assign(static_cast<std::size_t>(dw) * dh, all ? 1 : 0);
    if (all || sub_ == 1) return;
    mark_differences(frame.rule, frame.covered, frame.width);
    // A pixel takes all its samples when it differs from a neighbour (which the precondition
    // on `decided` puts inside `traced` whenever it is inside the image), row by row.
    const int tw = traced_.width();
    resize_exact(no_differences_, static_cast<std::size_t>(tw));
    std::fill(no_differences_.begin(), no_differences_.end(), 0);
    for (int y = decided_.y0; y < decided_.y1; ++y) {
        const std::size_t i = first_index(decided_.x0, y);
        const std::uint8_t* right = differs_right_.data() + i;
        // The pixel left of the row's first: its flag, or none at the image's edge.
        const std::uint8_t left_of_first = decided_.x0 > traced_.x0 ? right[-1] : 0;
        const std::uint8_t* above =
            y > traced_.y0 ? differs_below_.data() + (i - tw) : no_differences_.data();
        std::uint8_t* row = refine_.data() + static_cast<std::size_t>(y - decided_.y0) * dw;
        neighbours_differ(right, left_of_first, differs_below_.data() + i, above, dw, row);
        if (frame.rule.surface)
            for (int x = 0; x < dw; ++x)
                if (!row[x]) row[x] = depth_step(frame, decided_.x0 + x, y);
        if (frame.covered)
            keep_uncovered(frame.covered + static_cast<std::size_t>(y) * frame.width + decided_.x0,
                           dw, row);
    }
}

void BucketSampler::trace_refined(const SamplerFrame& frame) {
    if (sub_ == 1) {  // nothing refined
        refined_pixels_.clear();
        rest_.resize(0, frame.rest_fields, static_cast<int>(frame.shading.lights.size()));
        return;
    }
    const int dw = decided_.width();
    const int per_pixel = sub_ * sub_ - 1;
    // Sized before filling (not grown), so that the buffers hold no more than they need.
    resize_exact(refined_pixels_,
                 static_cast<std::size_t>(std::count(refine_.begin(), refine_.end(), 1)));
    refined_slot_.assign(refine_.size(), kNoIndex);
    // Listed block by block of kBlock x kBlock pixels, so that rays next to each other in the
    // list (one packet of intersect_tile) are near each other in the image.
    const int dh = decided_.height();
    std::size_t count = 0;
    for (int by = 0; by < dh; by += kBlock)
        for (int bx = 0; bx < dw; bx += kBlock)
            for (int y = by; y < std::min(by + kBlock, dh); ++y)
                for (int x = bx; x < std::min(bx + kBlock, dw); ++x) {
                    const std::size_t p = static_cast<std::size_t>(y) * dw + x;
                    if (!refine_[p]) continue;
                    refined_slot_[p] = static_cast<std::uint32_t>(count * per_pixel);
                    refined_pixels_[count++] = static_cast<std::uint32_t>(p);
                }
    const std::size_t n = refined_pixels_.size() * per_pixel;
    rest_.resize(n, frame.rest_fields, static_cast<int>(frame.shading.lights.size()));
    if (n == 0) return;
    const std::size_t padded = (n + kListWidth - 1) / kListWidth * kListWidth;
    resize_exact(rest_dirs_, padded);
    std::size_t k = 0;
    for (std::uint32_t p : refined_pixels_) {
        const int x = decided_.x0 + static_cast<int>(p % dw),
                  y = decided_.y0 + static_cast<int>(p / dw);
        for (int j = 0; j < sub_; ++j)
            for (int i = 0; i < sub_; ++i)
                if (i != 0 || j != 0) {
                    if (rest_.has(kSurfaceWhere))
                        rest_.image[k] = image_position(x * sub_ + i, y * sub_ + j, sub_);
                    rest_dirs_[k++] =
                        sample_direction(frame.view, x * sub_ + i, y * sub_ + j, sub_);
                }
    }
    std::fill(rest_dirs_.begin() + static_cast<std::ptrdiff_t>(n), rest_dirs_.end(),
              rest_dirs_[n - 1]);
    resize_exact(hits_, padded);
    if (hit_found_size_ < padded) {
        hit_found_size_ = padded;
        hit_found_ = std::make_unique<bool[]>(hit_found_size_);
    }
    // The refined rays lie along edges, a few in a block of pixels. Spread evenly over the
    // bucket they would be sqrt(pixels / n) pixels apart: as packets, rays that sparse reach
    // most of a dense mesh's leaves near the edges (a 1.1M-triangle scan took 10,000
    // instructions a ray, against 1,500 ray by ray), so the accelerator is told the spacing
    // and chooses (TriangleAccel::intersect_tile).
    const int cx = decided_.x0 + dw / 2, cy = decided_.y0 + dh / 2;
    const Vec3f step =
        sample_direction(frame.view, cx + 1, cy, 1) - sample_direction(frame.view, cx, cy, 1);
    const float ray_angle2 =
        dot(step, step) * static_cast<float>(dw) * static_cast<float>(dh) / static_cast<float>(n);
    frame.accel.intersect_tile(
        frame.view.eye, rest_dirs_.data(), kListWidth, static_cast<int>(padded / kListWidth),
        hits_.data(), hit_found_.get(), std::numeric_limits<float>::infinity(), ray_angle2);
    shade_into(frame, static_cast<int>(n), rest_dirs_.data(), hits_.data(), hit_found_.get(), rest_,
               0);
}

void BucketSampler::resolve_colours(const PixelRect& rect, ImageRgb8& out, int out_x0,
                                    int out_y0) const {
    const int n = sub_ * sub_;
    const float inv_n = 1.0f / static_cast<float>(n);
    const int dw = decided_.width();
    for (int y = rect.y0; y < rect.y1; ++y) {
        Rgb8* row = out.row(y - out_y0) + (rect.x0 - out_x0);
        const std::size_t first_row = first_index(rect.x0, y);
        to_bytes(&first_.colour[first_row].x, 3 * rect.width(), &(*row)[0]);
    }
    for (std::uint32_t p : refined_pixels_) {
        const int x = decided_.x0 + static_cast<int>(p % dw),
                  y = decided_.y0 + static_cast<int>(p / dw);
        if (!rect.contains(x, y)) continue;
        // Summed in the order full supersampling sums a pixel's samples (row by row).
        Vec3f sum = first_.colour[first_index(x, y)];
        const Vec3f* rest = rest_.colour.data() + refined_slot_[p];
        for (int k = 0; k + 1 < n; ++k) sum += rest[k];
        sum = sum * inv_n;
        out(x - out_x0, y - out_y0) = {to_byte(sum.x), to_byte(sum.y), to_byte(sum.z)};
    }
}

void BucketSampler::fill_fine(ImageF& view_depth, Image<Vec3f>& normal, Image<Vec3f>& colour,
                              Image<std::uint32_t>& material, Image<std::uint32_t>& object) const {
    const SamplerFrame& f = *frame_;
    const int dw = decided_.width(), dh = decided_.height(), sub = sub_;
    view_depth.reshape(dw * sub, dh * sub);
    normal.reshape(dw * sub, dh * sub);
    colour.reshape(dw * sub, dh * sub);
    material.reshape(dw * sub, dh * sub);
    object.reshape(dw * sub, dh * sub);
    const Vec3f& forward = f.view.forward;
    for (int y = decided_.y0; y < decided_.y1; ++y)
        for (int x = decided_.x0; x < decided_.x1; ++x) {
            const std::size_t a = first_index(x, y);
            const std::size_t p =
                static_cast<std::size_t>(y - decided_.y0) * dw + (x - decided_.x0);
            const int fx0 = (x - decided_.x0) * sub, fy0 = (y - decided_.y0) * sub;
            if (refine_[p]) {
                std::size_t r = refined_slot_[p];
                for (int j = 0; j < sub; ++j)
                    for (int i = 0; i < sub; ++i) {
                        const bool is_first = i == 0 && j == 0;
                        const SurfaceSamples& s = is_first ? first_ : rest_;
                        const std::size_t k = is_first ? a : r++;
                        view_depth(fx0 + i, fy0 + j) = s.view_depth[k];
                        normal(fx0 + i, fy0 + j) = s.geometric_normal[k];
                        colour(fx0 + i, fy0 + j) = s.colour[k];
                        material(fx0 + i, fy0 + j) = s.material[k];
                        object(fx0 + i, fy0 + j) = s.object[k];
                    }
                continue;
            }
            // An unrefined pixel: its first sample everywhere, with the depth of that sample's
            // plane along each ray: z_k = z_0 (n.D_0 / f.D_0) (f.D_k / n.D_k) for rays D through
            // the image plane (unnormalised), n the plane's normal and f the view direction.
            const float z0 = first_.view_depth[a];
            const Vec3f n = first_.geometric_normal[a];
            float plane = 0.0f;
            if (first_.found[a]) {
                const Vec3f d0 = f.view.pixel_point((static_cast<float>(x * sub) + 0.5f) / sub,
                                                    (static_cast<float>(y * sub) + 0.5f) / sub) -
                                 f.view.eye;
                plane = z0 * (dot(n, d0) / dot(forward, d0));
            }
            for (int j = 0; j < sub; ++j)
                for (int i = 0; i < sub; ++i) {
                    float z = z0;
                    if (first_.found[a] && (i != 0 || j != 0)) {
                        const Vec3f d =
                            f.view.pixel_point((static_cast<float>(x * sub + i) + 0.5f) / sub,
                                               (static_cast<float>(y * sub + j) + 0.5f) / sub) -
                            f.view.eye;
                        const float along = plane * (dot(forward, d) / dot(n, d));
                        if (std::isfinite(along) && along > 0.0f) z = along;
                    }
                    view_depth(fx0 + i, fy0 + j) = z;
                    normal(fx0 + i, fy0 + j) = n;
                    colour(fx0 + i, fy0 + j) = first_.colour[a];
                    material(fx0 + i, fy0 + j) = first_.material[a];
                    object(fx0 + i, fy0 + j) = first_.object[a];
                }
        }
}

}  // namespace toonray
