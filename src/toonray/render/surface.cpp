#include "toonray/render/surface.h"

#include "toonray/core/image.h"

namespace toonray {
namespace {

// Calls f(array, values per sample) on every array of a level, in one list, so that resize,
// bytes and bytes_per_sample cannot disagree about which arrays a level keeps.
template <typename Samples, typename F>
void for_each_array(Samples& s, SurfaceFields level, int light_count, F&& f) {
    f(s.found, 1);
    f(s.object, 1);
    f(s.material, 1);
    f(s.band, 1);
    f(s.accents, 1);
    f(s.albedo, 1);
    f(s.image, 1);
    f(s.colour, 1);
    f(s.edge, 1);
    const bool geometry = level >= SurfaceFields::Geometry, all = level >= SurfaceFields::All;
    f(s.distance, geometry);
    f(s.view_depth, geometry);
    f(s.normal, geometry);
    f(s.geometric_normal, geometry);
    f(s.position, all);
    f(s.uv, all);
    f(s.prim, all);
    f(s.barycentric, all);
    f(s.diffuse, all);
    f(s.n_dot_l, all ? light_count : 0);
    f(s.shadowed, all);
}

}  // namespace

void SurfaceSamples::resize(std::size_t n, SurfaceFields level, int lights) {
    fields = level;
    light_count = lights;
    for_each_array(*this, level, lights,
                   [n](auto& array, int per_sample) { resize_exact(array, n * per_sample); });
}

std::uint64_t SurfaceSamples::bytes() const {
    std::uint64_t bytes = 0;
    // Every array, whatever the level: a smaller level keeps the memory of a larger one.
    for_each_array(*this, SurfaceFields::All, 0,
                   [&](const auto& array, int) { bytes += array.capacity() * sizeof(array[0]); });
    return bytes;
}

std::uint64_t SurfaceSamples::bytes_per_sample(SurfaceFields level, int lights) {
    std::uint64_t bytes = 0;
    SurfaceSamples none;
    for_each_array(none, level, lights, [&](const auto& array, int per_sample) {
        bytes += static_cast<std::uint64_t>(per_sample) * sizeof(array[0]);
    });
    return bytes;
}

}  // namespace toonray
