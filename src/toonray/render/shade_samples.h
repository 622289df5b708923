#pragma once
/// The per-sample work of every line mode after tracing: the toon colour of each traced sample
/// and what its mode's lines need of the surface there.

#include <cstdint>

#include "toonray/accel/ray.h"
#include "toonray/render/shading.h"
#include "toonray/scene/camera.h"

namespace toonray {

/// Where shade_samples writes; null arrays are not written.
struct ShadedSamples {
    Vec3f* colour = nullptr;            ///< toon colour; the background on a miss
    float* view_depth = nullptr;        ///< along the view direction; +inf on a miss
    float* distance = nullptr;          ///< along the ray; +inf on a miss
    Vec3f* geometric_normal = nullptr;  ///< unit, facing the viewer; 0 on a miss
    Vec3f* shading_normal = nullptr;    ///< unit, facing the viewer; 0 on a miss
    std::uint32_t* material = nullptr;  ///< kNoIndex on a miss
    std::uint32_t* object = nullptr;    ///< kNoIndex on a miss
    std::uint8_t* found = nullptr;      ///< 1 on a hit
};

/// Shades n traced samples (their unit directions from view.eye, hits and whether they hit)
/// into out[0, n): what shading_normal, geometric_normal and shade_hit give, bit for bit. What
/// a triangle contributes (normals, material, whether plain lighting applies) is looked up once
/// for a run of samples that hit it: on a piano frame that made shading 1.5x faster, where
/// shading four samples at once in SIMD, gathering each one's triangle, gained at most 7%.
void shade_samples(const ShadingContext& ctx, const ViewPlane& view, const Vec3f& background, int n,
                   const Vec3f* dirs, const Hit* hits, const bool* found, const ShadedSamples& out);

}  // namespace toonray
