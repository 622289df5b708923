#include "toonray/scene/scene.h"

#include <fmt/format.h>

#include <limits>

#include "toonray/core/error.h"
#include "toonray/core/saturating.h"

namespace toonray {

BBox TriangleMesh::triangle_bounds() const {
    BBox box;
    for (const auto& tri : tri_positions)
        for (std::uint32_t v : tri) box.extend(positions[v]);
    return box;
}

void TriangleMesh::clear_triangles() {
    positions.clear();
    normals.clear();
    texcoords.clear();
    colours.clear();
    tri_positions.clear();
    tri_normals.clear();
    tri_texcoords.clear();
    tri_material.clear();
    tri_object.clear();
}

BBox Scene::bounds() const {
    BBox box = triangle_bounds();
    if (instances.empty()) return box;
    std::vector<BBox> mesh_box(meshes.size());
    for (std::size_t m = 0; m < meshes.size(); ++m) mesh_box[m] = meshes[m]->triangle_bounds();
    for (const Instance& instance : instances)
        box.extend(instance.to_world.box(mesh_box[instance.mesh]));
    return box;
}

std::uint32_t Scene::add_mesh(std::shared_ptr<const TriangleMesh> mesh) {
    if (!mesh) throw Error("add_mesh: no mesh");
    const TriangleMesh& m = *mesh;
    const std::size_t n = m.triangle_count();
    if (m.tri_normals.size() != n || m.tri_texcoords.size() != n || m.tri_material.size() != n ||
        m.tri_object.size() != n)
        throw Error(fmt::format(
            "add_mesh: {} triangles but {} normal, {} texture coordinate, {} material and {} "
            "object index triples",
            n, m.tri_normals.size(), m.tri_texcoords.size(), m.tri_material.size(),
            m.tri_object.size()));
    if (!m.colours.empty() && m.colours.size() != m.positions.size())
        throw Error(fmt::format("add_mesh: {} vertex colours for {} positions", m.colours.size(),
                                m.positions.size()));
    auto check = [&](const auto& indices, std::size_t count, const char* what, bool optional) {
        for (std::size_t t = 0; t < n; ++t)
            for (std::uint32_t i : indices[t])
                if ((i != kNoIndex || !optional) && i >= count)
                    throw Error(fmt::format("add_mesh: triangle {} refers to {} {} of {}", t, what,
                                            i, count));
    };
    check(m.tri_positions, m.positions.size(), "position", false);
    check(m.tri_normals, m.normals.size(), "normal", true);
    check(m.tri_texcoords, m.texcoords.size(), "texture coordinate", true);
    for (std::size_t t = 0; t < n; ++t)
        if (m.tri_material[t] >= materials.size())
            throw Error(fmt::format("add_mesh: triangle {} has material {} of {}", t,
                                    m.tri_material[t], materials.size()));
    if (meshes.size() >= kNoIndex) throw Error("add_mesh: too many meshes");
    meshes.push_back(std::move(mesh));
    return static_cast<std::uint32_t>(meshes.size() - 1);
}

std::uint32_t Scene::add_instance(std::uint32_t mesh, const Affine3& to_world,
                                  std::string object_name) {
    if (objects.size() >= kNoIndex) throw Error("add_instance: too many objects");
    objects.push_back(std::move(object_name));
    try {
        return add_instance(mesh, to_world, static_cast<std::uint32_t>(objects.size() - 1));
    } catch (...) {
        objects.pop_back();
        throw;
    }
}

std::uint32_t Scene::add_instance(std::uint32_t mesh, const Affine3& to_world,
                                  std::uint32_t object) {
    if (mesh >= meshes.size())
        throw Error(fmt::format("add_instance: mesh {} of {}", mesh, meshes.size()));
    if (object >= objects.size())
        throw Error(fmt::format("add_instance: object {} of {}", object, objects.size()));
    if (!to_world.invertible())
        throw Error(fmt::format("add_instance '{}': the transform is not finite and invertible",
                                objects[object]));
    if (instances.size() >= kNoIndex - 1) throw Error("add_instance: too many instances");
    instances.push_back(Instance{mesh, to_world, object});
    return static_cast<std::uint32_t>(instances.size() - 1);
}

bool Scene::has_colours() const {
    if (!colours.empty()) return true;
    for (const auto& mesh : meshes)
        if (!mesh->colours.empty()) return true;
    return false;
}

std::uint64_t Scene::instanced_triangle_count() const {
    std::uint64_t n = 0;
    for (const Instance& instance : instances)
        n = add_saturated(n, meshes[instance.mesh]->triangle_count());
    return n;
}

std::uint64_t Scene::stored_triangle_count() const {
    std::uint64_t n = triangle_count();
    for (const auto& mesh : meshes) n = add_saturated(n, mesh->triangle_count());
    return n;
}

std::uint64_t Scene::stored_vertex_count() const {
    auto attributes = [](const TriangleMesh& m) {
        return std::max({m.positions.size(), m.normals.size(), m.texcoords.size()});
    };
    std::uint64_t n = attributes(*this);
    for (const auto& mesh : meshes) n = add_saturated(n, attributes(*mesh));
    return n;
}

void Scene::clear() {
    clear_triangles();
    materials.assign(1, Material{"(default)"});
    objects.assign(1, "(default)");
    camera.reset();
    polyline_points.clear();
    polylines.clear();
    meshes.clear();
    instances.clear();
}

Scene flatten_instances(const Scene& scene) {
    Scene out = scene;
    out.meshes.clear();
    out.instances.clear();
    const bool colours = scene.has_colours();
    if (colours && out.colours.empty()) out.colours.assign(out.positions.size(), Vec3f(1.0f));
    for (const Instance& instance : scene.instances) {
        const TriangleMesh& mesh = *scene.meshes[instance.mesh];
        const auto base = static_cast<std::uint32_t>(out.positions.size());
        const auto normal_base = static_cast<std::uint32_t>(out.normals.size());
        const auto texcoord_base = static_cast<std::uint32_t>(out.texcoords.size());
        for (const Vec3f& p : mesh.positions) out.positions.push_back(instance.to_world.point(p));
        for (const Vec3f& n : mesh.normals) out.normals.push_back(instance.to_world.unit_normal(n));
        out.texcoords.insert(out.texcoords.end(), mesh.texcoords.begin(), mesh.texcoords.end());
        if (colours) {
            if (mesh.colours.empty()) out.colours.resize(out.positions.size(), Vec3f(1.0f));
            else out.colours.insert(out.colours.end(), mesh.colours.begin(), mesh.colours.end());
        }
        auto shift = [](std::array<std::uint32_t, 3> t, std::uint32_t by) {
            for (std::uint32_t& i : t)
                if (i != kNoIndex) i += by;
            return t;
        };
        for (std::size_t t = 0; t < mesh.triangle_count(); ++t)
            out.add_triangle(shift(mesh.tri_positions[t], base), mesh.tri_material[t],
                             instance.object, shift(mesh.tri_normals[t], normal_base),
                             shift(mesh.tri_texcoords[t], texcoord_base));
    }
    return out;
}

std::uint64_t scene_bytes(std::uint64_t vertices, std::uint64_t triangles,
                          std::uint64_t instances) {
    // Per vertex: the position and, at worst, a normal and a texture coordinate. Per triangle:
    // 5 index arrays (44 bytes), the BVH build (boxes, centres, indices, nodes: ~100 bytes),
    // the packed triangles (36 bytes) and the corner list the automatic camera gathers (36
    // bytes). Measured: a 2M-triangle, 1M-vertex grid peaks at 431 MB including its 55 MB of
    // text; this estimates 518 MB. Per instance: the scene's record (112 bytes), its object
    // name (48), the accelerator's record and its share of the top level (about 200,
    // kBytesPerInstance in accel/triangle_accel.h) and the top level's build (100): 512.
    return add_saturated(add_saturated(mul_saturated(vertices, 12 + 12 + 8),
                                       mul_saturated(triangles, 44 + 100 + 36 + 36)),
                         mul_saturated(instances, 512));
}

std::uint64_t scene_bytes(const Scene& scene) {
    return scene_bytes(scene.stored_vertex_count(), scene.stored_triangle_count(),
                       scene.instances.size());
}

}  // namespace toonray
