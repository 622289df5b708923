#include "toonray/scene/scene_arrays.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "toonray/core/error.h"
#include "toonray/core/index.h"

namespace toonray {

namespace {

// How many entries an attribute may have: none, one per position, or one per corner.
void check_count(std::size_t count, const MeshArrays& mesh, std::string_view what,
                 std::string_view name) {
    if (count == 0 || count == mesh.positions.size() || count == 3 * mesh.triangles.size()) return;
    throw Error(
        fmt::format("mesh '{}': {} {}: expected none, one per position ({}) or one per "
                    "triangle corner ({})",
                    name, count, what, mesh.positions.size(), 3 * mesh.triangles.size()));
}

std::uint32_t checked_index(std::size_t value, std::string_view what) {
    if (value > kMaxIndexable)
        throw LimitError(
            Limit::Triangles,
            fmt::format("the scene needs more than {} {} (32-bit indices)", kMaxIndexable, what));
    return static_cast<std::uint32_t>(value);
}

}  // namespace

void check_mesh(const MeshArrays& mesh, std::size_t material_count, std::string_view name) {
    for (std::size_t i = 0; i < mesh.positions.size(); ++i)
        if (!is_finite(mesh.positions[i]))
            throw Error(fmt::format("mesh '{}': position {} is not finite", name, i));
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
        for (std::uint32_t v : mesh.triangles[t])
            if (v >= mesh.positions.size())
                throw Error(fmt::format("mesh '{}': triangle {} uses position {}, but there are {}",
                                        name, t, v, mesh.positions.size()));
    check_count(mesh.normals.size(), mesh, "normals", name);
    check_count(mesh.uvs.size(), mesh, "uvs", name);
    for (std::size_t i = 0; i < mesh.normals.size(); ++i)
        if (!is_finite(mesh.normals[i]))
            throw Error(fmt::format("mesh '{}': normal {} is not finite", name, i));
    for (std::size_t i = 0; i < mesh.uvs.size(); ++i)
        if (!std::isfinite(mesh.uvs[i].x) || !std::isfinite(mesh.uvs[i].y))
            throw Error(fmt::format("mesh '{}': uv {} is not finite", name, i));
    if (!mesh.materials.empty() && mesh.materials.size() != mesh.triangles.size())
        throw Error(fmt::format("mesh '{}': {} material ids for {} triangles (one per triangle)",
                                name, mesh.materials.size(), mesh.triangles.size()));
    for (std::size_t t = 0; t < mesh.materials.size(); ++t)
        if (mesh.materials[t] >= material_count)
            throw Error(fmt::format("mesh '{}': triangle {} has material {}, but the scene has {}",
                                    name, t, mesh.materials[t], material_count));
}

std::uint32_t append_mesh(Scene& scene, const MeshArrays& mesh, const Affine3& to_world,
                          std::string name) {
    check_mesh(mesh, scene.materials.size(), name);
    const auto& m = to_world.m;
    for (const auto& row : m)
        for (double v : row)
            if (!std::isfinite(v))
                throw Error(fmt::format("mesh '{}': the transform is not finite", name));
    // The 3x3 part, its determinant and the inverse transpose (cofactors / det) for normals.
    const double a = m[0][0], b = m[0][1], c = m[0][2], d = m[1][0], e = m[1][1], f = m[1][2],
                 g = m[2][0], h = m[2][1], i = m[2][2];
    const double cof[3][3] = {{e * i - f * h, f * g - d * i, d * h - e * g},
                              {c * h - b * i, a * i - c * g, b * g - a * h},
                              {b * f - c * e, c * d - a * f, a * e - b * d}};
    const double det = a * cof[0][0] + b * cof[0][1] + c * cof[0][2];
    if (!(std::abs(det) > 0.0) || !std::isfinite(det))
        throw Error(
            fmt::format("mesh '{}': the transform is singular (determinant {:g})", name, det));
    const bool mirrored = det < 0.0;

    const std::uint32_t object = checked_index(scene.objects.size(), "objects");
    const std::uint32_t first_position = checked_index(scene.positions.size(), "positions");
    const std::uint32_t first_normal = checked_index(scene.normals.size(), "normals");
    const std::uint32_t first_uv = checked_index(scene.texcoords.size(), "texture coordinates");
    (void)checked_index(scene.positions.size() + mesh.positions.size(), "positions");
    (void)checked_index(scene.normals.size() + mesh.normals.size(), "normals");
    (void)checked_index(scene.texcoords.size() + mesh.uvs.size(), "texture coordinates");
    (void)checked_index(scene.triangle_count() + mesh.triangles.size(), "triangles");

    scene.objects.push_back(std::move(name));
    scene.positions.reserve(scene.positions.size() + mesh.positions.size());
    for (const Vec3f& p : mesh.positions) scene.positions.push_back(to_world.point(p));
    // Zero normals (degenerate faces) have no direction: their triangles take the face's.
    std::vector<char> zero_normal(mesh.normals.size(), 0);
    scene.normals.reserve(scene.normals.size() + mesh.normals.size());
    for (std::size_t k = 0; k < mesh.normals.size(); ++k) {
        const Vec3f& n = mesh.normals[k];
        double out[3];
        for (int r = 0; r < 3; ++r)
            out[r] = (cof[r][0] * n.x + cof[r][1] * n.y + cof[r][2] * n.z) / det;
        const double len = std::sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2]);
        if (!(len > 0.0) || !std::isfinite(len)) {
            zero_normal[k] = 1;
            scene.normals.emplace_back(0.0f, 0.0f, 0.0f);
            continue;
        }
        scene.normals.emplace_back(static_cast<float>(out[0] / len),
                                   static_cast<float>(out[1] / len),
                                   static_cast<float>(out[2] / len));
    }
    scene.texcoords.insert(scene.texcoords.end(), mesh.uvs.begin(), mesh.uvs.end());

    const bool normals_per_corner =
        !mesh.normals.empty() && mesh.normals.size() != mesh.positions.size();
    const bool uvs_per_corner = !mesh.uvs.empty() && mesh.uvs.size() != mesh.positions.size();
    scene.tri_positions.reserve(scene.triangle_count() + mesh.triangles.size());
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        const auto& tri = mesh.triangles[t];
        // Corner order: reversed for a mirroring transform.
        const int order[3] = {0, mirrored ? 2 : 1, mirrored ? 1 : 2};
        std::array<std::uint32_t, 3> p{}, n{kNoIndex, kNoIndex, kNoIndex},
            uv{kNoIndex, kNoIndex, kNoIndex};
        bool has_zero_normal = false;
        for (int k = 0; k < 3; ++k) {
            const std::size_t corner = 3 * t + static_cast<std::size_t>(order[k]);
            const std::uint32_t v = tri[static_cast<std::size_t>(order[k])];
            p[k] = first_position + v;
            if (!mesh.normals.empty()) {
                const std::size_t source = normals_per_corner ? corner : v;
                has_zero_normal = has_zero_normal || zero_normal[source] != 0;
                n[k] = first_normal + static_cast<std::uint32_t>(source);
            }
            if (!mesh.uvs.empty())
                uv[k] = first_uv + static_cast<std::uint32_t>(uvs_per_corner ? corner : v);
        }
        if (has_zero_normal) n = {kNoIndex, kNoIndex, kNoIndex};
        scene.add_triangle(p, mesh.materials.empty() ? 0 : mesh.materials[t], object, n, uv);
    }
    return object;
}

