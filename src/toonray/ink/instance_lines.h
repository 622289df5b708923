#pragma once
/// The ink lines of a scene's instances (Scene::instances): feature edges of each distinct mesh
/// found once, in object space, and kept across frames; silhouettes and smooth contours found
/// per instance with the eye taken into object space, skipping the parts of the mesh that
/// cannot hold one (a tree over the faces' planes for mesh edges, a normal-cone hierarchy for
/// smooth contours) and the instances outside the view;
/// intersection lines within each mesh (found once) and between instances whose boxes overlap.
/// docs/ink.md, "Instances", has the rules.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "toonray/accel/triangle_accel.h"
#include "toonray/core/affine.h"
#include "toonray/ink/feature_edges.h"
#include "toonray/ink/screen.h"
#include "toonray/ink/visibility.h"
#include "toonray/scene/scene.h"

namespace toonray::ink {

/// One distinct mesh's eye-independent ink work (instance_lines.cpp).
struct MeshLines;

/// What the ink lines of instances keep from one frame to the next: each mesh's MeshLines
/// while frames use the same mesh object (meshes are immutable, so the same object is the
/// same triangles) and the same edge settings, and the crossings between two instances that
/// did not move.
struct InstanceLineCache {
    std::vector<std::shared_ptr<const MeshLines>> meshes;
    /// Per instance of the last frame: its mesh's entry.
    std::vector<const MeshLines*> of_instance;
    struct Pair {
        std::uint32_t a = 0, b = 0;  ///< instances, a < b
        /// Held, so that a new mesh's work can never take an old one's address.
        std::shared_ptr<const MeshLines> mesh_a, mesh_b;
        Affine3 to_world_a, to_world_b;
        std::vector<PairCrossing> crossings;  ///< t in a's mesh, u in b's
    };
    std::vector<Pair> pairs;  ///< by (a, b)
    /// How many meshes' work was done (not taken from the cache) so far.
    std::size_t mesh_builds = 0;
};

/// Switches for tests: the culling by the silhouette candidates' plane tree and the smooth
/// contours' normal cones (`cone_culling`) and by the view can be turned off, which must not
/// change any segment.
struct InstanceLineOptions {
    bool cone_culling = true;
    bool view_culling = true;
};

/// Visibility run on the instances' segments as they are found, a chunk of instances at a
/// time: a crowd's segments are mostly hidden or outside the image, and this way they are never
/// all held at once.
struct InstanceVisibility {
    VisibilitySettings settings;
    /// Out: the pieces of the segments appended, in segment order, numbering the segments as
    /// `segments` does (split_by_visibility's pieces of them, with `scene`, `own`, `accel`,
    /// `view` and the cache as context).
    std::vector<EdgePiece> pieces;
};

/// Appends the feature segments of `scene`'s instances seen through `plane` (projected by
/// `view`; visibility keeps what lies within `margin` pixels of the image) to `segments`, in a
/// fixed order whatever the thread count: per instance in index order its mesh edges, then its
/// smooth contours, then the intersection lines within its mesh; then the intersection lines
/// between instances, and between the scene's own triangles (welded as `own`, in `accel`'s
/// binary tree) and instances, by pair. Segments on an instance's triangles name it in
/// FeatureSegment::face_instance and in their endpoint keys. Instances whose boxes lie outside
/// the view (grown by a margin beyond visibility's) give none, and parts of a mesh outside it
/// give no smooth contours: their segments would be clipped away. Updates the cache. With `visibility`, only the segments
/// that keep a piece are appended, and their pieces go to visibility->pieces.
void add_instance_segments(const Scene& scene, const TriangleAccel& accel, const WeldedMesh& own,
                           const ViewPlane& plane, const ScreenProjection& view, float margin,
                           const FeatureEdgeSettings& settings, int threads,
                           InstanceLineCache& cache, std::vector<FeatureSegment>& segments,
                           const InstanceLineOptions& options = {},
                           InstanceVisibility* visibility = nullptr);

/// Where chaining may cut the pieces of add_instance_segments' segments [first_segment,
/// end_segment) of `segments` (which visibility keeps together, in segment order) into parts
/// of whole instances of at least `min_part` pieces each: chain_pieces_in_parts' cuts (one
/// cut, pieces.size(), when they are not together). An instance's end keys name it
/// (EndpointKey::instance), and a crossing's name both its sides (the other instance in
/// c_instance, or the own triangle crossed in c), so pieces of different instances never
/// meet, nor crossings of different pairs, nor any of them the rest's.
[[nodiscard]] std::vector<std::size_t> instance_chain_cuts(std::span<const EdgePiece> pieces,
                                                           std::span<const FeatureSegment> segments,
                                                           std::size_t first_segment,
                                                           std::size_t end_segment,
                                                           std::size_t min_part);

/// The welded mesh of instance `instance`'s mesh, as add_instance_segments last welded it.
[[nodiscard]] const WeldedMesh& instance_welded_mesh(const InstanceLineCache& cache,
                                                     std::uint32_t instance);

}  // namespace toonray::ink
