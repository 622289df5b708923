// Every float operation of the triangle tests must round exactly as written, in every build:
// no fused multiply-adds (the project compiles with -ffp-contract=off).
#include "toonray/accel/triangle_accel.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <memory>

#include "toonray/accel/huge_pages.h"
#include "toonray/accel/kernels.h"
#include "toonray/accel/watertight.h"
#include "toonray/core/error.h"

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

// An instance's world box is grown by this fraction of its size plus its distance from the
// origin: the ray is taken into object space in float, so a hit found there lies near, not
// exactly on, the world ray, and the top level must not cull it on any CPU (a hit culled on
// one instruction set and found on another would change pixels). The rounding is about 2^-24
// of the coordinates; this covers eyes up to some hundreds of times the scene's size away.
constexpr double kInstanceBoxPad = 1.0 / (1 << 14);

BBox padded(const BBox& b) {
    if (b.empty()) return b;
    double size = 0;
    for (int a = 0; a < 3; ++a)
        size = std::max({size, double(b.hi[a]) - double(b.lo[a]), std::abs(double(b.lo[a])),
                         std::abs(double(b.hi[a]))});
    const float pad = static_cast<float>(size * kInstanceBoxPad);
    BBox out = b;
    for (int a = 0; a < 3; ++a) {
        out.lo[a] = std::nextafter(b.lo[a] - pad, -std::numeric_limits<float>::infinity());
        out.hi[a] = std::nextafter(b.hi[a] + pad, std::numeric_limits<float>::infinity());
    }
    return out;
}

// A stack of n entries of T: on the stack up to kFixedStack, else on the heap.
template <class T>
struct Stack {
    T fixed[kFixedStack];
    std::vector<T> heap;
    explicit Stack(std::size_t n) {
        if (n > kFixedStack) heap.resize(n);
    }
    T* data() { return heap.empty() ? fixed : heap.data(); }
};

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

TriangleAccel::TriangleAccel(const TriangleAccel& other) { *this = other; }

TriangleAccel& TriangleAccel::operator=(const TriangleAccel& other) {
    if (this == &other) return *this;
    bvh_ = other.bvh_;
    wide_ = std::make_unique<accel::WideBvh>(*other.wide_);
    collapse_ = other.collapse_;
    triangle_count_ = other.triangle_count_;
    top_config_ = other.top_config_;
    meshes_ = other.meshes_;
    instance_mesh_ = other.instance_mesh_;
    to_world_ = other.to_world_;
    instance_count_ = other.instance_count_;
    level_.reset();
    if (other.level_) {
        level_ = std::make_unique<accel::InstanceLevel>(*other.level_);
        // The own triangles' record points to this copy's tree.
        for (accel::InstanceRecord& r : level_->records)
            if (r.identity) r.tree = wide_.get();
    }
    return *this;
}

void TriangleAccel::build(std::span<const Vec3f> positions,
                          std::span<const std::array<std::uint32_t, 3>> tris,
                          const Bvh::Config& config) {
    std::vector<float> leaf_areas;
    bvh_ = Bvh::build(positions, tris, config, &leaf_areas);
    triangle_count_ = tris.size();
    collapse_ = {config.traversal_cost, config.intersection_cost};
    wide_->build(bvh_, leaf_areas, positions, tris, collapse_);
    if (level_) build_instance_level();
}

void TriangleAccel::refit(std::span<const Vec3f> positions,
                          std::span<const std::array<std::uint32_t, 3>> tris) {
    std::vector<BBox> boxes;
    boxes_of(positions, tris, boxes);
    bvh_.refit(boxes);
    std::vector<float> leaf_areas(bvh_.prim_indices.size());
    for (std::size_t i = 0; i < leaf_areas.size(); ++i)
        leaf_areas[i] = boxes[bvh_.prim_indices[i]].half_area();
    wide_->build(bvh_, leaf_areas, positions, tris, collapse_);
    if (level_) build_instance_level();
}

