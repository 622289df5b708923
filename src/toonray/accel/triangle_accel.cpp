// Every float operation of the triangle tests must round exactly as written, in every build:
// no fused multiply-adds (the project compiles with -ffp-contract=off).
#include "toonray/accel/triangle_accel.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cstdlib>
#include <memory>

#include "toonray/accel/huge_pages.h"
#include "toonray/accel/kernels.h"
#include "toonray/accel/watertight.h"

namespace toonray {
namespace {

bool cpu_has_avx2() {
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
           __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2");
#else
    return false;
#endif
}

bool cpu_has_avx512() {
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
    return cpu_has_avx2() && __builtin_cpu_supports("avx512f") &&
           __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512bw") &&
           __builtin_cpu_supports("avx512dq");
#else
    return false;
#endif
}

// The kernels for an instruction set, when this build has them and the CPU runs them.
const accel::KernelTable* kernels_for(std::string_view isa) {
    if (isa == "sse4.2") return &accel::kernels_sse();
    if (isa == "avx2") return cpu_has_avx2() ? accel::kernels_avx2() : nullptr;
    if (isa == "avx512") return cpu_has_avx512() ? accel::kernels_avx512() : nullptr;
    return nullptr;
}

const accel::KernelTable* best_kernels() {
    if (const char* env = std::getenv("TOONRAY_ACCEL_ISA"))
        if (const accel::KernelTable* t = kernels_for(env)) return t;
    for (const char* isa : {"avx512", "avx2"})
        if (const accel::KernelTable* t = kernels_for(isa)) return t;
    return &accel::kernels_sse();
}

std::atomic<const accel::KernelTable*>& kernels_slot() {
    static std::atomic<const accel::KernelTable*> slot{best_kernels()};
    return slot;
}

const accel::KernelTable& kernels() { return *kernels_slot().load(std::memory_order_relaxed); }

void boxes_of(std::span<const Vec3f> positions, std::span<const std::array<std::uint32_t, 3>> tris,
              std::vector<BBox>& boxes) {
    accel::reserve_huge(boxes, tris.size());
    boxes.resize(tris.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, tris.size(), 1u << 14),
                      [&](const auto& r) {
                          for (std::size_t i = r.begin(); i != r.end(); ++i) {
                              BBox b;
                              for (std::uint32_t v : tris[i]) b.extend(positions[v]);
                              boxes[i] = b;
                          }
                      });
}

constexpr std::size_t kFixedStack = 256;

}  // namespace

const char* accel_isa() { return kernels().name; }

bool set_accel_isa(std::string_view isa) {
    const accel::KernelTable* table = isa == "auto" ? best_kernels() : kernels_for(isa);
    if (!table) return false;
    kernels_slot().store(table);
    return true;
}

bool intersect_triangle(const Ray& ray, const Vec3f& v0, const Vec3f& v1, const Vec3f& v2, float& t,
                        float& u, float& v) {
    return accel::watertight_test(accel::ShearedRay(ray), v0, v1, v2, ray.tmax, t, u, v) &&
           t < ray.tmax;
}

void TriangleAccel::build(std::span<const Vec3f> positions,
                          std::span<const std::array<std::uint32_t, 3>> tris,
                          const Bvh::Config& config) {
    std::vector<float> leaf_areas;
    bvh_ = Bvh::build(positions, tris, config, &leaf_areas);
    triangle_count_ = tris.size();
    collapse_ = {config.traversal_cost, config.intersection_cost};
    wide_.build(bvh_, leaf_areas, positions, tris, collapse_);
}

void TriangleAccel::refit(std::span<const Vec3f> positions,
                          std::span<const std::array<std::uint32_t, 3>> tris) {
    std::vector<BBox> boxes;
    boxes_of(positions, tris, boxes);
    bvh_.refit(boxes);
    std::vector<float> leaf_areas(bvh_.prim_indices.size());
    for (std::size_t i = 0; i < leaf_areas.size(); ++i)
        leaf_areas[i] = boxes[bvh_.prim_indices[i]].half_area();
    wide_.build(bvh_, leaf_areas, positions, tris, collapse_);
}

std::size_t TriangleAccel::memory_bytes() const {
    return bvh_.nodes.capacity() * sizeof(BvhNode) +
           bvh_.prim_indices.capacity() * sizeof(std::uint32_t) +
           wide_.nodes.capacity() * sizeof(accel::WideNode) +
           wide_.blocks.capacity() * sizeof(accel::TriBlock);
}

bool TriangleAccel::intersect(const Ray& ray, Hit& hit) const {
    if (wide_.max_stack <= kFixedStack) {
        std::uint64_t stack[kFixedStack];
        return kernels().intersect1(wide_, ray, hit, stack);
    }
    std::vector<std::uint64_t> stack(wide_.max_stack);
    return kernels().intersect1(wide_, ray, hit, stack.data());
}

bool TriangleAccel::occluded(const Ray& ray) const {
    if (wide_.max_stack <= kFixedStack) {
        std::uint64_t stack[kFixedStack];
        return kernels().occluded1(wide_, ray, stack);
    }
    std::vector<std::uint64_t> stack(wide_.max_stack);
    return kernels().occluded1(wide_, ray, stack.data());
}

void TriangleAccel::intersect_tile(const Vec3f& origin, const Vec3f* dirs, int width, int height,
                                   Hit* hits, bool* found, float tmax) const {
    if (width <= 0 || height <= 0) return;
    if (width <= kTileSize && height > kTileSize) {
        // A narrow grid (a list of rays a few wide): its tiles are runs of whole rows, which
        // lie next to each other in memory already.
        for (int y0 = 0; y0 < height; y0 += kTileSize) {
            const std::size_t at = static_cast<std::size_t>(y0) * width;
            intersect_tile(origin, dirs + at, width, std::min(kTileSize, height - y0), hits + at,
                           found + at, tmax);
        }
        return;
    }
    if (width > kTileSize || height > kTileSize) {
        // Larger grids: tile them.
        for (int y0 = 0; y0 < height; y0 += kTileSize)
            for (int x0 = 0; x0 < width; x0 += kTileSize) {
                const int w = std::min(kTileSize, width - x0), h = std::min(kTileSize, height - y0);
                Vec3f d[kTileSize * kTileSize];
                Hit hh[kTileSize * kTileSize];
                bool ff[kTileSize * kTileSize];
                for (int y = 0; y < h; ++y)
                    for (int x = 0; x < w; ++x) d[y * w + x] = dirs[(y0 + y) * width + x0 + x];
                intersect_tile(origin, d, w, h, hh, ff, tmax);
                for (int y = 0; y < h; ++y)
                    for (int x = 0; x < w; ++x) {
                        hits[(y0 + y) * width + x0 + x] = hh[y * w + x];
                        found[(y0 + y) * width + x0 + x] = ff[y * w + x];
                    }
            }
        return;
    }
    if (wide_.max_stack <= kFixedStack) {
        accel::TileEntry stack[kFixedStack];
        std::uint64_t stack1[kFixedStack];
        kernels().intersect_tile(wide_, origin, dirs, width, height, tmax, hits, found, stack,
                                 stack1);
        return;
    }
    std::vector<accel::TileEntry> stack(wide_.max_stack);
    std::vector<std::uint64_t> stack1(wide_.max_stack);
    kernels().intersect_tile(wide_, origin, dirs, width, height, tmax, hits, found, stack.data(),
                             stack1.data());
}

}  // namespace toonray
