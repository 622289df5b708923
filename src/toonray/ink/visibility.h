#pragma once
/// Exact visibility of feature segments: each segment is cut where its visibility changes, as
/// seen by rays from points on it toward the eye, and each piece gets its quantitative
/// invisibility (the number of surfaces between it and the eye; Appel 1967).

#include <cstdint>
#include <span>
#include <vector>

#include "toonray/accel/triangle_accel.h"
#include "toonray/ink/feature_edges.h"
#include "toonray/ink/screen.h"

namespace toonray::ink {

struct VisibilitySettings {
    float step = 1.0f;            ///< pixels between samples along a segment's image
    float precision = 1.0f / 16;  ///< change points are refined by bisection to this many pixels
    /// A ray from a point toward the eye ignores hits closer to the point than this fraction
    /// of the distance to the eye, so that the surface a line lies on does not hide it.
    float self_epsilon = 1e-4f;
    /// The most occluders counted (1 or more): counts are exact up to it, and a point behind
    /// more surfaces gets it. 1 tells only visible (0) from hidden (1); then segments known
    /// to be hidden (FeatureSegment::certainly_hidden) are not traced at all, and each
    /// segment's samples are traced as one packet from the eye. More costs a ray query per
    /// extra surface on hidden points.
    int max_invisibility = 255;
    /// Segments are clipped to the image grown by this many pixels on each side.
    float margin = 4.0f;
    /// Whether hidden pieces are returned. Without them (when nothing draws hidden lines) a
    /// crowd's pieces take a third of the memory; each segment's pieces then first take the
    /// visibility of their neighbours as chaining would (settle_sub_pixel_pieces, with
    /// `min_piece`), so that the visible lines are the same.
    bool keep_hidden = true;
    float min_piece = 1.0f;
};

/// A part of a feature segment with one visibility.
struct EdgePiece {
    std::uint32_t segment = 0;  ///< index into the segments
    float t0 = 0, t1 = 1;       ///< parameters along the segment (p0 + (p1 - p0) t), t0 < t1
    Vec3f p0, p1;               ///< the piece's ends in the world
    Point2 s0, s1;              ///< and on the image
    /// The segment's keys where the piece ends at the segment's own ends; kNoIndex keys where
    /// it was cut (by visibility or clipping).
    EndpointKey key0, key1;
    EdgeType type = EdgeType::Silhouette;
    int invisibility = 0;  ///< occluding surfaces, at most VisibilitySettings::max_invisibility
    [[nodiscard]] bool visible() const { return invisibility == 0; }
};

/// Chaining's rule for one segment's pieces (in order along it): a piece whose image is shorter
/// than `min_piece` pixels, cut from both sides by pieces of the other visibility (or at an end
/// of the segment, from its one side) and contiguous with them, takes their visibility.
/// `visible` gets each piece's visibility after the rule.
void settle_sub_pixel_pieces(std::span<const EdgePiece> pieces, float min_piece,
                             std::vector<char>& visible);

struct InstanceLineCache;

/// Everything a visibility query needs: the scene's triangles in an accelerator, the welded
/// mesh (for the rings ignored around smooth contours) and the view; with instances, the welded
/// meshes of their meshes (instance_lines.h).
struct VisibilityContext {
    const Scene& scene;
    const WeldedMesh& mesh;
    const TriangleAccel& accel;
    const ScreenProjection& view;
    const InstanceLineCache* instances = nullptr;
};

/// A triangle of the scene as hits name it: (instance + 1) << 32 | triangle, so that the own
/// triangles' keys are their indices.
using TriangleKey = std::uint64_t;
[[nodiscard]] inline TriangleKey triangle_key(std::uint32_t instance, std::uint32_t triangle) {
    return (static_cast<TriangleKey>(instance + 1u) << 32) | triangle;
}

/// Triangles whose hits do not count against `segment`: its faces, and for a smooth contour
/// every triangle sharing a vertex with its face. Sorted.
[[nodiscard]] std::vector<std::uint32_t> ignored_triangles(const FeatureSegment& segment,
                                                           const WeldedMesh& mesh);
/// The same as keys, for segments on instances too (their rings from `instances`).
[[nodiscard]] std::vector<TriangleKey> ignored_triangle_keys(const FeatureSegment& segment,
                                                             const WeldedMesh& mesh,
                                                             const InstanceLineCache* instances);

/// Surfaces between `point` and the eye: hits of the segment from point to eye with parameter
/// in (self_epsilon, 1 - self_epsilon), not on an `ignored` triangle (sorted), exactly up to
/// max_invisibility, which caps the count; any number of ignored hits may come before them.
/// Hits closer together than a hundredth of self_epsilon count once.
[[nodiscard]] int count_occluders(const TriangleAccel& accel, const Vec3f& point, const Vec3f& eye,
                                  std::span<const std::uint32_t> ignored,
                                  const VisibilitySettings& settings);
/// The same with the ignored triangles as keys (any instance's).
[[nodiscard]] int count_occluders(const TriangleAccel& accel, const Vec3f& point, const Vec3f& eye,
                                  std::span<const TriangleKey> ignored,
                                  const VisibilitySettings& settings);

/// The segments cut into pieces of constant visibility, in segment order and along each
/// segment, the same for any thread count. Parts behind the eye or outside the image (grown by
/// the margin) are left out.
[[nodiscard]] std::vector<EdgePiece> split_by_visibility(std::span<const FeatureSegment> segments,
                                                         const VisibilityContext& context,
                                                         const VisibilitySettings& settings,
                                                         int threads);

/// Removes the segments that no piece lies on, keeping the others in order, and renumbers the
/// pieces' segments to match (the pieces are in segment order, as split_by_visibility gives
/// them). Then the segments of lines that are not drawn need not be held.
void drop_segments_without_pieces(std::vector<FeatureSegment>& segments,
                                  std::vector<EdgePiece>& pieces);

}  // namespace toonray::ink
