#pragma once
/// glTF 2.0 reading (`.gltf` with external or embedded buffers, `.glb`) through tinygltf, into a
/// document whose every array is checked and decoded: the node hierarchy, triangle meshes with
/// their morph targets and skin weights, materials, perspective cameras, KHR_lights_punctual
/// lights and animations. anim/gltf_animation.h poses it at a time and builds the Scene.
///
/// Every index, accessor and buffer view is checked here before use (tinygltf does not check
/// them all); a bad file is an Error naming the file and the JSON path
/// ("scene.gltf: accessors[3].count: 4294967295 exceeds the buffer view").

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/core/image.h"
#include "toonray/core/limits.h"
#include "toonray/core/math.h"
#include "toonray/scene/scene.h"

namespace toonray {

/// A unit quaternion (x, y, z, w), as glTF stores rotations.
struct GltfQuat {
    float x = 0, y = 0, z = 0, w = 1;
};

/// A column-major 4x4 matrix, as glTF stores them.
using GltfMatrix = std::array<float, 16>;

/// EXT_mesh_gpu_instancing: the node's mesh is drawn once per entry, placed by the node's world
/// transform times the entry's translation, rotation and scale (an attribute the file leaves
/// out is the identity).
struct GltfGpuInstances {
    std::size_t count = 0;           ///< 0: the node is not instanced this way
    std::vector<Vec3f> translation;  ///< empty or `count` long
    std::vector<GltfQuat> rotation;
    std::vector<Vec3f> scale;
};

struct GltfNode {
    std::string name;
    int mesh = -1, camera = -1, skin = -1, light = -1;  ///< -1: none
    int parent = -1;
    std::vector<int> children;
    Vec3f translation{0.0f};
    GltfQuat rotation;
    Vec3f scale{1.0f};
    std::optional<GltfMatrix> matrix;  ///< replaces translation, rotation and scale when given
    std::vector<float> weights;        ///< one per morph target of the mesh; empty: the mesh's
    GltfGpuInstances gpu_instances;
};

/// One morph target's displacements (an empty array: that attribute does not move).
struct GltfMorphTarget {
    std::vector<Vec3f> positions, normals;
};

/// A triangle primitive, decoded: attributes per vertex and three indices per triangle.
struct GltfPrimitive {
    std::vector<Vec3f> positions;
    std::vector<Vec3f> normals;    ///< empty: none
    std::vector<Vec2f> texcoords;  ///< TEXCOORD_0 with v flipped to OBJ's (v = 0 at the bottom)
    std::vector<Vec3f> colours;    ///< COLOR_0 (alpha dropped); empty: none
    std::vector<std::array<std::uint32_t, 4>> joints;  ///< JOINTS_0; empty: not skinned
    std::vector<std::array<float, 4>> weights;         ///< WEIGHTS_0
    std::vector<std::uint32_t> indices;                ///< 3 per triangle, each < positions.size()
    std::vector<GltfMorphTarget> targets;
    std::uint32_t material = 0;  ///< index into GltfDocument::materials (0 = the default)
};

struct GltfMesh {
    std::string name;
    std::vector<GltfPrimitive> primitives;
    std::vector<float> weights;  ///< default morph weights, one per target
};

struct GltfSkin {
    std::vector<int> joints;               ///< node indices
    std::vector<GltfMatrix> inverse_bind;  ///< one per joint
};

/// A perspective camera.
struct GltfCamera {
    std::string name;
    float yfov = 0.8f;    ///< vertical field of view, radians
    float aspect = 0.0f;  ///< width / height the file asks for; 0 when it does not say
};

/// A KHR_lights_punctual light, as the file gives it.
struct GltfLight {
    enum class Kind { Point, Directional, Spot };
    std::string name;
    Kind kind = Kind::Point;
    Vec3f colour{1.0f};
    float intensity = 1.0f;  ///< candela (point, spot) or lux (directional)
};

enum class GltfInterpolation { Linear, Step, CubicSpline };
enum class GltfPath { Translation, Rotation, Scale, Weights };

struct GltfSampler {
    std::vector<float> times;   ///< increasing
    std::vector<float> values;  ///< per key `width` floats (three times that for CUBICSPLINE)
    int width = 3;              ///< floats per value: 3, 4, or the morph target count
    GltfInterpolation interpolation = GltfInterpolation::Linear;
};

struct GltfChannel {
    int node = 0;
    GltfPath path = GltfPath::Translation;
    int sampler = 0;
};

struct GltfAnimation {
    std::string name;
    std::vector<GltfSampler> samplers;
    std::vector<GltfChannel> channels;
    float duration = 0.0f;  ///< the last key time of any sampler
};

/// A glTF file, read and checked.
struct GltfDocument {
    std::string file;  ///< as given, for messages
    std::vector<GltfNode> nodes;
    std::vector<int> roots;  ///< the nodes of the scene shown (the default scene, else scene 0)
    std::vector<GltfMesh> meshes;
    std::vector<Material> materials{Material{"(default)"}};  ///< material i of the file is i + 1
    std::vector<GltfSkin> skins;
    std::vector<GltfCamera> cameras;
    std::vector<GltfLight> lights;
    std::vector<GltfAnimation> animations;
    /// Per mesh: posed as instances of one shared mesh (scene/scene.h) rather than flattened
    /// into the scene's triangles: meshes that the scene places more than once (on several
    /// nodes, or by EXT_mesh_gpu_instancing), with no morph targets and no skinned node.
    std::vector<std::uint8_t> instanced_meshes;
    /// Triangles stored: of every flattened node's mesh, and of each instanced mesh once.
    std::uint64_t triangles = 0;
    std::uint64_t vertices = 0;   ///< likewise
    std::uint64_t instances = 0;  ///< instances of instanced meshes (and of morphed GPU meshes)

    /// Whether posing at a time can move vertices relative to each other (skins, animated morph
    /// weights), rather than only move whole meshes.
    [[nodiscard]] bool deforms() const;
};

struct GltfOptions {
    bool load_textures = true;
    /// The input size, triangle and vertex counts, the memory estimate (docs/robustness.md).
    Limits limits = toonray::limits();
};

/// Reads `path`: a GLB when it starts with the GLB magic, else glTF JSON. External buffers and
/// images are read relative to it. Throws Error("file: JSON path: reason"), LimitError past a
/// limit; a texture that is missing or cannot be decoded is a warning (the material keeps its
/// colour), as are primitives that are not triangles and unsupported features.
GltfDocument load_gltf(const std::filesystem::path& path, Warnings& warnings,
                       const GltfOptions& options = {});

/// Reads a glTF or GLB file already in memory; `path` names it and anchors relative URIs.
GltfDocument parse_gltf(std::span<const std::uint8_t> bytes, const std::filesystem::path& path,
                        Warnings& warnings, const GltfOptions& options = {});

/// Whether `path` names a glTF file (by its extension, .gltf or .glb, any case).
[[nodiscard]] bool is_gltf_path(const std::filesystem::path& path);

}  // namespace toonray
