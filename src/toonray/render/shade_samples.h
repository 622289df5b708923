#pragma once
/// The per-sample work after tracing, in every line mode: the surface record of each traced
/// sample (render/surface.h), at the level of fields the frame needs.

#include <cstddef>

#include "toonray/accel/ray.h"
#include "toonray/render/look.h"
#include "toonray/render/shading.h"
#include "toonray/render/surface.h"
#include "toonray/scene/camera.h"

namespace toonray {

/// Fills samples [offset, offset + n) of `out` (sized by SurfaceSamples::resize, whose level
/// says which fields) from n traced samples: their unit directions from view.eye, their hits
/// and whether they hit; then each sample's look (look_sample). Everything but the image
/// positions, which are the sampler's. Normals are shading_normal's and geometric_normal's, and
/// the light terms light_terms's, bit for bit. What a triangle contributes (normals, material, whether plain
/// lighting applies) is looked up once for a run of samples that hit it: on a piano frame
/// that made shading 1.5x faster, where shading four samples at once in SIMD, gathering each
/// one's triangle, gained at most 7%.
void shade_samples(const ShadingContext& ctx, const LookFrame& look, const ViewPlane& view, int n,
                   const Vec3f* dirs, const Hit* hits, const bool* found, SurfaceSamples& out,
                   std::size_t offset);

}  // namespace toonray
