#include "toonray/scene/gltf_animation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fmt/format.h>

namespace toonray {
namespace {

// Column-major 4x4 in double: world matrices chain many nodes.
struct Mat4 {
    std::array<double, 16> m{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

    double& at(int row, int col) { return m[static_cast<std::size_t>(col * 4 + row)]; }
    [[nodiscard]] double at(int row, int col) const {
        return m[static_cast<std::size_t>(col * 4 + row)];
    }

    static Mat4 from(const GltfMatrix& g) {
        Mat4 r;
        for (std::size_t i = 0; i < 16; ++i) r.m[i] = g[i];
        return r;
    }
    friend Mat4 operator*(const Mat4& a, const Mat4& b) {
        Mat4 r;
        for (int row = 0; row < 4; ++row)
            for (int col = 0; col < 4; ++col) {
                double s = 0;
                for (int k = 0; k < 4; ++k) s += a.at(row, k) * b.at(k, col);
                r.at(row, col) = s;
            }
        return r;
    }
    [[nodiscard]] Vec3f point(const Vec3f& p) const {
        return {static_cast<float>(at(0, 0) * p.x + at(0, 1) * p.y + at(0, 2) * p.z + at(0, 3)),
                static_cast<float>(at(1, 0) * p.x + at(1, 1) * p.y + at(1, 2) * p.z + at(1, 3)),
                static_cast<float>(at(2, 0) * p.x + at(2, 1) * p.y + at(2, 2) * p.z + at(2, 3))};
    }
    [[nodiscard]] Vec3f direction(const Vec3f& d) const {
        return {static_cast<float>(at(0, 0) * d.x + at(0, 1) * d.y + at(0, 2) * d.z),
                static_cast<float>(at(1, 0) * d.x + at(1, 1) * d.y + at(1, 2) * d.z),
                static_cast<float>(at(2, 0) * d.x + at(2, 1) * d.y + at(2, 2) * d.z)};
    }
    // A normal: by the cofactor matrix of the upper 3x3 (the inverse transpose times the
    // determinant), which also works for singular matrices; the caller normalises.
    [[nodiscard]] Vec3f normal(const Vec3f& n) const {
        auto c = [&](int r, int k) { return at(r, k); };
        double cof[3][3];
        for (int r = 0; r < 3; ++r)
            for (int k = 0; k < 3; ++k) {
                const int r1 = (r + 1) % 3, r2 = (r + 2) % 3, k1 = (k + 1) % 3, k2 = (k + 2) % 3;
                cof[r][k] = c(r1, k1) * c(r2, k2) - c(r1, k2) * c(r2, k1);
            }
        return {static_cast<float>(cof[0][0] * n.x + cof[0][1] * n.y + cof[0][2] * n.z),
                static_cast<float>(cof[1][0] * n.x + cof[1][1] * n.y + cof[1][2] * n.z),
                static_cast<float>(cof[2][0] * n.x + cof[2][1] * n.y + cof[2][2] * n.z)};
    }
};

Mat4 trs(const Vec3f& t, GltfQuat q, const Vec3f& s) {
    const double len =
        std::sqrt(double(q.x) * q.x + double(q.y) * q.y + double(q.z) * q.z + double(q.w) * q.w);
    double x = 0, y = 0, z = 0, w = 1;
    if (len > 0 && std::isfinite(len)) x = q.x / len, y = q.y / len, z = q.z / len, w = q.w / len;
    Mat4 r;
    r.at(0, 0) = (1 - 2 * (y * y + z * z)) * s.x;
    r.at(1, 0) = 2 * (x * y + z * w) * s.x;
    r.at(2, 0) = 2 * (x * z - y * w) * s.x;
    r.at(0, 1) = 2 * (x * y - z * w) * s.y;
    r.at(1, 1) = (1 - 2 * (x * x + z * z)) * s.y;
    r.at(2, 1) = 2 * (y * z + x * w) * s.y;
    r.at(0, 2) = 2 * (x * z + y * w) * s.z;
    r.at(1, 2) = 2 * (y * z - x * w) * s.z;
    r.at(2, 2) = (1 - 2 * (x * x + y * y)) * s.z;
    r.at(0, 3) = t.x;
    r.at(1, 3) = t.y;
    r.at(2, 3) = t.z;
    return r;
}

// Spherical interpolation along the shorter arc.
std::array<float, 4> slerp(std::array<float, 4> a, std::array<float, 4> b, double s) {
    double d =
        double(a[0]) * b[0] + double(a[1]) * b[1] + double(a[2]) * b[2] + double(a[3]) * b[3];
    if (d < 0) {
        for (float& v : b) v = -v;
        d = -d;
    }
    double wa = 1 - s, wb = s;
    if (d < 0.9995) {
        const double theta = std::acos(std::min(d, 1.0));
        const double sin_theta = std::sin(theta);
        wa = std::sin((1 - s) * theta) / sin_theta;
        wb = std::sin(s * theta) / sin_theta;
    }
    std::array<float, 4> r;
    for (std::size_t i = 0; i < 4; ++i) r[i] = static_cast<float>(wa * a[i] + wb * b[i]);
    return r;
}

// A sampler's value at t into `out` (sampler.width floats).
void sample(const GltfSampler& s, double t, bool rotation, std::vector<float>& out) {
    const std::size_t w = static_cast<std::size_t>(s.width);
    const std::size_t keys = s.times.size();
    const bool cubic = s.interpolation == GltfInterpolation::CubicSpline;
    const std::size_t stride = cubic ? 3 * w : w;
    const std::size_t value_offset = cubic ? w : 0;  // in-tangent, value, out-tangent
    out.resize(w);
    auto value = [&](std::size_t k, std::size_t i) {
        return s.values[k * stride + value_offset + i];
    };
    if (t <= s.times.front() || keys == 1) {
        for (std::size_t i = 0; i < w; ++i) out[i] = value(0, i);
        return;
    }
    if (t >= s.times.back()) {
        for (std::size_t i = 0; i < w; ++i) out[i] = value(keys - 1, i);
        return;
    }
    const auto next = std::upper_bound(s.times.begin(), s.times.end(), static_cast<float>(t));
    const std::size_t k1 = static_cast<std::size_t>(next - s.times.begin());
    const std::size_t k0 = k1 - 1;
    const double t0 = s.times[k0], t1 = s.times[k1];
    const double dt = t1 - t0;
    const double u = dt > 0 ? std::clamp((t - t0) / dt, 0.0, 1.0) : 0.0;
    switch (s.interpolation) {
        case GltfInterpolation::Step:
            for (std::size_t i = 0; i < w; ++i) out[i] = value(k0, i);
            return;
        case GltfInterpolation::Linear:
            if (rotation) {
                auto r = slerp({value(k0, 0), value(k0, 1), value(k0, 2), value(k0, 3)},
                               {value(k1, 0), value(k1, 1), value(k1, 2), value(k1, 3)}, u);
                std::copy(r.begin(), r.end(), out.begin());
            } else {
                for (std::size_t i = 0; i < w; ++i)
                    out[i] = static_cast<float>((1 - u) * value(k0, i) + u * value(k1, i));
            }
            return;
        case GltfInterpolation::CubicSpline: {
            const double u2 = u * u, u3 = u2 * u;
            const double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u;
            const double h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
            for (std::size_t i = 0; i < w; ++i) {
                const double out_tangent = s.values[k0 * stride + 2 * w + i];
                const double in_tangent = s.values[k1 * stride + i];
                out[i] = static_cast<float>(h00 * value(k0, i) + h10 * dt * out_tangent +
                                            h01 * value(k1, i) + h11 * dt * in_tangent);
            }
            return;
        }
    }
}

std::string node_label(const GltfDocument& doc, int index) {
    const GltfNode& node = doc.nodes[static_cast<std::size_t>(index)];
    if (!node.name.empty()) return node.name;
    if (node.mesh >= 0 && !doc.meshes[static_cast<std::size_t>(node.mesh)].name.empty())
        return doc.meshes[static_cast<std::size_t>(node.mesh)].name;
    return fmt::format("node{}", index);
}

// The scene's nodes, parents before children, depth first in file order.
std::vector<int> scene_order(const GltfDocument& doc) {
    std::vector<int> order, stack(doc.roots.rbegin(), doc.roots.rend());
    while (!stack.empty()) {
        const int n = stack.back();
        stack.pop_back();
        order.push_back(n);
        const auto& children = doc.nodes[static_cast<std::size_t>(n)].children;
        stack.insert(stack.end(), children.rbegin(), children.rend());
    }
    return order;
}

// A primitive's positions and normals morphed by `weights` (one per target; fewer: the rest
// are zero), into `positions` and `normals`.
void morph(const GltfPrimitive& prim, const std::vector<float>& weights,
           std::vector<Vec3f>& positions, std::vector<Vec3f>& normals) {
    positions = prim.positions;
    normals = prim.normals;
    for (std::size_t t = 0; t < prim.targets.size() && t < weights.size(); ++t) {
        if (weights[t] == 0.0f) continue;
        const GltfMorphTarget& target = prim.targets[t];
        for (std::size_t v = 0; v < target.positions.size(); ++v)
            positions[v] += target.positions[v] * weights[t];
        for (std::size_t v = 0; v < target.normals.size() && v < normals.size(); ++v)
            normals[v] += target.normals[v] * weights[t];
    }
}

// Appends a primitive's texture coordinates, its colours (white without; only when `colours`)
// and its triangles to `mesh`, whose positions and normals from `base` and `normal_base` on are
// the primitive's.
void add_primitive(const GltfPrimitive& prim, std::uint32_t object, std::uint32_t base,
                   std::uint32_t normal_base, bool colours, TriangleMesh& mesh) {
    const auto texcoord_base = static_cast<std::uint32_t>(mesh.texcoords.size());
    mesh.texcoords.insert(mesh.texcoords.end(), prim.texcoords.begin(), prim.texcoords.end());
    if (colours) {
        if (prim.colours.empty()) mesh.colours.resize(mesh.positions.size(), Vec3f(1.0f));
        else mesh.colours.insert(mesh.colours.end(), prim.colours.begin(), prim.colours.end());
    }
    for (std::size_t k = 0; k + 2 < prim.indices.size(); k += 3) {
        const std::array<std::uint32_t, 3> tri{base + prim.indices[k], base + prim.indices[k + 1],
                                               base + prim.indices[k + 2]};
        std::array<std::uint32_t, 3> nt{kNoIndex, kNoIndex, kNoIndex};
        std::array<std::uint32_t, 3> tt{kNoIndex, kNoIndex, kNoIndex};
        if (!prim.normals.empty())
            for (int c = 0; c < 3; ++c) nt[c] = normal_base + prim.indices[k + c];
        if (!prim.texcoords.empty())
            for (int c = 0; c < 3; ++c) tt[c] = texcoord_base + prim.indices[k + c];
        mesh.add_triangle(tri, prim.material, object, nt, tt);
    }
}

// A glTF mesh's primitives as one mesh in object space, morphed by `weights`, with vertex
// colours when a primitive has them (white for the others, as the flattened scene has them).
std::shared_ptr<const TriangleMesh> object_mesh(const GltfMesh& mesh,
                                                const std::vector<float>& weights) {
    auto out = std::make_shared<TriangleMesh>();
    bool colours = false;
    for (const GltfPrimitive& prim : mesh.primitives) colours = colours || !prim.colours.empty();
    std::vector<Vec3f> positions, normals;
    for (const GltfPrimitive& prim : mesh.primitives) {
        const auto base = static_cast<std::uint32_t>(out->positions.size());
        const auto normal_base = static_cast<std::uint32_t>(out->normals.size());
        morph(prim, weights, positions, normals);
        out->positions.insert(out->positions.end(), positions.begin(), positions.end());
        out->normals.insert(out->normals.end(), normals.begin(), normals.end());
        add_primitive(prim, 0, base, normal_base, colours, *out);
    }
    return out;
}

Affine3 to_affine(const Mat4& m) { return Affine3::from_column_major(m.m); }

}  // namespace

double gltf_frame_time(int frame, double fps) { return static_cast<double>(frame) / fps; }

GltfAnimator::GltfAnimator(GltfDocument document, const GltfPoseOptions& options)
    : doc_(std::move(document)) {
    if (options.animation) {
        const std::string& want = *options.animation;
        int found = -1;
        for (std::size_t i = 0; i < doc_.animations.size(); ++i)
            if (doc_.animations[i].name == want) found = static_cast<int>(i);
        if (found < 0 && !want.empty() && want.size() < 10 &&
            std::all_of(want.begin(), want.end(), [](char c) { return c >= '0' && c <= '9'; })) {
            const int index = std::stoi(want);
            if (static_cast<std::size_t>(index) < doc_.animations.size()) found = index;
        }
        if (found < 0) {
            std::string names;
            for (std::size_t i = 0; i < doc_.animations.size(); ++i)
                names +=
                    fmt::format("{}{} '{}'", names.empty() ? "" : ", ", i, doc_.animations[i].name);
            throw Error(fmt::format("{}: no animation '{}' ({})", doc_.file, want,
                                    names.empty() ? "the file has none" : "it has " + names));
        }
        animations_.push_back(found);
    } else {
        for (std::size_t i = 0; i < doc_.animations.size(); ++i)
            animations_.push_back(static_cast<int>(i));
    }
    meshes_.resize(doc_.meshes.size());
    for (std::size_t m = 0; m < doc_.meshes.size(); ++m)
        if (m < doc_.instanced_meshes.size() && doc_.instanced_meshes[m])
            meshes_[m] = object_mesh(doc_.meshes[m], doc_.meshes[m].weights);
    std::string cameras;
    for (int n : scene_order(doc_)) {
        const GltfNode& node = doc_.nodes[static_cast<std::size_t>(n)];
        if (node.camera < 0) continue;
        const bool perspective = doc_.cameras[static_cast<std::size_t>(node.camera)].yfov > 0;
        if (options.camera_node) {
            cameras += fmt::format("{}'{}'", cameras.empty() ? "" : ", ", node.name);
            if (node.name != *options.camera_node) continue;
            if (!perspective)
                throw Error(fmt::format("{}: nodes[{}] ('{}'): only perspective cameras are read",
                                        doc_.file, n, node.name));
        }
        if (perspective) {
            camera_node_ = n;
            break;
        }
    }
    if (options.camera_node && camera_node_ < 0)
        throw Error(
            fmt::format("{}: no camera node '{}' ({})", doc_.file, *options.camera_node,
                        cameras.empty() ? "the scene has no camera" : "cameras: " + cameras));
}

double GltfAnimator::duration() const {
    double d = 0;
    for (int a : animations_)
        d = std::max(d, double(doc_.animations[static_cast<std::size_t>(a)].duration));
    return d;
}

std::optional<std::string> GltfAnimator::aspect_warning(int width, int height) const {
    if (camera_node_ < 0) return std::nullopt;
    const GltfNode& node = doc_.nodes[static_cast<std::size_t>(camera_node_)];
    const float aspect = doc_.cameras[static_cast<std::size_t>(node.camera)].aspect;
    const double image = static_cast<double>(width) / height;
    if (aspect <= 0 || std::abs(aspect / image - 1.0) < 0.01) return std::nullopt;
    return fmt::format(
        "{}: camera '{}' has aspect ratio {:.4g}, the image {:.4g}: its vertical "
        "field of view is kept and the horizontal one follows the image",
        doc_.file, node.name, aspect, image);
}

void GltfAnimator::pose(double seconds, int width, int height, Scene& scene,
                        std::vector<Light>& lights) const {
    const std::size_t n = doc_.nodes.size();
    // Local transforms and morph weights, with the animations applied.
    std::vector<Vec3f> translation(n), scale(n);
    std::vector<GltfQuat> rotation(n);
    std::vector<bool> animated(n, false);
    std::vector<std::vector<float>> weights(n);
    for (std::size_t i = 0; i < n; ++i) {
        translation[i] = doc_.nodes[i].translation;
        rotation[i] = doc_.nodes[i].rotation;
        scale[i] = doc_.nodes[i].scale;
        weights[i] = doc_.nodes[i].weights;
    }
    std::vector<float> value;
    for (int a : animations_) {
        const GltfAnimation& anim = doc_.animations[static_cast<std::size_t>(a)];
        for (const GltfChannel& ch : anim.channels) {
            const GltfSampler& s = anim.samplers[static_cast<std::size_t>(ch.sampler)];
            const auto node = static_cast<std::size_t>(ch.node);
            sample(s, seconds, ch.path == GltfPath::Rotation, value);
            animated[node] = true;
            switch (ch.path) {
                case GltfPath::Translation:
                    translation[node] = {value[0], value[1], value[2]};
                    break;
                case GltfPath::Rotation:
                    rotation[node] = {value[0], value[1], value[2], value[3]};
                    break;
                case GltfPath::Scale: scale[node] = {value[0], value[1], value[2]}; break;
                case GltfPath::Weights: weights[node] = value; break;
            }
        }
    }
    // World transforms, parents first.
    const std::vector<int> order = scene_order(doc_);
    std::vector<Mat4> world(n);
    for (int i : order) {
        const GltfNode& node = doc_.nodes[static_cast<std::size_t>(i)];
        const auto k = static_cast<std::size_t>(i);
        const Mat4 local = node.matrix && !animated[k] ? Mat4::from(*node.matrix)
                                                       : trs(translation[k], rotation[k], scale[k]);
        world[k] = node.parent >= 0 ? world[static_cast<std::size_t>(node.parent)] * local : local;
    }
    // Joints may sit outside the scene's tree; give those nodes their transforms too.
    std::vector<bool> done(n, false);
    for (int i : order) done[static_cast<std::size_t>(i)] = true;
    std::vector<int> chain;
    for (std::size_t i = 0; i < n; ++i) {
        chain.clear();
        for (int p = static_cast<int>(i); p >= 0 && !done[static_cast<std::size_t>(p)];
             p = doc_.nodes[static_cast<std::size_t>(p)].parent)
            chain.push_back(p);
        for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
            const auto k = static_cast<std::size_t>(*it);
            const GltfNode& node = doc_.nodes[k];
            const Mat4 local = node.matrix && !animated[k]
                                   ? Mat4::from(*node.matrix)
                                   : trs(translation[k], rotation[k], scale[k]);
            world[k] =
                node.parent >= 0 ? world[static_cast<std::size_t>(node.parent)] * local : local;
            done[k] = true;
        }
    }