std::shared_ptr<const TriangleMesh> instance_mesh(const MeshArrays& mesh,
                                                  std::size_t material_count,
                                                  std::string_view name) {
    // append_mesh's material check needs the materials to exist; their contents do not matter.
    Scene scene;
    scene.materials.assign(std::max<std::size_t>(material_count, 1), Material{"(default)"});
    append_mesh(scene, mesh, Affine3{}, std::string(name));
    return std::make_shared<const TriangleMesh>(std::move(static_cast<TriangleMesh&>(scene)));
}

void check_scene_limits(const Scene& scene, const Limits& limits) {
    // What is stored: an instanced mesh once, however often it is placed.
    std::uint64_t positions = scene.positions.size();
    for (const auto& mesh : scene.meshes) positions += mesh->positions.size();
    const std::uint64_t triangles = scene.stored_triangle_count();
    if (triangles > limits.max_triangles)
        throw LimitError(Limit::Triangles,
                         fmt::format("the scene has {} triangles, more than the limit of {}",
                                     triangles, limits.max_triangles));
    if (positions > limits.max_vertices)
        throw LimitError(Limit::Vertices,
                         fmt::format("the scene has {} vertex positions, more than the limit of {}",
                                     positions, limits.max_vertices));
}

}  // namespace toonray
