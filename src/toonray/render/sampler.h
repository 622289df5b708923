#pragma once
/// Adaptive supersampling of one bucket of pixels. Every pixel gets one sample first, the first
/// of its regular sub x sub grid; a pixel then gets the rest of its grid only where it differs
/// from a 4-neighbour in the discrete fields of its surface record (whether it hits, ids, band,
/// accents, the look's edge signal: render/look.h), and for robust lines also in normals and
/// depth steps. Sample positions are fixed and each pixel's
/// choice depends only on its own and its neighbours' first samples, so a frame is the same
/// whatever the bucket size, the bucket order and the thread count. A pixel that takes all its
/// samples gets exactly the values full supersampling gives it.

#include <cstdint>
#include <memory>
#include <vector>

#include "toonray/accel/triangle_accel.h"
#include "toonray/core/image.h"
#include "toonray/render/look.h"
#include "toonray/render/shading.h"
#include "toonray/render/surface.h"
#include "toonray/scene/camera.h"

namespace toonray {

/// A rectangle of pixels [x0, x1) x [y0, y1).
struct PixelRect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;

    [[nodiscard]] int width() const { return x1 - x0; }
    [[nodiscard]] int height() const { return y1 - y0; }
    [[nodiscard]] bool empty() const { return x1 <= x0 || y1 <= y0; }
    [[nodiscard]] bool contains(int x, int y) const {
        return x >= x0 && x < x1 && y >= y0 && y < y1;
    }
    /// Grown by `by` pixels on every side, then clipped to a width x height image.
    [[nodiscard]] PixelRect grown(int by, int width, int height) const;
    bool operator==(const PixelRect&) const = default;
};

/// The buckets of a width x height image, `size` x `size` pixels each (smaller at the right and
/// bottom edges), numbered row by row.
struct BucketGrid {
    int width, height, size;

    [[nodiscard]] int columns() const { return (width + size - 1) / size; }
    [[nodiscard]] int count() const { return columns() * ((height + size - 1) / size); }
    [[nodiscard]] PixelRect bucket(int index) const;
};

/// What makes a pixel take all its samples: a 4-neighbour whose first sample differs from its
/// own in its refine key (render/look.h: whether it hits, object, material, band, accents and
/// the look's edge signal), or by one of these.
struct RefineRule {
    /// Also compare the geometry (robust lines): geometric normals (cos of the angle between
    /// them below cos_normal), and depth steps: a second difference of 1/z across the pixel,
    /// relative to its own 1/z, above depth_step.
    bool surface = false;
    float cos_normal = 1.0f;
    float depth_step = 0.0f;
};

/// Everything the sampler needs of a frame.
struct SamplerFrame {
    const TriangleAccel& accel;
    const ShadingContext& shading;
    const LookFrame& look;
    const ViewPlane& view;
    int width, height;  ///< of the image, in pixels
    int sub;            ///< samples per pixel side
    bool adaptive;      ///< false: every pixel takes all its samples
    RefineRule rule;
    unsigned first_fields = 0;  ///< SurfaceFields kept of each pixel's first sample
    unsigned rest_fields = 0;   ///< of the other samples
    /// Per pixel of the image (row by row), or null: 1 where lines drawn over the frame cover
    /// the picture completely. Such pixels never take more than their first sample.
    const std::uint8_t* covered = nullptr;
};

/// Samples buckets one after another, keeping its buffers. One per thread.
class BucketSampler {
public:
    /// Traces the first sample of every pixel of `traced`, decides which pixels of `decided`
    /// take all their samples, and traces those. `decided` must lie within `traced` shrunk by
    /// one pixel, except along the image's own edges.
    void sample(const SamplerFrame& frame, const PixelRect& traced, const PixelRect& decided);

    /// The first sample of pixel (x, y) of `traced`: index into first().
    [[nodiscard]] std::size_t first_index(int x, int y) const {
        return static_cast<std::size_t>(y - traced_.y0) * traced_.width() + (x - traced_.x0);
    }
    [[nodiscard]] const SurfaceSamples& first() const { return first_; }
    /// Whether pixel (x, y) of `decided` took all its samples.
    [[nodiscard]] bool refined(int x, int y) const {
        return refine_[static_cast<std::size_t>(y - decided_.y0) * decided_.width() +
                       (x - decided_.x0)] != 0;
    }
    /// Pixels of `decided` that took all their samples.
    [[nodiscard]] std::size_t refined_count() const { return refined_pixels_.size(); }
    /// Bytes held by the buffers.
    [[nodiscard]] std::uint64_t bytes() const;
    /// The most bytes the buffers reach for buckets of `traced` and `decided` pixels (every
    /// decided pixel refined), with `lights` lights: for the frame's memory estimate.
    [[nodiscard]] static std::uint64_t max_bytes(std::uint64_t traced, std::uint64_t decided,
                                                 int sub, unsigned first_fields,
                                                 unsigned rest_fields, int lights);

    /// The colours of the pixels of `rect` (within `decided`) as bytes into `out`, whose pixel
    /// (0, 0) is (out_x0, out_y0): a refined pixel's mean over its sub x sub samples, summed row
    /// by row as full supersampling sums them; an unrefined one's first sample.
    void resolve_colours(const PixelRect& rect, ImageRgb8& out, int out_x0, int out_y0) const;

    /// The fine grid of `decided` (decided.width() * sub by decided.height() * sub samples)
    /// for the robust lines: real samples where a pixel was refined; elsewhere the first
    /// sample's colour, ids and geometric normal, with the view depth of the first sample's
    /// plane along each sample's ray, which keeps the depth tests' planes planar.
    void fill_fine(ImageF& view_depth, Image<Vec3f>& normal, Image<Vec3f>& colour,
                   Image<std::uint32_t>& material, Image<std::uint32_t>& object) const;

private:
    void trace_first(const SamplerFrame& frame);
    void decide(const SamplerFrame& frame);
    void trace_refined(const SamplerFrame& frame);
    void mark_differences(const RefineRule& rule, const std::uint8_t* covered, int width);
    [[nodiscard]] bool depth_step(const SamplerFrame& frame, int x, int y) const;

    const SamplerFrame* frame_ = nullptr;
    PixelRect traced_, decided_;
    int sub_ = 1;
    SurfaceSamples first_;  ///< per pixel of traced_
    /// Per pixel of traced_: the first sample's refine key (RefineKey), in two arrays.
    std::vector<std::uint64_t> key_ids_, key_shade_;
    std::vector<std::uint8_t> refine_;  ///< per pixel of decided_
    /// Per pixel of traced_: whether it differs from the pixel to its right, and below.
    std::vector<std::uint8_t> differs_right_, differs_below_;
    std::vector<std::uint8_t> no_differences_;  ///< zeros: the row above the image
    std::vector<std::uint8_t> covered_;         ///< per pixel of traced_: SamplerFrame::covered
    /// Refined pixels (indices into decided_) and their other sub * sub - 1 samples, pixel by
    /// pixel, each pixel's in row order without the first.
    std::vector<std::uint32_t> refined_pixels_;
    std::vector<std::uint32_t> refined_slot_;  ///< per pixel of decided_: its first sample in rest_
    SurfaceSamples rest_;
    std::vector<Vec3f> dirs_, rest_dirs_;  ///< scratch: directions
    std::vector<Hit> hits_;
    std::unique_ptr<bool[]> hit_found_;  ///< scratch: whether each traced ray hit
    std::size_t hit_found_size_ = 0;
    std::vector<int> columns_, rows_;
};

}  // namespace toonray