void TriangleAccel::set_instances(std::span<const AccelInstance> instances,
                                  const Bvh::Config& config) {
    meshes_.clear();
    instance_mesh_.clear();
    to_world_.clear();
    level_.reset();
    instance_count_ = 0;
    if (instances.empty()) return;
    for (std::size_t i = 0; i < instances.size(); ++i) {
        const AccelInstance& instance = instances[i];
        if (!instance.mesh) throw Error(fmt::format("instance {}: no mesh", i));
        if (instance.mesh->instance_count() != 0)
            throw Error(fmt::format("instance {}: its mesh has instances of its own", i));
        if (!instance.to_world.invertible())
            throw Error(fmt::format("instance {}: the transform cannot be inverted", i));
    }
    if (instances.size() >= accel::kMaxSlots) throw Error("too many instances");
    std::vector<const TriangleAccel*> seen;
    instance_mesh_.reserve(instances.size());
    to_world_.reserve(instances.size());
    for (const AccelInstance& instance : instances) {
        const auto it = std::find(seen.begin(), seen.end(), instance.mesh.get());
        if (it == seen.end()) {
            instance_mesh_.push_back(static_cast<std::uint32_t>(seen.size()));
            seen.push_back(instance.mesh.get());
            meshes_.push_back(instance.mesh);
        } else {
            instance_mesh_.push_back(static_cast<std::uint32_t>(it - seen.begin()));
        }
        to_world_.push_back(instance.to_world);
    }
    instance_count_ = instances.size();
    top_config_ = config;
    level_ = std::make_unique<accel::InstanceLevel>();
    build_instance_level();
}

void TriangleAccel::move_instances(std::span<const Affine3> to_world) {
    if (to_world.size() != instance_count_)
        throw Error(fmt::format("move_instances: {} transforms for {} instances", to_world.size(),
                                instance_count_));
    for (std::size_t i = 0; i < to_world.size(); ++i)
        if (!to_world[i].invertible())
            throw Error(fmt::format("instance {}: the transform cannot be inverted", i));
    std::copy(to_world.begin(), to_world.end(), to_world_.begin());
    if (level_) build_instance_level();
}

void TriangleAccel::build_instance_level() {
    accel::InstanceLevel& lv = *level_;
    // Records: the own triangles (rank 0) when there are any, then the instances.
    const bool own = triangle_count_ > 0;
    lv.records.clear();
    lv.records.reserve(instance_count_ + (own ? 1 : 0));
    std::vector<BBox> boxes;
    boxes.reserve(lv.records.capacity());
    lv.bottom_stack = 8;
    if (own) {
        accel::InstanceRecord r{};
        r.tree = wide_.get();
        r.rank = 0;
        r.identity = 1;
        lv.records.push_back(r);
        boxes.push_back(padded(bvh_.nodes[0].bounds));
        lv.bottom_stack = std::max(lv.bottom_stack, wide_->max_stack);
    }
    std::vector<BBox> mesh_box(meshes_.size());
    for (std::size_t m = 0; m < meshes_.size(); ++m) {
        const Bvh& b = meshes_[m]->bvh_;
        if (!b.nodes.empty()) mesh_box[m] = b.nodes[0].bounds;
        lv.bottom_stack = std::max(lv.bottom_stack, meshes_[m]->wide_->max_stack);
    }
    for (std::size_t i = 0; i < instance_count_; ++i) {
        const Affine3& m = to_world_[i];
        const Affine3 inv = m.inverse();
        accel::InstanceRecord r{};
        for (int row = 0; row < 3; ++row)
            for (int k = 0; k < 4; ++k) r.from_world[row][k] = static_cast<float>(inv.m[row][k]);
        r.tree = meshes_[instance_mesh_[i]]->wide_.get();
        r.rank = static_cast<std::uint32_t>(i + 1);
        r.identity = 0;
        lv.records.push_back(r);
        boxes.push_back(padded(m.box(mesh_box[instance_mesh_[i]])));
    }
    // The top level: a few records per leaf (each visit transforms the ray).
    Bvh::Config config = top_config_;
    config.max_leaf_size = std::min(config.max_leaf_size, 4);
    // Built anew for each pose (move_instances): a few microseconds for the piano's 88 keys,
    // and a tighter tree than a refit; the binary tree is dropped once collapsed.
    std::vector<float> leaf_areas;
    const Bvh top = Bvh::build(boxes, config, &leaf_areas);
    lv.tree.build_over_boxes(top, leaf_areas, boxes,
                             {config.traversal_cost, config.intersection_cost, 4, 1}, lv.slots);
}

std::size_t TriangleAccel::instance_level_bytes() const {
    if (!level_) return 0;
    const accel::InstanceLevel& lv = *level_;
    return lv.records.capacity() * sizeof(accel::InstanceRecord) +
           lv.slots.capacity() * sizeof(std::uint32_t) +
           lv.tree.nodes.capacity() * sizeof(accel::WideNode) +
           to_world_.capacity() * sizeof(Affine3) +
           instance_mesh_.capacity() * sizeof(std::uint32_t) +
           meshes_.capacity() * sizeof(std::shared_ptr<const TriangleAccel>);
}