    scene.clear();
    scene.materials = doc_.materials;
    bool any_colours = false;
    for (int i : order) {
        const GltfNode& node = doc_.nodes[static_cast<std::size_t>(i)];
        if (node.mesh >= 0)
            for (const auto& prim : doc_.meshes[static_cast<std::size_t>(node.mesh)].primitives)
                any_colours = any_colours || !prim.colours.empty();
    }
    std::vector<Vec3f> positions, normals;
    std::vector<Mat4> joint_matrices;
    // Instanced meshes get their scene index when first placed.
    std::vector<std::uint32_t> scene_mesh(doc_.meshes.size(), kNoIndex);
    auto place = [&](std::uint32_t mesh_index, const Mat4& m, std::string name) {
        const Affine3 to_world = to_affine(m);
        // A node scaled to nothing (a common way to hide one) has no inverse and no area: it
        // is left out, as its flattened triangles would be hit by no ray.
        if (!to_world.invertible()) return;
        scene.add_instance(mesh_index, to_world, std::move(name));
    };
    for (int i : order) {
        const GltfNode& node = doc_.nodes[static_cast<std::size_t>(i)];
        if (node.mesh < 0) continue;
        const GltfMesh& mesh = doc_.meshes[static_cast<std::size_t>(node.mesh)];
        const std::shared_ptr<const TriangleMesh>& shared =
            meshes_[static_cast<std::size_t>(node.mesh)];
        const std::size_t gpu = node.gpu_instances.count;
        if (shared || gpu > 0) {
            std::uint32_t index;
            if (shared) {
                std::uint32_t& known = scene_mesh[static_cast<std::size_t>(node.mesh)];
                if (known == kNoIndex) known = scene.add_mesh(shared);
                index = known;
            } else {
                // A morphed mesh placed by EXT_mesh_gpu_instancing: this node's pose of it.
                const std::vector<float>& w = weights[static_cast<std::size_t>(i)].empty()
                                                  ? mesh.weights
                                                  : weights[static_cast<std::size_t>(i)];
                index = scene.add_mesh(object_mesh(mesh, w));
            }
            const Mat4& node_world = world[static_cast<std::size_t>(i)];
            if (gpu == 0) {
                place(index, node_world, node_label(doc_, i));
                continue;
            }
            const GltfGpuInstances& g = node.gpu_instances;
            for (std::size_t k = 0; k < gpu; ++k) {
                const Mat4 local = trs(g.translation.empty() ? Vec3f(0.0f) : g.translation[k],
                                       g.rotation.empty() ? GltfQuat{} : g.rotation[k],
                                       g.scale.empty() ? Vec3f(1.0f) : g.scale[k]);
                place(index, node_world * local, fmt::format("{}.{}", node_label(doc_, i), k));
            }
            continue;
        }
        const auto object = static_cast<std::uint32_t>(scene.objects.size());
        scene.objects.push_back(node_label(doc_, i));
        // The loader checked that a node's weights, given or animated, match its mesh's.
        const std::vector<float>& w = weights[static_cast<std::size_t>(i)].empty()
                                          ? mesh.weights
                                          : weights[static_cast<std::size_t>(i)];
        const GltfSkin* skin =
            node.skin >= 0 ? &doc_.skins[static_cast<std::size_t>(node.skin)] : nullptr;
        if (skin) {
            joint_matrices.resize(skin->joints.size());
            for (std::size_t j = 0; j < skin->joints.size(); ++j)
                joint_matrices[j] = world[static_cast<std::size_t>(skin->joints[j])] *
                                    Mat4::from(skin->inverse_bind[j]);
        }
        const Mat4& node_world = world[static_cast<std::size_t>(i)];
        for (const GltfPrimitive& prim : mesh.primitives) {
            morph(prim, w, positions, normals);
            const auto base = static_cast<std::uint32_t>(scene.positions.size());
            const auto normal_base = static_cast<std::uint32_t>(scene.normals.size());
            const bool skinned = skin && !prim.joints.empty();
            for (std::size_t v = 0; v < positions.size(); ++v) {
                Mat4 blended;
                const Mat4* m = &node_world;
                if (skinned) {
                    const auto& joints = prim.joints[v];
                    const auto& jw = prim.weights[v];
                    double sum = double(jw[0]) + jw[1] + jw[2] + jw[3];
                    if (sum > 0) {
                        blended.m.fill(0.0);
                        for (std::size_t k = 0; k < 4; ++k)
                            if (jw[k] != 0.0f)
                                for (std::size_t e = 0; e < 16; ++e)
                                    blended.m[e] += jw[k] / sum * joint_matrices[joints[k]].m[e];
                        m = &blended;
                    }
                }
                const Vec3f p = m->point(positions[v]);
                scene.positions.push_back(is_finite(p) ? p : Vec3f(0.0f));
                if (!normals.empty()) {
                    Vec3f nn = m->normal(normals[v]);
                    const float len = length(nn);
                    scene.normals.push_back(len > 0 && std::isfinite(len) ? nn / len : Vec3f(0.0f));
                }
            }
            add_primitive(prim, object, base, normal_base, any_colours, scene);
        }
    }

