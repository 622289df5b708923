#pragma once
/// Scenes built from arrays rather than read from files: meshes given as positions, triangles
/// and optional attributes (the Python module's numpy arrays, the Blender engine's evaluated
/// meshes), placed in the world by a transform.

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "toonray/core/affine.h"
#include "toonray/core/limits.h"
#include "toonray/core/math.h"
#include "toonray/scene/scene.h"

namespace toonray {

/// A triangle mesh as arrays, in its own coordinates. Per-corner attributes follow the
/// triangles: corner k of triangle t is entry 3 t + k.
struct MeshArrays {
    std::span<const Vec3f> positions;
    std::span<const std::array<std::uint32_t, 3>> triangles;  ///< indices into positions
    std::span<const Vec3f> normals;  ///< none, one per position, or one per corner
    std::span<const Vec2f> uvs;      ///< none, one per position, or one per corner
    /// None (every triangle has the default material, 0), or one per triangle: an index into
    /// the scene's materials.
    std::span<const std::uint32_t> materials;
};

/// Checks a mesh on its own: every index within the positions, attribute counts of none, one
/// per position or one per corner, finite values, materials below `material_count`. Throws
/// Error("mesh 'NAME': what is wrong").
void check_mesh(const MeshArrays& mesh, std::size_t material_count, std::string_view name);

/// Appends `mesh` (checked with check_mesh) placed by `to_world` as a new object named `name`;
/// returns the object's index. Positions are transformed in double precision and rounded to
/// float once (the identity copies them exactly); normals are transformed by the inverse
/// transpose and normalised. A mirroring transform (negative determinant) reverses each
/// triangle's corners so that its winding still faces where its normals do. Throws Error for a
/// transform that is not finite or is singular, and Error or LimitError when the scene would
/// need more than 32-bit indices.
std::uint32_t append_mesh(Scene& scene, const MeshArrays& mesh, const Affine3& to_world,
                          std::string name);

/// `mesh` (checked with check_mesh against `material_count` materials) as a mesh for instances
/// (Scene::add_mesh), in its own coordinates: the triangles append_mesh would append to an empty
/// scene with the identity transform, so that an instance of it placed by M and the mesh
/// appended by M are the same triangles (the instance's are transformed as it is traced).
[[nodiscard]] std::shared_ptr<const TriangleMesh> instance_mesh(const MeshArrays& mesh,
                                                                std::size_t material_count,
                                                                std::string_view name);

/// Throws LimitError when `scene` stores more triangles or vertex positions than `limits` allow
/// (max_triangles, max_vertices; an instanced mesh counts once), in the words of the loaders:
/// "the scene has N triangles, more than the limit of M".
void check_scene_limits(const Scene& scene, const Limits& limits);

}  // namespace toonray