std::size_t TriangleAccel::memory_bytes() const {
    std::size_t bytes = bvh_.nodes.capacity() * sizeof(BvhNode) +
                        bvh_.prim_indices.capacity() * sizeof(std::uint32_t) +
                        wide_->nodes.capacity() * sizeof(accel::WideNode) +
                        wide_->blocks.capacity() * sizeof(accel::TriBlock);
    for (const auto& mesh : meshes_) bytes += mesh->memory_bytes();
    return bytes + instance_level_bytes();
}

bool TriangleAccel::intersect(const Ray& ray, Hit& hit) const {
    if (level_) {
        Stack<std::uint64_t> top(level_->tree.max_stack), bottom(level_->bottom_stack);
        return kernels().intersect1_instances(*level_, ray, hit, top.data(), bottom.data());
    }
    const accel::WideBvh& wide = *wide_;
    if (wide.max_stack <= kFixedStack) {
        std::uint64_t stack[kFixedStack];
        return kernels().intersect1(wide, ray, hit, stack);
    }
    std::vector<std::uint64_t> stack(wide.max_stack);
    return kernels().intersect1(wide, ray, hit, stack.data());
}

bool TriangleAccel::occluded(const Ray& ray) const {
    if (level_) {
        Stack<std::uint64_t> top(level_->tree.max_stack), bottom(level_->bottom_stack);
        return kernels().occluded1_instances(*level_, ray, top.data(), bottom.data());
    }
    const accel::WideBvh& wide = *wide_;
    if (wide.max_stack <= kFixedStack) {
        std::uint64_t stack[kFixedStack];
        return kernels().occluded1(wide, ray, stack);
    }
    std::vector<std::uint64_t> stack(wide.max_stack);
    return kernels().occluded1(wide, ray, stack.data());
}

void TriangleAccel::intersect_tile(const Vec3f& origin, const Vec3f* dirs, int width, int height,
                                   Hit* hits, bool* found, float tmax, float ray_angle2) const {
    if (width <= 0 || height <= 0) return;
    if (!level_ && ray_angle2 >= 0.0f &&
        (std::isinf(ray_angle2) || !wide_->dense_for(origin, ray_angle2))) {
        const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
        for (std::size_t i = 0; i < n; ++i) {
            hits[i] = Hit{};
            found[i] = intersect(Ray{origin, dirs[i], tmax}, hits[i]);
        }
        return;
    }
    if (width <= kTileSize && height > kTileSize) {
        // A narrow grid (a list of rays a few wide): its tiles are runs of whole rows, which
        // lie next to each other in memory already.
        for (int y0 = 0; y0 < height; y0 += kTileSize) {
            const std::size_t at = static_cast<std::size_t>(y0) * width;
            intersect_tile(origin, dirs + at, width, std::min(kTileSize, height - y0), hits + at,
                           found + at, tmax, ray_angle2);
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
                intersect_tile(origin, d, w, h, hh, ff, tmax, ray_angle2);
                for (int y = 0; y < h; ++y)
                    for (int x = 0; x < w; ++x) {
                        hits[(y0 + y) * width + x0 + x] = hh[y * w + x];
                        found[(y0 + y) * width + x0 + x] = ff[y * w + x];
                    }
            }
        return;
    }
    if (level_) {
        const std::size_t top = level_->tree.max_stack, bottom = level_->bottom_stack;
        Stack<accel::TileEntry> stack(top), stack_b(bottom);
        Stack<std::uint64_t> stack1(top), stack1_b(bottom);
        kernels().intersect_tile_instances(*level_, origin, dirs, width, height, tmax, ray_angle2,
                                           hits, found, stack.data(), stack1.data(), stack_b.data(),
                                           stack1_b.data());
        return;
    }
    const accel::WideBvh& wide = *wide_;
    if (wide.max_stack <= kFixedStack) {
        accel::TileEntry stack[kFixedStack];
        std::uint64_t stack1[kFixedStack];
        kernels().intersect_tile(wide, origin, dirs, width, height, tmax, hits, found, stack,
                                 stack1);
        return;
    }
    std::vector<accel::TileEntry> stack(wide.max_stack);
    std::vector<std::uint64_t> stack1(wide.max_stack);
    kernels().intersect_tile(wide, origin, dirs, width, height, tmax, hits, found, stack.data(),
                             stack1.data());
}

}  // namespace toonray
