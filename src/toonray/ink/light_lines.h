#pragma once
/// Lines of the light (`--lines band,shadow`): the boundaries between cel bands on the surfaces,
/// the light/shade terminator included, and the boundaries of cast shadows on the surfaces that
/// receive them. Both are feature segments, which the ink's visibility, chaining, styles,
/// drawing and SVG take like every other type (ink.h).

#include <cstdint>
#include <span>
#include <vector>

#include "toonray/accel/triangle_accel.h"
#include "toonray/core/math.h"
#include "toonray/ink/feature_edges.h"
#include "toonray/ink/screen.h"
#include "toonray/scene/light.h"
#include "toonray/scene/scene.h"

namespace toonray::ink {

/// The light a frame's shading sees: its lights and its ramp's thresholds (diffuse light below
/// thresholds[0] is band 0, and so on).
struct LightingModel {
    std::span<const Light> lights;
    std::span<const float> thresholds;
};

/// The diffuse term shading gives point `p` with unit normal `n`, before toon shadows: the sum
/// over the lights of intensity times max(0, n.l), l toward a point light from p or against a
/// directional light's direction (render/shading.h, light_terms).
[[nodiscard]] float diffuse_light(std::span<const Light> lights, const Vec3f& p, const Vec3f& n);

/// n.l of one light at `p` (unclamped): zero on its terminator.
[[nodiscard]] float light_cosine(const Light& light, const Vec3f& p, const Vec3f& n);

/// The band of a diffuse term: how many thresholds min(diffuse, 1) reaches.
[[nodiscard]] std::uint8_t band_of(std::span<const float> thresholds, float diffuse);

/// Band lines inside triangles: where the diffuse term interpolated linearly from the corners
/// (their normals, turned to face the eye with the face) crosses a threshold in (0, 1], and where
/// each light's n.l crosses 0 (its terminator); one segment per triangle and boundary, found as
/// smooth contours are (Hertzmann & Zorin 2000), the same point from both triangles of an edge.
/// Band changes across mesh edges between faces that do not shade smoothly are found with the
/// mesh edges (FeatureEdgeSettings::bands). In triangle order, whatever the thread count.
/// Triangles turned away from the eye on closed solids (`outward`, feature_edges.h) are hidden
/// and left out; elsewhere normals face the eye with their face, as shading turns them.
[[nodiscard]] std::vector<FeatureSegment> band_segments(const Scene& scene, const WeldedMesh& mesh,
                                                        const Vec3f& eye,
                                                        const LightingModel& lighting,
                                                        std::span<const std::int8_t> outward,
                                                        int threads);

/// Shadow lines: for each light (the first 32, as toon shadows), the boundaries of the shadows
/// cast on the surfaces facing it. Each edge of the scene that is a silhouette seen from the
/// light (a face toward it and a face away, or a border) sweeps a wedge away from the light; where
/// the wedge cuts a receiving triangle is a candidate boundary, kept where a ray from it to the
/// light meets nothing but the triangles around the casting edge (sampled a pixel apart on the
/// image and bisected to 1/16 px, as visibility is). Pieces outside the view are left out. In a
/// fixed order, whatever the thread count.
[[nodiscard]] std::vector<FeatureSegment> shadow_segments(
    const Scene& scene, const WeldedMesh& mesh, const TriangleAccel& accel,
    const ScreenProjection& view, const LightingModel& lighting, int threads);

}  // namespace toonray::ink
