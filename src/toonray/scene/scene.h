#pragma once
/// A triangle scene as loaded from OBJ/MTL or built in code.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "toonray/core/affine.h"
#include "toonray/core/bbox.h"
#include "toonray/core/image.h"
#include "toonray/core/index.h"
#include "toonray/core/math.h"
#include "toonray/scene/camera.h"

namespace toonray {

struct Material {
    explicit Material(std::string name_ = {}) : name(std::move(name_)) {}

    std::string name;
    Vec3f kd{0.8f};  ///< diffuse colour; 0.8 grey for faces without a material
    Vec3f ka{0.0f};
    Vec3f ks{0.0f};
    float ns = 0.0f;
    float d = 1.0f;
    int illum = 2;
    std::string map_kd;  ///< texture path as written in the MTL, resolved relative to it
    /// A texture the loader decoded itself (glTF images, which may sit inside the file); used
    /// instead of map_kd. v = 0 at the bottom, as OBJ texture coordinates have it.
    std::shared_ptr<const ImageRgb8> kd_image;
};

/// A polyline (an OBJ `l` element): its points are positions[polyline_points[first + i]] for
/// i < count (at least 2), drawn as ink strokes with its object's and material's lines.
struct Polyline {
    std::uint32_t first = 0, count = 0;
    std::uint32_t material = 0, object = 0;
};

/// Triangles with per-corner indices into shared attribute arrays: a scene's own triangles
/// (Scene derives from it) or a mesh that instances share (Scene::meshes).
struct TriangleMesh {
    std::vector<Vec3f> positions;
    std::vector<Vec3f> normals;
    std::vector<Vec2f> texcoords;
    /// Vertex colours by position index (glTF COLOR_0), multiplying Kd; empty when the mesh
    /// has none, else as long as `positions`.
    std::vector<Vec3f> colours;

    std::vector<std::array<std::uint32_t, 3>> tri_positions;
    std::vector<std::array<std::uint32_t, 3>> tri_normals;    ///< kNoIndex where a corner has none
    std::vector<std::array<std::uint32_t, 3>> tri_texcoords;  ///< kNoIndex where a corner has none
    /// Index into the scene's materials (a mesh's triangles use its scene's materials).
    std::vector<std::uint32_t> tri_material;
    /// Index into the scene's objects. The triangles of an instanced mesh take their
    /// instance's object instead (Instance::object), whatever this says.
    std::vector<std::uint32_t> tri_object;

    [[nodiscard]] std::size_t triangle_count() const { return tri_positions.size(); }
    /// Bounds of the vertices that triangles use.
    [[nodiscard]] BBox triangle_bounds() const;

    /// Appends a triangle; normals/texcoords default to none.
    void add_triangle(std::array<std::uint32_t, 3> v, std::uint32_t material, std::uint32_t object,
                      std::array<std::uint32_t, 3> n = {kNoIndex, kNoIndex, kNoIndex},
                      std::array<std::uint32_t, 3> t = {kNoIndex, kNoIndex, kNoIndex}) {
        tri_positions.push_back(v);
        tri_normals.push_back(n);
        tri_texcoords.push_back(t);
        tri_material.push_back(material);
        tri_object.push_back(object);
    }
    void clear_triangles();
};

/// One placement of a shared mesh (Scene::meshes): its triangles seen through `to_world`,
/// named by `object`. A scene holds a mesh once however often it is placed; an instance is a
/// small constant (the ray tracer's share of it: accel/triangle_accel.h, kBytesPerInstance).
struct Instance {
    std::uint32_t mesh = 0;  ///< index into Scene::meshes
    Affine3 to_world;        ///< object space to world space; invertible
    /// Index into Scene::objects: the name its strokes, ids and styles go by (every triangle of
    /// the instance is of this object).
    std::uint32_t object = 0;
};

/// A scene: its own triangles (the TriangleMesh it derives from, in world space), materials,
/// objects, the camera block, polylines, and instances of shared meshes.
///
/// Instances (a binding fills them like this; glTF nodes that share a mesh and the piano's keys
/// do the same):
///
///     auto mesh = std::make_shared<TriangleMesh>();   // object space; tri_material indexes
///     ...fill mesh->positions, tri_positions, ...      // scene.materials
///     const std::uint32_t m = scene.add_mesh(std::move(mesh));
///     scene.add_instance(m, Affine3::from_row_major(matrix), "tree.001");
///
/// A mesh is immutable once added (shared_ptr to const): renderers keep work done on it (its
/// BVH, its ink lines' feature edges) across frames while the same mesh object is used, so a
/// changed mesh must be a new object. Every function of the library takes instances into
/// account; flatten_instances() turns them into the scene's own triangles.
struct Scene : TriangleMesh {
    std::vector<Material> materials{Material{"(default)"}};
    std::vector<std::string> objects{"(default)"};

