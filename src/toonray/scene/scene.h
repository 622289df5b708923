#pragma once
/// A triangle scene as loaded from OBJ/MTL or built in code.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

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

/// Triangles with per-corner indices into shared attribute arrays. Material 0 is always the
/// default material and object 0 the default object, so every triangle has both.
struct Scene {
    std::vector<Vec3f> positions;
    std::vector<Vec3f> normals;
    std::vector<Vec2f> texcoords;
    /// Vertex colours by position index (glTF COLOR_0), multiplying Kd; empty when the scene
    /// has none, else as long as `positions`.
    std::vector<Vec3f> colours;

    std::vector<std::array<std::uint32_t, 3>> tri_positions;
    std::vector<std::array<std::uint32_t, 3>> tri_normals;    ///< kNoIndex where a corner has none
    std::vector<std::array<std::uint32_t, 3>> tri_texcoords;  ///< kNoIndex where a corner has none
    std::vector<std::uint32_t> tri_material;
    std::vector<std::uint32_t> tri_object;

    std::vector<Material> materials{Material{"(default)"}};
    std::vector<std::string> objects{"(default)"};

    std::optional<CameraSpec> camera;  ///< from the OBJ camera block, if any

    std::vector<std::uint32_t> polyline_points;  ///< position indices of all polylines
    std::vector<Polyline> polylines;

    [[nodiscard]] std::size_t triangle_count() const { return tri_positions.size(); }
    /// Bounds of the vertices that triangles use (camera vertices do not count).
    [[nodiscard]] BBox bounds() const;

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
    void clear();
};

/// Memory for a scene of `vertices` attribute values and `triangles` triangles while it is
/// rendered, saturating at the largest value: its arrays, and what rendering builds from it
/// (the BVH build, the packed triangles and the automatic camera's corner list). Deliberately
/// generous, as the estimates of core/limits.h are.
[[nodiscard]] std::uint64_t scene_bytes(std::uint64_t vertices, std::uint64_t triangles);

}  // namespace toonray