    // The camera.
    if (camera_node_ >= 0) {
        const Mat4& m = world[static_cast<std::size_t>(camera_node_)];
        const GltfCamera& cam = doc_.cameras[static_cast<std::size_t>(
            doc_.nodes[static_cast<std::size_t>(camera_node_)].camera)];
        const Vec3f eye = m.point(Vec3f(0.0f));
        Vec3f forward = m.direction({0, 0, -1});
        Vec3f up = m.direction({0, 1, 0});
        const float fl = length(forward);
        if (fl > 0 && std::isfinite(fl)) {
            forward = forward / fl;
            up = up - forward * dot(up, forward);
            const float ul = length(up);
            if (ul > 0 && std::isfinite(ul)) up = up / ul;
            // Keep the vertical field of view; the horizontal one follows the image.
            const double tan_x = std::tan(cam.yfov / 2.0) * width / height;
            scene.camera = CameraSpec{eye, eye + forward * static_cast<float>(1.0 / tan_x), up};
        }
    }

    // Lights: toon intensity relative to the file's strongest light.
    lights.clear();
    float strongest = 0.0f;
    for (const GltfLight& l : doc_.lights) strongest = std::max(strongest, l.intensity);
    for (int i : order) {
        const GltfNode& node = doc_.nodes[static_cast<std::size_t>(i)];
        if (node.light < 0) continue;
        const GltfLight& l = doc_.lights[static_cast<std::size_t>(node.light)];
        const Mat4& m = world[static_cast<std::size_t>(i)];
        Light light;
        light.intensity = strongest > 0 ? l.intensity / strongest : 0.0f;
        if (l.kind == GltfLight::Kind::Directional) {
            light.kind = Light::Kind::Directional;
            light.vector = m.direction({0, 0, -1});
            const float len = length(light.vector);
            if (!(len > 0) || !std::isfinite(len)) continue;
            light.vector = light.vector / len;
        } else {
            light.kind = Light::Kind::Point;
            light.vector = m.point(Vec3f(0.0f));
            if (!is_finite(light.vector)) continue;
        }
        lights.push_back(light);
    }
}

GltfSource::GltfSource(GltfDocument document, const GltfPoseOptions& options, double fps,
                       SceneSetup setup)
    : animator_(std::move(document), options), fps_(fps), setup_(std::move(setup)) {}

void GltfSource::load(int frame, SceneFrame& out, Warnings&) const {
    load_at(gltf_frame_time(frame, fps_), out);
}

void GltfSource::load_at(double seconds, SceneFrame& out) const {
    std::vector<Light> lights;
    animator_.pose(seconds, setup_.width, setup_.height, out.scene, lights);
    finish_scene(out, std::move(lights), setup_);
}

void GltfSource::hold_automatic_camera(double seconds) {
    if (setup_.camera || animator_.has_camera()) return;
    SceneFrame first;
    load_at(seconds, first);
    setup_.camera = first.camera;
}

}  // namespace toonray