    std::optional<CameraSpec> camera;  ///< from the OBJ camera block, if any

    std::vector<std::uint32_t> polyline_points;  ///< position indices of all polylines
    std::vector<Polyline> polylines;

    std::vector<std::shared_ptr<const TriangleMesh>> meshes;  ///< shared by instances
    std::vector<Instance> instances;

    /// Bounds of the vertices that triangles use (camera vertices do not count), the
    /// instances' included (each by its mesh's bounds transformed, Affine3::box).
    [[nodiscard]] BBox bounds() const;

    /// Adds a mesh for instances and returns its index. Throws Error when a triangle refers to
    /// a vertex, normal or texture coordinate it does not have, or when its arrays disagree.
    std::uint32_t add_mesh(std::shared_ptr<const TriangleMesh> mesh);
    /// Places mesh `mesh` (an index from add_mesh) by `to_world`, as a new object named
    /// `object_name`; returns the instance's index. Throws Error for an unknown mesh or a
    /// transform that is not finite and invertible.
    std::uint32_t add_instance(std::uint32_t mesh, const Affine3& to_world,
                               std::string object_name);
    /// The same, with an object already in `objects` (several instances may share one).
    std::uint32_t add_instance(std::uint32_t mesh, const Affine3& to_world, std::uint32_t object);

    /// The mesh a triangle of instance `instance` comes from; the scene itself for kNoIndex.
    [[nodiscard]] const TriangleMesh& mesh_of(std::uint32_t instance) const {
        return instance == kNoIndex ? *this : *meshes[instances[instance].mesh];
    }
    /// Whether any triangle has vertex colours: the scene's own or an instanced mesh's.
    [[nodiscard]] bool has_colours() const;
    /// Triangles of the instances, each counted once per instance (what flattening makes).
    [[nodiscard]] std::uint64_t instanced_triangle_count() const;
    /// Triangles stored: the scene's own and each mesh's once.
    [[nodiscard]] std::uint64_t stored_triangle_count() const;
    /// Vertex attributes stored: positions, normals and texture coordinates, own and meshes'.
    [[nodiscard]] std::uint64_t stored_vertex_count() const;

    void clear();
};

/// The scene with every instance's triangles appended to its own, transformed (positions by
/// Affine3::point, normals by Affine3::unit_normal, as the glTF loader transforms a node's
/// mesh), in instance order, each instance's object on its triangles; no instances left.
[[nodiscard]] Scene flatten_instances(const Scene& scene);

/// Memory for a scene of `vertices` attribute values, `triangles` stored triangles and
/// `instances` instances while it is rendered, saturating at the largest value: its arrays, and
/// what rendering builds from it (the BVH build, the packed triangles and the automatic
/// camera's corner list; per instance its record, its object name and its share of the top
/// level BVH). Deliberately generous, as the estimates of core/limits.h are.
[[nodiscard]] std::uint64_t scene_bytes(std::uint64_t vertices, std::uint64_t triangles,
                                        std::uint64_t instances = 0);
/// scene_bytes of what `scene` stores.
[[nodiscard]] std::uint64_t scene_bytes(const Scene& scene);

}  // namespace toonray
