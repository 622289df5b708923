#include "toonray/render/surface.h"

#include "toonray/core/image.h"

namespace toonray {
namespace {

// Calls f(array, values per sample) on every array, with 0 values for the arrays `fields` does
// not keep, in one list, so that resize, bytes and bytes_per_sample cannot disagree.
template <typename Samples, typename F>
void for_each_array(Samples& s, unsigned fields, int light_count, F&& f) {
    const int keys = (fields & kSurfaceKeys) ? 1 : 0,
              distance = (fields & kSurfaceDistance) ? 1 : 0,
              view = (fields & kSurfaceViewDepth) ? 1 : 0, where = (fields & kSurfaceWhere) ? 1 : 0;
    f(s.found, 1);
    f(s.colour, 1);
    f(s.object, keys);
    f(s.material, keys);
    f(s.band, keys);
    f(s.accents, keys);
    f(s.albedo, where);
    f(s.edge, keys);
    f(s.distance, distance);
    f(s.normal, distance);
    f(s.view_depth, view);
    f(s.geometric_normal, view);
    f(s.image, where);
    f(s.position, where);
    f(s.uv, where);
    f(s.prim, where);
    f(s.barycentric, where);
    f(s.diffuse, where);
    f(s.n_dot_l, where * light_count);
    f(s.shadowed, where);
}

}  // namespace

void SurfaceSamples::resize(std::size_t n, unsigned kept, int lights) {
    fields = kept;
    light_count = lights;
    for_each_array(*this, kept, lights,
                   [n](auto& array, int per_sample) { resize_exact(array, n * per_sample); });
}

std::uint64_t SurfaceSamples::bytes() const {
    std::uint64_t bytes = 0;
    // Every array, kept or not: an array left empty keeps the memory it had.
    for_each_array(*this, kSurfaceAll, 0,
                   [&](const auto& array, int) { bytes += array.capacity() * sizeof(array[0]); });
    return bytes;
}

std::uint64_t SurfaceSamples::bytes_per_sample(unsigned kept, int lights) {
    std::uint64_t bytes = 0;
    SurfaceSamples none;
    for_each_array(none, kept, lights, [&](const auto& array, int per_sample) {
        bytes += static_cast<std::uint64_t>(per_sample) * sizeof(array[0]);
    });
    return bytes;
}

}  // namespace toonray
