#pragma once
/// Auto-smooth by angle, as Blender's: vertex normals for triangles that have none, averaged
/// over the faces around a vertex that meet at less than an angle, so that curved scans shade
/// smoothly while creases stay sharp.

#include <cstddef>

#include "toonray/scene/scene.h"

namespace toonray {

/// Gives every triangle of `scene` that lacks a normal at any corner (a triangle the renderer
/// would shade flat) a normal at each corner:
///
/// - corners are welded by position within an object (exactly equal coordinates), so meshes
///   written with a vertex per triangle corner (STL-like scans) smooth too;
/// - an edge between two such triangles is smooth when exactly two triangles share it, they
///   wind it in opposite directions (consistently oriented), and their face normals differ by
///   less than `angle_degrees`; every other edge is sharp (Blender's rule);
/// - the corners around a vertex that smooth edges join form one group, whose normal is the
///   average of the group's face normals weighted by the triangles' angles at the vertex.
///
/// Triangles with normals at all three corners are left as they are and take no part; so are
/// degenerate triangles (no area, or two corners welded together), which stay flat. New
/// normals are appended to scene.normals. Deterministic: the same scene gives the same bits on
/// every platform (IEEE operations only, no libm functions; see core/portable_math.h).
/// Returns the number of triangles given normals. Throws Error when `angle_degrees` is not in
/// [0, 180] or the normals would not fit 32-bit indices. Works on a scene's own triangles or a
/// mesh's (the triangles of an instanced mesh are all of one object here).
std::size_t auto_smooth(TriangleMesh& scene, float angle_degrees);

/// auto_smooth on the scene's own triangles and on each instanced mesh that has triangles
/// without normals (replaced by a smoothed copy: meshes are shared and immutable). Returns the
/// number of triangles given normals, each mesh's counted once.
std::size_t auto_smooth_scene(Scene& scene, float angle_degrees);

}  // namespace toonray
