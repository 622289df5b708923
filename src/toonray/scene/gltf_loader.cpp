#include "toonray/scene/gltf_loader.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fmt/format.h>
#include <map>
#include <tiny_gltf.h>
#include <tuple>

#include "toonray/core/saturating.h"
#include "toonray/io/file.h"
#include "toonray/scene/gltf_json_check.h"
#include "toonray/scene/gltf_third_party.h"

namespace toonray {
namespace {

constexpr std::uint32_t kGlbMagic = 0x46546C67;  // "glTF"
constexpr std::uint32_t kGlbJson = 0x4E4F534A;   // "JSON"
constexpr std::uint32_t kGlbBin = 0x004E4942;    // "BIN\0"

std::uint32_t read_u32(const std::uint8_t* p) {
    return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
           static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}

// Checks a GLB's header and chunk table (tinygltf trusts the lengths in them).
void check_glb(std::span<const std::uint8_t> bytes, const std::string& file) {
    auto fail = [&](std::size_t offset, const std::string& what) {
        throw Error(fmt::format("{}: byte {}: {}", file, offset, what));
    };
    if (bytes.size() < 20) fail(bytes.size(), "truncated GLB: the header needs 20 bytes");
    const std::uint32_t version = read_u32(bytes.data() + 4);
    if (version != 2) fail(4, fmt::format("GLB version {}, only version 2 is read", version));
    const std::uint32_t length = read_u32(bytes.data() + 8);
    if (length != bytes.size())
        fail(8, fmt::format("truncated GLB: the header says {} bytes, the file has {}", length,
                            bytes.size()));
    const std::uint64_t json_length = read_u32(bytes.data() + 12);
    if (read_u32(bytes.data() + 16) != kGlbJson) fail(16, "the first chunk is not JSON");
    if (20 + json_length > bytes.size())
        fail(12,
             fmt::format("truncated GLB: the JSON chunk of {} bytes does not fit", json_length));
    std::uint64_t offset = 20 + json_length;
    offset = (offset + 3) & ~std::uint64_t{3};
    if (offset + 8 <= bytes.size()) {
        const std::uint64_t bin_length = read_u32(bytes.data() + offset);
        if (read_u32(bytes.data() + offset + 4) == kGlbBin &&
            offset + 8 + bin_length > bytes.size())
            fail(offset,
                 fmt::format("truncated GLB: the BIN chunk of {} bytes does not fit", bin_length));
    }
}

// What tinygltf's callbacks need: where external files are, the limits, warnings.
struct LoadContext {
    std::uint64_t max_input_bytes = 0;
    std::uint64_t max_image_pixels = 0;
    std::map<int, std::shared_ptr<const ImageRgb8>> images;  // decoded, by image index
    std::map<int, std::string> image_errors;
};

bool file_exists(const std::string& path, void*) {
    std::error_code ec;
    return std::filesystem::is_regular_file(path, ec);
}

// No shell-style expansion of names written in a file.
std::string expand_path(const std::string& path, void*) { return path; }

bool read_whole_file(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                     void* user) {
    const auto* context = static_cast<const LoadContext*>(user);
    try {
        std::string data = read_file(path, context->max_input_bytes);
        out->assign(data.begin(), data.end());
        return true;
    } catch (const Error& e) {
        if (err) *err += e.what();
        return false;
    }
}

bool write_whole_file(std::string* err, const std::string&, const std::vector<unsigned char>&,
                      void*) {
    if (err) *err += "writing is not supported";
    return false;
}

// tinygltf's image callback: decodes embedded images (data URIs, buffer views). A bad image
// is remembered and reported as a warning by the material that uses it.
bool load_image(tinygltf::Image* image, const int index, std::string*, std::string*, int, int,
                const unsigned char* bytes, int size, void* user) {
    auto* context = static_cast<LoadContext*>(user);
    auto decoded = std::make_shared<ImageRgb8>();
    std::string error;
    if (size > 0 && gltf_detail::decode_image(bytes, static_cast<std::size_t>(size),
                                              context->max_image_pixels, *decoded, error)) {
        context->images[index] = std::move(decoded);
    } else {
        context->image_errors[index] = size > 0 ? error : "the image is empty";
    }
    image->image.clear();
    return true;
}

const char* type_name(int type) {
    switch (type) {
        case TINYGLTF_TYPE_SCALAR: return "SCALAR";
        case TINYGLTF_TYPE_VEC2: return "VEC2";
        case TINYGLTF_TYPE_VEC3: return "VEC3";
        case TINYGLTF_TYPE_VEC4: return "VEC4";
        case TINYGLTF_TYPE_MAT2: return "MAT2";
        case TINYGLTF_TYPE_MAT3: return "MAT3";
        case TINYGLTF_TYPE_MAT4: return "MAT4";
        default: return "an unknown type";
    }
}

int component_bytes(int component_type) {
    switch (component_type) {
        case TINYGLTF_COMPONENT_TYPE_BYTE:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
        case TINYGLTF_COMPONENT_TYPE_SHORT:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
        default: return 0;
    }
}

// One component at p, as stored, or normalised to [0, 1] / [-1, 1].
double component_value(const std::uint8_t* p, int component_type, bool normalized) {
    switch (component_type) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: {
            const double v = static_cast<std::int8_t>(p[0]);
            return normalized ? std::max(v / 127.0, -1.0) : v;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? p[0] / 255.0 : p[0];
        case TINYGLTF_COMPONENT_TYPE_SHORT: {
            std::int16_t s;
            std::memcpy(&s, p, 2);
            return normalized ? std::max(s / 32767.0, -1.0) : s;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            std::uint16_t s;
            std::memcpy(&s, p, 2);
            return normalized ? s / 65535.0 : s;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return read_u32(p);
        default: {
            float f;
            std::memcpy(&f, p, 4);
            return f;
        }
    }
}

class DocumentReader {
public:
    DocumentReader(const tinygltf::Model& model, const std::string& file,
                   const std::filesystem::path& base_dir, Warnings& warnings,
                   const GltfOptions& options, LoadContext& context)
        : m_(model),
          file_(file),
          base_dir_(base_dir),
          warnings_(warnings),
          options_(options),
          context_(context) {}

    GltfDocument read() {
        doc_.file = file_;
        check_required_extensions();
        read_nodes();
        read_materials();
        read_meshes();
        check_node_weights();
        read_skins();
        read_cameras();
        read_lights();
        read_animations();
        count_instances();
        return std::move(doc_);
    }

private:
    [[noreturn]] void fail(const std::string& where, const std::string& what) const {
        throw Error(fmt::format("{}: {}: {}", file_, where, what));
    }
    void warn(const std::string& where, const std::string& what) const {
        if (warning_count_++ < 100)
            warnings_.push_back(fmt::format("{}: {}: {}", file_, where, what));
    }

    // Throws unless 0 <= index < size.
    void check_index(int index, std::size_t size, const std::string& where,
                     const char* array) const {
        if (index < 0 || static_cast<std::size_t>(index) >= size)
            fail(where, fmt::format("{} {} does not exist ({} {})", array, index, size, array));
    }

    // Checks an accessor's type and its storage, then hands each value to `sink(element,
    // component, value)`. `types` lists the allowed accessor types; `normalize` maps normalised
    // integers to [0, 1] / [-1, 1] (for float data; indices pass `false`).
    template <typename Sink>
    std::size_t read_accessor(int index, const std::string& where, std::initializer_list<int> types,
                              bool integers_only, Sink&& sink) const {
        check_index(index, m_.accessors.size(), where, "accessors");
        const tinygltf::Accessor& a = m_.accessors[static_cast<std::size_t>(index)];
        const std::string at = fmt::format("accessors[{}]", index);
        if (std::find(types.begin(), types.end(), a.type) == types.end()) {
            std::string expected;
            for (int t : types)
                expected += (expected.empty() ? "" : " or ") + std::string(type_name(t));
            fail(at + ".type", fmt::format("{} where {} is expected (for {})", type_name(a.type),
                                           expected, where));
        }
        const int csize = component_bytes(a.componentType);
        if (csize == 0)
            fail(at + ".componentType", fmt::format("{} is not a component type", a.componentType));
        if (integers_only && (a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT ||
                              a.componentType == TINYGLTF_COMPONENT_TYPE_BYTE ||
                              a.componentType == TINYGLTF_COMPONENT_TYPE_SHORT))
            fail(at + ".componentType",
                 fmt::format("unsigned integers are expected (for {})", where));
        const int comps = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(a.type));
        if (a.count > std::min<std::uint64_t>(kMaxIndexable, options_.limits.max_vertices))
            throw LimitError(
                Limit::Vertices,
                fmt::format("{}: {}.count: {} is more than the limit of {}", file_, at, a.count,
                            std::min<std::uint64_t>(kMaxIndexable, options_.limits.max_vertices)));
        const std::uint64_t element = static_cast<std::uint64_t>(comps) * csize;
        const bool normalized = a.normalized && !integers_only;
        if (a.bufferView >= 0) {
            const std::string view_at = fmt::format("bufferViews[{}]", a.bufferView);
            const auto [data, length, stride_given] = buffer_view(a.bufferView, at + ".bufferView");
            const std::uint64_t stride = stride_given ? stride_given : element;
            if (stride < element || stride % static_cast<std::uint64_t>(csize) != 0)
                fail(view_at + ".byteStride",
                     fmt::format("{} does not fit elements of {} bytes", stride, element));
            if (a.byteOffset > length || a.count > length ||
                (a.count > 0 && a.byteOffset + (a.count - 1) * stride + element > length))
                fail(at + ".count",
                     fmt::format("{} exceeds the buffer view ({} bytes from byte {}, "
                                 "{} apart, in {})",
                                 a.count, element, a.byteOffset, stride, view_at));
            if (a.byteOffset % static_cast<std::uint64_t>(csize) != 0)
                warn(at + ".byteOffset", "not a multiple of the component size");
            for (std::size_t i = 0; i < a.count; ++i) {
                const std::uint8_t* p = data + a.byteOffset + i * stride;
                for (int c = 0; c < comps; ++c)
                    sink(i, c, component_value(p + c * csize, a.componentType, normalized));
            }
        } else {
            if (!a.sparse.isSparse) warn(at, "no bufferView: all values are zero");
            for (std::size_t i = 0; i < a.count; ++i)
                for (int c = 0; c < comps; ++c) sink(i, c, 0.0);
        }
        if (a.sparse.isSparse) read_sparse(a, at, comps, csize, normalized, sink);
        return a.count;
    }

    template <typename Sink>
    void read_sparse(const tinygltf::Accessor& a, const std::string& at, int comps, int csize,
                     bool normalized, Sink& sink) const {
        const auto& s = a.sparse;
        if (s.count < 1 || static_cast<std::size_t>(s.count) > a.count)
            fail(at + ".sparse.count", fmt::format("{} is not within 1..{}", s.count, a.count));
        const std::size_t count = static_cast<std::size_t>(s.count);
        const int isize = component_bytes(s.indices.componentType);
        if (isize == 0 || s.indices.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT ||
            s.indices.componentType == TINYGLTF_COMPONENT_TYPE_BYTE ||
            s.indices.componentType == TINYGLTF_COMPONENT_TYPE_SHORT)
            fail(at + ".sparse.indices.componentType", "unsigned integers are expected");
        const auto [idata, ilength, istride] =
            buffer_view(s.indices.bufferView, at + ".sparse.indices.bufferView");
        const auto [vdata, vlength, vstride] =
            buffer_view(s.values.bufferView, at + ".sparse.values.bufferView");
        const std::uint64_t ioff = static_cast<std::uint64_t>(std::max(0, s.indices.byteOffset));
        const std::uint64_t voff = static_cast<std::uint64_t>(std::max(0, s.values.byteOffset));
        const std::uint64_t element = static_cast<std::uint64_t>(comps) * csize;
        if (ioff > ilength || count * static_cast<std::uint64_t>(isize) > ilength - ioff)
            fail(at + ".sparse.count", fmt::format("{} indices exceed their buffer view", count));
        if (voff > vlength || count * element > vlength - voff)
            fail(at + ".sparse.count", fmt::format("{} values exceed their buffer view", count));
        for (std::size_t k = 0; k < count; ++k) {
            const double target =
                component_value(idata + ioff + k * isize, s.indices.componentType, false);
            if (target >= static_cast<double>(a.count))
                fail(at + ".sparse.indices",
                     fmt::format("index {} at element {} is out of range ({} elements)", target, k,
                                 a.count));
            const std::uint8_t* p = vdata + voff + k * element;
            for (int c = 0; c < comps; ++c)
                sink(static_cast<std::size_t>(target), c,
                     component_value(p + c * csize, a.componentType, normalized));
        }
    }

    struct View {
        const std::uint8_t* data;
        std::uint64_t length;
        std::uint64_t stride;
    };

    // A buffer view's bytes, checked against its buffer.
    View buffer_view(int index, const std::string& where) const {
        check_index(index, m_.bufferViews.size(), where, "bufferViews");
        const tinygltf::BufferView& v = m_.bufferViews[static_cast<std::size_t>(index)];
        const std::string at = fmt::format("bufferViews[{}]", index);
        check_index(v.buffer, m_.buffers.size(), at + ".buffer", "buffers");
        const auto& data = m_.buffers[static_cast<std::size_t>(v.buffer)].data;
        if (v.byteOffset > data.size() || v.byteLength > data.size() - v.byteOffset)
            fail(at + ".byteLength",
                 fmt::format("{} bytes from byte {} exceed buffers[{}] ({} bytes)", v.byteLength,
                             v.byteOffset, v.buffer, data.size()));
        return {data.data() + v.byteOffset, v.byteLength, v.byteStride};
    }

    std::vector<Vec3f> read_vec3(int index, const std::string& where) const {
        std::vector<Vec3f> out;
        const auto& a = accessor_or_fail(index, where);
        out.resize(a.count);
        read_accessor(index, where, {TINYGLTF_TYPE_VEC3}, false,
                      [&](std::size_t i, int c, double v) { out[i][c] = static_cast<float>(v); });
        return out;
    }

    // The accessor, with its count checked against its buffer view and the vertex limit before
    // anything is allocated for it (read_accessor checks the rest).
    const tinygltf::Accessor& accessor_or_fail(int index, const std::string& where) const {
        check_index(index, m_.accessors.size(), where, "accessors");
        const auto& a = m_.accessors[static_cast<std::size_t>(index)];
        if (a.bufferView >= 0) {
            const View view =
                buffer_view(a.bufferView, fmt::format("accessors[{}].bufferView", index));
            if (a.count > view.length)
                fail(fmt::format("accessors[{}].count", index),
                     fmt::format("{} exceeds the buffer view (bufferViews[{}], {} bytes)", a.count,
                                 a.bufferView, view.length));
        }
        const std::uint64_t limit =
            std::min<std::uint64_t>(kMaxIndexable, options_.limits.max_vertices);
        if (a.bufferView < 0 && a.count <= limit)  // zeros (or sparse values), not in the file
            check_memory(add_saturated(options_.limits.reserved_memory, mul_saturated(a.count, 64)),
                         fmt::format("{}: accessors[{}] ({} values without a buffer view)", file_,
                                     index, a.count));
        if (a.count > limit)
            throw LimitError(Limit::Vertices,
                             fmt::format("{}: accessors[{}].count: {} is more than the limit of {}",
                                         file_, index, a.count, limit));
        return a;
    }

    // Normals and morph displacements that are not finite count as zero (a zero normal shades
    // with the geometric one).
    static void zero_non_finite(std::vector<Vec3f>& values) {
        for (auto& v : values)
            if (!is_finite(v)) v = Vec3f(0.0f);
    }

    // Extensions a file needs to be read right. The ones toonray ignores only change what
    // toon shading does not use (PBR material details, texture transforms).
    void check_required_extensions() const {
        for (std::size_t i = 0; i < m_.extensionsRequired.size(); ++i) {
            const std::string& name = m_.extensionsRequired[i];
            const bool known = name == "KHR_lights_punctual" || name == "KHR_mesh_quantization" ||
                               name == "KHR_texture_transform" ||
                               name == "EXT_mesh_gpu_instancing" ||
                               name.rfind("KHR_materials_", 0) == 0;
            if (!known)
                fail(fmt::format("extensionsRequired[{}]", i),
                     fmt::format("{} is not supported", name));
        }
    }

    // EXT_mesh_gpu_instancing's TRANSLATION, ROTATION and SCALE accessors, all of one count.
    void read_gpu_instances(const tinygltf::Value& ext, const std::string& at,
                            const tinygltf::Node& src, GltfNode& node) {
        if (!ext.IsObject() || !ext.Has("attributes") || !ext.Get("attributes").IsObject())
            fail(at, "no attributes object");
        const tinygltf::Value& attributes = ext.Get("attributes");
        GltfGpuInstances& out = node.gpu_instances;
        std::size_t count = 0;
        bool any = false;
        auto read = [&](const char* name, int width, auto&& store) {
            if (!attributes.Has(name)) return;
            const tinygltf::Value& v = attributes.Get(name);
            const std::string where = at + ".attributes." + name;
            if (!v.IsNumber() && !v.IsInt()) fail(where, "not an accessor index");
            const int index = v.GetNumberAsInt();
            const auto& a = accessor_or_fail(index, where);
            if (any && a.count != count)
                fail(where,
                     fmt::format("{} entries where the other attributes have {}", a.count, count));
            count = a.count;
            any = true;
            store(a.count);
            read_accessor(index, where, {width == 4 ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3},
                          false, [&](std::size_t i, int c, double value) {
                              if (!std::isfinite(value) || std::abs(value) > 1e30)
                                  fail(where,
                                       fmt::format("value {} at entry {} is not usable", value, i));
                              store(i, c, static_cast<float>(value));
                          });
        };
        read("TRANSLATION", 3, [&](auto... args) {
            if constexpr (sizeof...(args) == 1) out.translation.resize(args...);
            else {
                auto t = std::make_tuple(args...);
                out.translation[std::get<0>(t)][std::get<1>(t)] = std::get<2>(t);
            }
        });
        read("ROTATION", 4, [&](auto... args) {
            if constexpr (sizeof...(args) == 1) out.rotation.resize(args...);
            else {
                auto t = std::make_tuple(args...);
                GltfQuat& q = out.rotation[std::get<0>(t)];
                const int c = std::get<1>(t);
                (c == 0 ? q.x : c == 1 ? q.y : c == 2 ? q.z : q.w) = std::get<2>(t);
            }
        });
        read("SCALE", 3, [&](auto... args) {
            if constexpr (sizeof...(args) == 1) out.scale.resize(args...);
            else {
                auto t = std::make_tuple(args...);
                out.scale[std::get<0>(t)][std::get<1>(t)] = std::get<2>(t);
            }
        });
        if (!any) fail(at + ".attributes", "none of TRANSLATION, ROTATION and SCALE");
        if (src.mesh == -1) {
            warn(at, "the node has no mesh: ignored");
            out = {};
            return;
        }
        if (src.skin != -1) {
            warn(at, "a skinned node is not instanced: drawn once");
            out = {};
            return;
        }
        out.count = count;
    }

    void read_nodes() {
        const std::size_t n = m_.nodes.size();
        doc_.nodes.resize(n);
        for (std::size_t i = 0; i < n; ++i) {
            const tinygltf::Node& src = m_.nodes[i];
            GltfNode& node = doc_.nodes[i];
            const std::string at = fmt::format("nodes[{}]", i);
            node.name = src.name;
            node.mesh = src.mesh;
            node.camera = src.camera;
            node.skin = src.skin;
            if (src.mesh != -1) check_index(src.mesh, m_.meshes.size(), at + ".mesh", "meshes");
            if (src.camera != -1)
                check_index(src.camera, m_.cameras.size(), at + ".camera", "cameras");
            if (src.skin != -1) check_index(src.skin, m_.skins.size(), at + ".skin", "skins");
            if (auto it = src.extensions.find("KHR_lights_punctual"); it != src.extensions.end()) {
                const tinygltf::Value& ext = it->second;
                if (ext.IsObject() && ext.Has("light") && ext.Get("light").IsNumber()) {
                    node.light = ext.Get("light").GetNumberAsInt();
                    check_index(node.light, m_.lights.size(),
                                at + ".extensions.KHR_lights_punctual.light", "lights");
                } else {
                    fail(at + ".extensions.KHR_lights_punctual", "no light index");
                }
            }
            auto numbers = [&](const std::vector<double>& v, std::size_t size, const char* name) {
                if (!v.empty() && v.size() != size)
                    fail(at + "." + name,
                         fmt::format("{} numbers where {} are expected", v.size(), size));
                for (double d : v)
                    if (!std::isfinite(d) || std::abs(d) > 1e30)
                        fail(at + "." + name, fmt::format("{} is not a usable number", d));
                return !v.empty();
            };
            if (numbers(src.translation, 3, "translation"))
                node.translation = {static_cast<float>(src.translation[0]),
                                    static_cast<float>(src.translation[1]),
                                    static_cast<float>(src.translation[2])};
            if (numbers(src.rotation, 4, "rotation"))
                node.rotation = {
                    static_cast<float>(src.rotation[0]), static_cast<float>(src.rotation[1]),
                    static_cast<float>(src.rotation[2]), static_cast<float>(src.rotation[3])};
            if (numbers(src.scale, 3, "scale"))
                node.scale = {static_cast<float>(src.scale[0]), static_cast<float>(src.scale[1]),
                              static_cast<float>(src.scale[2])};
            if (numbers(src.matrix, 16, "matrix")) {
                GltfMatrix matrix;
                for (int k = 0; k < 16; ++k) matrix[k] = static_cast<float>(src.matrix[k]);
                node.matrix = matrix;
            }
            numbers(src.weights, src.weights.size(), "weights");
            for (double w : src.weights) node.weights.push_back(static_cast<float>(w));
            if (auto it = src.extensions.find("EXT_mesh_gpu_instancing");
                it != src.extensions.end())
                read_gpu_instances(it->second, at + ".extensions.EXT_mesh_gpu_instancing", src,
                                   node);
            for (std::size_t k = 0; k < src.children.size(); ++k) {
                const int child = src.children[k];
                check_index(child, n, fmt::format("{}.children[{}]", at, k), "nodes");
                GltfNode& c = doc_.nodes[static_cast<std::size_t>(child)];
                if (child == static_cast<int>(i))
                    fail(fmt::format("{}.children[{}]", at, k), "a node cannot be its own child");
                if (c.parent != -1)
                    fail(fmt::format("{}.children[{}]", at, k),
                         fmt::format("nodes[{}] is already a child of nodes[{}]", child, c.parent));
                c.parent = static_cast<int>(i);
                node.children.push_back(child);
            }
        }
        // With one parent each, a cycle is a chain of parents that comes back to itself.
        std::vector<std::uint8_t> state(n, 0);  // 0 unknown, 1 being walked, 2 leads to a root
        std::vector<int> path;
        for (std::size_t i = 0; i < n; ++i) {
            int k = static_cast<int>(i);
            path.clear();
            while (k != -1 && state[static_cast<std::size_t>(k)] == 0) {
                state[static_cast<std::size_t>(k)] = 1;
                path.push_back(k);
                k = doc_.nodes[static_cast<std::size_t>(k)].parent;
            }
            if (k != -1 && state[static_cast<std::size_t>(k)] == 1)
                fail(fmt::format("nodes[{}].children",
                                 doc_.nodes[static_cast<std::size_t>(k)].parent),
                     fmt::format("the node hierarchy has a cycle through nodes[{}]", k));
            for (int p : path) state[static_cast<std::size_t>(p)] = 2;
        }
        // The scene's roots.
        if (!m_.scenes.empty()) {
            std::size_t scene = 0;
            if (m_.defaultScene >= 0) {
                check_index(m_.defaultScene, m_.scenes.size(), "scene", "scenes");
                scene = static_cast<std::size_t>(m_.defaultScene);
            }
            const auto& roots = m_.scenes[scene].nodes;
            std::vector<bool> seen(n, false);
            for (std::size_t k = 0; k < roots.size(); ++k) {
                const std::string at = fmt::format("scenes[{}].nodes[{}]", scene, k);
                check_index(roots[k], n, at, "nodes");
                const auto r = static_cast<std::size_t>(roots[k]);
                if (doc_.nodes[r].parent != -1)
                    fail(at, fmt::format("nodes[{}] is not a root: it is a child of nodes[{}]", r,
                                         doc_.nodes[r].parent));
                if (seen[r]) fail(at, fmt::format("nodes[{}] is listed twice", r));
                seen[r] = true;
                doc_.roots.push_back(roots[k]);
            }
        } else {
            for (std::size_t i = 0; i < n; ++i)
                if (doc_.nodes[i].parent == -1) doc_.roots.push_back(static_cast<int>(i));
        }
    }

    std::shared_ptr<const ImageRgb8> texture(int texture_index, const std::string& where,
                                             const std::string& material) {
        check_index(texture_index, m_.textures.size(), where, "textures");
        const int source = m_.textures[static_cast<std::size_t>(texture_index)].source;
        const std::string at = fmt::format("textures[{}].source", texture_index);
        if (source < 0) {
            warn(at, fmt::format("no image: material '{}' keeps its colour", material));
            return nullptr;
        }
        check_index(source, m_.images.size(), at, "images");
        if (auto it = context_.images.find(source); it != context_.images.end()) return it->second;
        const tinygltf::Image& image = m_.images[static_cast<std::size_t>(source)];
        std::string error;
        if (auto it = context_.image_errors.find(source); it != context_.image_errors.end()) {
            error = it->second;
        } else if (!image.uri.empty()) {
            // An external file (tinygltf leaves those to us).
            const std::filesystem::path path = base_dir_ / decode_uri(image.uri);
            try {
                const std::string bytes = read_file(path, options_.limits.max_input_bytes);
                auto decoded = std::make_shared<ImageRgb8>();
                if (gltf_detail::decode_image(reinterpret_cast<const std::uint8_t*>(bytes.data()),
                                              bytes.size(), options_.limits.max_image_pixels,
                                              *decoded, error)) {
                    context_.images[source] = decoded;
                    return decoded;
                }
                error = fmt::format("{}: {}", path.string(), error);
            } catch (const Error& e) {
                error = e.what();
            }
        } else {
            error = "no image data";
        }
        context_.image_errors[source] = error;
        warn(fmt::format("images[{}]", source),
             fmt::format("texture not used by material '{}': {}", material, error));
        return nullptr;
    }

    // %XX escapes of a relative URI.
    static std::string decode_uri(const std::string& uri) {
        std::string out;
        for (std::size_t i = 0; i < uri.size(); ++i) {
            if (uri[i] == '%' && i + 2 < uri.size() &&
                std::isxdigit(static_cast<unsigned char>(uri[i + 1])) &&
                std::isxdigit(static_cast<unsigned char>(uri[i + 2]))) {
                out.push_back(static_cast<char>(std::stoi(uri.substr(i + 1, 2), nullptr, 16)));
                i += 2;
            } else {
                out.push_back(uri[i]);
            }
        }
        return out;
    }

    void read_materials() {
        for (std::size_t i = 0; i < m_.materials.size(); ++i) {
            const tinygltf::Material& src = m_.materials[i];
            const std::string at = fmt::format("materials[{}]", i);
            Material mat(src.name.empty() ? fmt::format("material{}", i) : src.name);
            const auto& factor = src.pbrMetallicRoughness.baseColorFactor;
            if (factor.size() != 4)
                fail(at + ".pbrMetallicRoughness.baseColorFactor",
                     fmt::format("{} numbers where 4 are expected", factor.size()));
            for (int c = 0; c < 3; ++c) {
                const double v = factor[static_cast<std::size_t>(c)];
                if (!std::isfinite(v) || v < 0 || v > 1)
                    fail(at + ".pbrMetallicRoughness.baseColorFactor",
                         fmt::format("{} is not in [0, 1]", v));
                mat.kd[c] = static_cast<float>(v);
            }
            const auto& tex = src.pbrMetallicRoughness.baseColorTexture;
            if (tex.index >= 0 && options_.load_textures) {
                const std::string where = at + ".pbrMetallicRoughness.baseColorTexture";
                if (tex.texCoord != 0)
                    warn(where + ".texCoord",
                         fmt::format("texture coordinates {} are not read: TEXCOORD_0 is used",
                                     tex.texCoord));
                mat.kd_image = texture(tex.index, where + ".index", mat.name);
            }
            doc_.materials.push_back(std::move(mat));
        }
    }

    void read_meshes() {
        doc_.meshes.resize(m_.meshes.size());
        for (std::size_t i = 0; i < m_.meshes.size(); ++i) {
            const tinygltf::Mesh& src = m_.meshes[i];
            GltfMesh& mesh = doc_.meshes[i];
            mesh.name = src.name;
            for (double w : src.weights) {
                if (!std::isfinite(w)) fail(fmt::format("meshes[{}].weights", i), "not a number");
                mesh.weights.push_back(static_cast<float>(w));
            }
            for (std::size_t p = 0; p < src.primitives.size(); ++p) {
                const std::string at = fmt::format("meshes[{}].primitives[{}]", i, p);
                GltfPrimitive prim;
                if (read_primitive(src.primitives[p], at, prim))
                    mesh.primitives.push_back(std::move(prim));
            }
            std::size_t targets = 0;
            for (const auto& prim : mesh.primitives)
                targets = std::max(targets, prim.targets.size());
            for (auto& prim : mesh.primitives)
                if (prim.targets.size() != targets)
                    fail(fmt::format("meshes[{}].primitives", i),
                         "primitives have different numbers of morph targets");
            if (!mesh.weights.empty() && mesh.weights.size() != targets)
                fail(fmt::format("meshes[{}].weights", i),
                     fmt::format("{} weights for {} morph targets", mesh.weights.size(), targets));
            mesh.weights.resize(targets, 0.0f);
        }
    }

    // A node's weights replace its mesh's: one per morph target, on a node with a mesh.
    void check_node_weights() const {
        for (std::size_t i = 0; i < doc_.nodes.size(); ++i) {
            const GltfNode& node = doc_.nodes[i];
            if (node.weights.empty()) continue;
            const std::string at = fmt::format("nodes[{}].weights", i);
            if (node.mesh < 0)
                fail(at, fmt::format("{} weights on a node without a mesh", node.weights.size()));
            const std::size_t targets =
                doc_.meshes[static_cast<std::size_t>(node.mesh)].weights.size();
            if (node.weights.size() != targets)
                fail(at, fmt::format("{} weights for the {} morph targets of meshes[{}]",
                                     node.weights.size(), targets, node.mesh));
        }
    }

    bool read_primitive(const tinygltf::Primitive& src, const std::string& at,
                        GltfPrimitive& prim) {
        const int mode = src.mode < 0 ? TINYGLTF_MODE_TRIANGLES : src.mode;
        if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
            mode != TINYGLTF_MODE_TRIANGLE_FAN) {
            warn(at + ".mode", fmt::format("mode {} (points or lines) is not drawn", mode));
            return false;
        }
        const auto position = src.attributes.find("POSITION");
        if (position == src.attributes.end()) {
            warn(at + ".attributes", "no POSITION: not drawn");
            return false;
        }
        prim.positions = read_vec3(position->second, at + ".attributes.POSITION");
        const std::size_t n = prim.positions.size();
        for (const auto& v : prim.positions)
            if (!is_finite(v)) fail(at + ".attributes.POSITION", "a coordinate is not finite");
        auto attribute = [&](const char* name) {
            auto it = src.attributes.find(name);
            return it == src.attributes.end() ? -1 : it->second;
        };
        auto same_count = [&](std::size_t count, const std::string& where) {
            if (count != n) fail(where, fmt::format("{} values for {} positions", count, n));
        };
        if (int a = attribute("NORMAL"); a >= 0) {
            prim.normals = read_vec3(a, at + ".attributes.NORMAL");
            same_count(prim.normals.size(), at + ".attributes.NORMAL");
            zero_non_finite(prim.normals);
        }
        if (int a = attribute("TEXCOORD_0"); a >= 0) {
            const std::string where = at + ".attributes.TEXCOORD_0";
            prim.texcoords.resize(accessor_or_fail(a, where).count);
            read_accessor(a, where, {TINYGLTF_TYPE_VEC2}, false,
                          [&](std::size_t k, int c, double v) {
                              const float f = std::isfinite(v) ? static_cast<float>(v) : 0.0f;
                              if (c == 0) prim.texcoords[k].x = f;
                              else prim.texcoords[k].y = 1.0f - f;  // glTF's v = 0 is the top
                          });
            same_count(prim.texcoords.size(), where);
        }
        if (int a = attribute("COLOR_0"); a >= 0) {
            const std::string where = at + ".attributes.COLOR_0";
            prim.colours.resize(accessor_or_fail(a, where).count);
            read_accessor(a, where, {TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4}, false,
                          [&](std::size_t k, int c, double v) {
                              if (c < 3)
                                  prim.colours[k][c] =
                                      std::isfinite(v) ? static_cast<float>(std::clamp(v, 0.0, 1.0))
                                                       : 0.0f;
                          });
            same_count(prim.colours.size(), where);
        }
        if (int j = attribute("JOINTS_0"), w = attribute("WEIGHTS_0"); j >= 0 || w >= 0) {
            if (j < 0 || w < 0) fail(at + ".attributes", "JOINTS_0 and WEIGHTS_0 come together");
            prim.joints.resize(accessor_or_fail(j, at + ".attributes.JOINTS_0").count);
            read_accessor(j, at + ".attributes.JOINTS_0", {TINYGLTF_TYPE_VEC4}, true,
                          [&](std::size_t k, int c, double v) {
                              prim.joints[k][static_cast<std::size_t>(c)] =
                                  static_cast<std::uint32_t>(v);
                          });
            same_count(prim.joints.size(), at + ".attributes.JOINTS_0");
            prim.weights.resize(accessor_or_fail(w, at + ".attributes.WEIGHTS_0").count);
            read_accessor(w, at + ".attributes.WEIGHTS_0", {TINYGLTF_TYPE_VEC4}, false,
                          [&](std::size_t k, int c, double v) {
                              prim.weights[k][static_cast<std::size_t>(c)] =
                                  std::isfinite(v) ? static_cast<float>(v) : 0.0f;
                          });
            same_count(prim.weights.size(), at + ".attributes.WEIGHTS_0");
        }
        for (std::size_t t = 0; t < src.targets.size(); ++t) {
            GltfMorphTarget target;
            for (const auto& [name, index] : src.targets[t]) {
                const std::string where = fmt::format("{}.targets[{}].{}", at, t, name);
                if (name == "POSITION" || name == "NORMAL") {
                    auto values = read_vec3(index, where);
                    same_count(values.size(), where);
                    zero_non_finite(values);
                    (name == "POSITION" ? target.positions : target.normals) = std::move(values);
                }
            }
            prim.targets.push_back(std::move(target));
        }
        if (src.material >= 0) {
            check_index(src.material, m_.materials.size(), at + ".material", "materials");
            prim.material = static_cast<std::uint32_t>(src.material) + 1;
        }
        // Corners: the indices, or the vertices in order.
        std::vector<std::uint32_t> corners;
        if (src.indices >= 0) {
            const std::string where = at + ".indices";
            corners.resize(accessor_or_fail(src.indices, where).count);
            read_accessor(src.indices, where, {TINYGLTF_TYPE_SCALAR}, true,
                          [&](std::size_t k, int, double v) {
                              if (v >= static_cast<double>(n))
                                  fail(where, fmt::format("index {} at element {} is out of range "
                                                          "({} vertices)",
                                                          v, k, n));
                              corners[k] = static_cast<std::uint32_t>(v);
                          });
        } else {
            corners.resize(n);
            for (std::size_t k = 0; k < n; ++k) corners[k] = static_cast<std::uint32_t>(k);
        }
        if (mode == TINYGLTF_MODE_TRIANGLES) {
            if (corners.size() % 3 != 0)
                warn(at, fmt::format("{} corners is not a whole number of triangles: the last {} "
                                     "are left out",
                                     corners.size(), corners.size() % 3));
            corners.resize(corners.size() - corners.size() % 3);
            prim.indices = std::move(corners);
        } else {
            for (std::size_t k = 2; k < corners.size(); ++k) {
                if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
                    prim.indices.insert(prim.indices.end(),
                                        {corners[0], corners[k - 1], corners[k]});
                } else if (k % 2 == 0) {
                    prim.indices.insert(prim.indices.end(),
                                        {corners[k - 2], corners[k - 1], corners[k]});
                } else {
                    prim.indices.insert(prim.indices.end(),
                                        {corners[k - 1], corners[k - 2], corners[k]});
                }
            }
        }
        return true;
    }

    void read_skins() {
        for (std::size_t i = 0; i < m_.skins.size(); ++i) {
            const tinygltf::Skin& src = m_.skins[i];
            const std::string at = fmt::format("skins[{}]", i);
            GltfSkin skin;
            for (std::size_t k = 0; k < src.joints.size(); ++k) {
                check_index(src.joints[k], m_.nodes.size(), fmt::format("{}.joints[{}]", at, k),
                            "nodes");
                skin.joints.push_back(src.joints[k]);
            }
            GltfMatrix identity{};
            for (int k = 0; k < 4; ++k) identity[static_cast<std::size_t>(k * 5)] = 1.0f;
            skin.inverse_bind.assign(skin.joints.size(), identity);
            if (src.inverseBindMatrices >= 0) {
                const std::string where = at + ".inverseBindMatrices";
                const auto& a = accessor_or_fail(src.inverseBindMatrices, where);
                if (a.count < skin.joints.size())
                    fail(where,
                         fmt::format("{} matrices for {} joints", a.count, skin.joints.size()));
                std::vector<GltfMatrix> matrices(a.count);
                read_accessor(src.inverseBindMatrices, where, {TINYGLTF_TYPE_MAT4}, false,
                              [&](std::size_t k, int c, double v) {
                                  matrices[k][static_cast<std::size_t>(c)] = static_cast<float>(v);
                              });
                for (std::size_t k = 0; k < skin.joints.size(); ++k)
                    skin.inverse_bind[k] = matrices[k];
            }
            doc_.skins.push_back(std::move(skin));
        }
        // Joint indices of skinned primitives must name joints of every skin they are used with.
        for (std::size_t i = 0; i < doc_.nodes.size(); ++i) {
            const GltfNode& node = doc_.nodes[i];
            if (node.mesh < 0) continue;
            const auto& mesh = doc_.meshes[static_cast<std::size_t>(node.mesh)];
            for (std::size_t p = 0; p < mesh.primitives.size(); ++p) {
                const auto& prim = mesh.primitives[p];
                if (prim.joints.empty()) continue;
                if (node.skin < 0) continue;  // drawn unskinned
                const std::size_t joints =
                    doc_.skins[static_cast<std::size_t>(node.skin)].joints.size();
                for (const auto& j : prim.joints)
                    for (std::uint32_t k : j)
                        if (k >= joints)
                            fail(fmt::format("meshes[{}].primitives[{}].attributes.JOINTS_0",
                                             node.mesh, p),
                                 fmt::format("joint {} is out of range (skins[{}] has {} joints)",
                                             k, node.skin, joints));
            }
        }
    }

    void read_cameras() {
        for (std::size_t i = 0; i < m_.cameras.size(); ++i) {
            const tinygltf::Camera& src = m_.cameras[i];
            const std::string at = fmt::format("cameras[{}]", i);
            GltfCamera camera;
            camera.name = src.name;
            if (src.type != "perspective") {
                // Kept so that node indices stay valid; choosing it is an error.
                camera.yfov = 0.0f;
                doc_.cameras.push_back(camera);
                continue;
            }
            const double yfov = src.perspective.yfov, aspect = src.perspective.aspectRatio;
            if (!(yfov > 1e-4 && yfov < 3.14))
                fail(at + ".perspective.yfov", fmt::format("{} is not an angle in (0, pi)", yfov));
            if (!(aspect >= 0 && aspect < 1e4))
                fail(at + ".perspective.aspectRatio",
                     fmt::format("{} is not a usable aspect", aspect));
            camera.yfov = static_cast<float>(yfov);
            camera.aspect = static_cast<float>(aspect);
            doc_.cameras.push_back(camera);
        }
    }

    void read_lights() {
        for (std::size_t i = 0; i < m_.lights.size(); ++i) {
            const tinygltf::Light& src = m_.lights[i];
            const std::string at = fmt::format("extensions.KHR_lights_punctual.lights[{}]", i);
            GltfLight light;
            light.name = src.name;
            if (src.type == "point") light.kind = GltfLight::Kind::Point;
            else if (src.type == "directional") light.kind = GltfLight::Kind::Directional;
            else if (src.type == "spot") light.kind = GltfLight::Kind::Spot;
            else
                fail(at + ".type", fmt::format("'{}' is not point, directional or spot", src.type));
            if (!src.color.empty()) {
                if (src.color.size() != 3) fail(at + ".color", "3 numbers are expected");
                for (int c = 0; c < 3; ++c) {
                    const double v = src.color[static_cast<std::size_t>(c)];
                    if (!(v >= 0 && v < 1e30))
                        fail(at + ".color", fmt::format("{} is not a colour", v));
                    light.colour[c] = static_cast<float>(v);
                }
            }
            if (!(src.intensity >= 0 && src.intensity < 1e30))
                fail(at + ".intensity", fmt::format("{} is not an intensity", src.intensity));
            light.intensity = static_cast<float>(src.intensity);
            doc_.lights.push_back(light);
        }
    }

    void read_animations() {
        for (std::size_t i = 0; i < m_.animations.size(); ++i) {
            const tinygltf::Animation& src = m_.animations[i];
            const std::string at = fmt::format("animations[{}]", i);
            GltfAnimation anim;
            anim.name = src.name;
            std::vector<int> widths(src.samplers.size(), 0);  // from the channels that use them
            std::vector<GltfPath> paths(src.samplers.size(), GltfPath::Translation);
            for (std::size_t c = 0; c < src.channels.size(); ++c) {
                const auto& ch = src.channels[c];
                const std::string where = fmt::format("{}.channels[{}]", at, c);
                if (ch.target_node < 0) continue;  // targets something other than a node
                check_index(ch.target_node, doc_.nodes.size(), where + ".target.node", "nodes");
                check_index(ch.sampler, src.samplers.size(), where + ".sampler", "samplers");
                GltfChannel channel;
                channel.node = ch.target_node;
                channel.sampler = ch.sampler;
                int width = 3;
                if (ch.target_path == "translation") channel.path = GltfPath::Translation;
                else if (ch.target_path == "rotation") channel.path = GltfPath::Rotation, width = 4;
                else if (ch.target_path == "scale") channel.path = GltfPath::Scale;
                else if (ch.target_path == "weights") {
                    channel.path = GltfPath::Weights;
                    const GltfNode& node = doc_.nodes[static_cast<std::size_t>(ch.target_node)];
                    width =
                        node.mesh < 0
                            ? 0
                            : static_cast<int>(
                                  doc_.meshes[static_cast<std::size_t>(node.mesh)].weights.size());
                    if (width == 0)
                        fail(where + ".target.path",
                             fmt::format("weights of nodes[{}], which has no morph targets",
                                         ch.target_node));
                } else {
                    warn(where + ".target.path",
                         fmt::format("'{}' is not animated", ch.target_path));
                    continue;
                }
                const auto s = static_cast<std::size_t>(ch.sampler);
                if (widths[s] != 0 && (widths[s] != width || paths[s] != channel.path))
                    fail(where + ".sampler",
                         "the sampler is shared by channels of different kinds");
                widths[s] = width;
                paths[s] = channel.path;
                anim.channels.push_back(channel);
            }
            for (std::size_t s = 0; s < src.samplers.size(); ++s) {
                const auto& sm = src.samplers[s];
                const std::string where = fmt::format("{}.samplers[{}]", at, s);
                GltfSampler sampler;
                if (sm.interpolation.empty() || sm.interpolation == "LINEAR")
                    sampler.interpolation = GltfInterpolation::Linear;
                else if (sm.interpolation == "STEP")
                    sampler.interpolation = GltfInterpolation::Step;
                else if (sm.interpolation == "CUBICSPLINE")
                    sampler.interpolation = GltfInterpolation::CubicSpline;
                else
                    fail(where + ".interpolation",
                         fmt::format("'{}' is not LINEAR, STEP or CUBICSPLINE", sm.interpolation));
                sampler.width = widths[s];
                if (sampler.width == 0) {  // used by no channel
                    anim.samplers.push_back(std::move(sampler));
                    continue;
                }
                sampler.times.resize(accessor_or_fail(sm.input, where + ".input").count);
                read_accessor(sm.input, where + ".input", {TINYGLTF_TYPE_SCALAR}, false,
                              [&](std::size_t k, int, double v) {
                                  sampler.times[k] = static_cast<float>(v);
                              });
                if (sampler.times.empty()) fail(where + ".input", "no key times");
                for (std::size_t k = 0; k < sampler.times.size(); ++k) {
                    if (!std::isfinite(sampler.times[k]) || std::abs(sampler.times[k]) > 1e9f)
                        fail(where + ".input",
                             fmt::format("key time {} is not usable", sampler.times[k]));
                    if (k > 0 && sampler.times[k] < sampler.times[k - 1])
                        fail(where + ".input",
                             fmt::format("key times decrease at key {} ({} after {})", k,
                                         sampler.times[k], sampler.times[k - 1]));
                }
                const bool weights = paths[s] == GltfPath::Weights;
                const auto& out = accessor_or_fail(sm.output, where + ".output");
                const std::uint64_t per_key =
                    static_cast<std::uint64_t>(
                        sampler.interpolation == GltfInterpolation::CubicSpline ? 3 : 1) *
                    (weights ? static_cast<std::uint64_t>(sampler.width) : 1);
                if (out.count != sampler.times.size() * per_key)
                    fail(where + ".output",
                         fmt::format("{} values for {} key times (expected {})", out.count,
                                     sampler.times.size(), sampler.times.size() * per_key));
                const int comps = weights ? 1 : sampler.width;
                sampler.values.resize(out.count * static_cast<std::size_t>(comps));
                read_accessor(
                    sm.output, where + ".output",
                    {weights ? TINYGLTF_TYPE_SCALAR
                             : (sampler.width == 4 ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3)},
                    false, [&](std::size_t k, int c, double v) {
                        if (!std::isfinite(v) || std::abs(v) > 1e30)
                            fail(where + ".output",
                                 fmt::format("value {} at element {} is not usable", v, k));
                        sampler.values[k * static_cast<std::size_t>(comps) +
                                       static_cast<std::size_t>(c)] = static_cast<float>(v);
                    });
                anim.duration = std::max(anim.duration, sampler.times.back());
                anim.samplers.push_back(std::move(sampler));
            }
            doc_.animations.push_back(std::move(anim));
        }
    }

    // Which meshes are instanced, and the triangles and vertices stored (every flattened node's
    // mesh, each instanced mesh once), against the limits.
    void count_instances() {
        const std::size_t meshes = doc_.meshes.size();
        std::vector<std::uint64_t> placements(meshes, 0);
        std::vector<std::uint8_t> excluded(meshes, 0);
        for (std::size_t m = 0; m < meshes; ++m)
            for (const auto& prim : doc_.meshes[m].primitives)
                if (!prim.targets.empty()) excluded[m] = 1;
        std::vector<int> stack(doc_.roots.rbegin(), doc_.roots.rend());
        std::vector<int> order;
        while (!stack.empty()) {
            const int n = stack.back();
            stack.pop_back();
            order.push_back(n);
            const GltfNode& node = doc_.nodes[static_cast<std::size_t>(n)];
            stack.insert(stack.end(), node.children.rbegin(), node.children.rend());
        }
        for (int n : order) {
            const GltfNode& node = doc_.nodes[static_cast<std::size_t>(n)];
            if (node.mesh < 0) continue;
            const auto m = static_cast<std::size_t>(node.mesh);
            if (node.skin >= 0) excluded[m] = 1;
            placements[m] =
                add_saturated(placements[m], node.gpu_instances.count > 0 ? node.gpu_instances.count
                                                                          : std::uint64_t{1});
        }
        doc_.instanced_meshes.assign(meshes, 0);
        for (std::size_t m = 0; m < meshes; ++m)
            doc_.instanced_meshes[m] = !excluded[m] && placements[m] >= 2;
        auto add_mesh = [&](std::size_t m) {
            for (const auto& prim : doc_.meshes[m].primitives) {
                doc_.triangles = add_saturated(doc_.triangles, prim.indices.size() / 3);
                doc_.vertices = add_saturated(doc_.vertices, prim.positions.size());
            }
        };
        for (std::size_t m = 0; m < meshes; ++m)
            if (doc_.instanced_meshes[m]) {
                add_mesh(m);
                doc_.instances = add_saturated(doc_.instances, placements[m]);
            }
        for (int n : order) {
            const GltfNode& node = doc_.nodes[static_cast<std::size_t>(n)];
            if (node.mesh < 0 || doc_.instanced_meshes[static_cast<std::size_t>(node.mesh)])
                continue;
            // A morphed mesh instanced by EXT_mesh_gpu_instancing is posed once per node.
            add_mesh(static_cast<std::size_t>(node.mesh));
            if (node.gpu_instances.count > 0)
                doc_.instances = add_saturated(doc_.instances, node.gpu_instances.count);
        }
        const std::uint64_t max_triangles = std::min(options_.limits.max_triangles, kMaxIndexable);
        if (doc_.triangles > max_triangles)
            throw LimitError(Limit::Triangles,
                             fmt::format("{}: {} triangles, more than the limit of {}", file_,
                                         doc_.triangles, max_triangles));
        if (doc_.instances >= kMaxIndexable)
            throw LimitError(Limit::Memory,
                             fmt::format("{}: {} instances are too many", file_, doc_.instances));
        const std::uint64_t max_vertices = std::min(options_.limits.max_vertices, kMaxIndexable);
        if (doc_.vertices > max_vertices)
            throw LimitError(Limit::Vertices,
                             fmt::format("{}: {} vertices, more than the limit of {}", file_,
                                         doc_.vertices, max_vertices));
    }

    const tinygltf::Model& m_;
    std::string file_;
    std::filesystem::path base_dir_;
    Warnings& warnings_;
    const GltfOptions& options_;
    LoadContext& context_;
    GltfDocument doc_;
    mutable std::size_t warning_count_ = 0;
};

// tinygltf's first error, cut short: it may quote a whole data URI.
std::string first_line(std::string text) {
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
    if (auto nl = text.find('\n'); nl != std::string::npos) text.resize(nl);
    if (text.size() > 240) text = text.substr(0, 200) + "...";
    return text;
}

}  // namespace

bool GltfDocument::deforms() const {
    for (const auto& skin : skins)
        if (!skin.joints.empty())
            for (const auto& node : nodes)
                if (node.skin >= 0 && node.mesh >= 0) return true;
    for (const auto& anim : animations)
        for (const auto& ch : anim.channels)
            if (ch.path == GltfPath::Weights) return true;
    return false;
}

bool is_gltf_path(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext == ".gltf" || ext == ".glb";
}

GltfDocument parse_gltf(std::span<const std::uint8_t> bytes, const std::filesystem::path& path,
                        Warnings& warnings, const GltfOptions& options) {
    const std::string file = path.string();
    const bool binary = bytes.size() >= 4 && read_u32(bytes.data()) == kGlbMagic;
    if (binary) check_glb(bytes, file);
    // The memory of the parsed document: decoded buffers are about the size of the file, and
    // tinygltf's JSON tree a few times the JSON text.
    check_memory(add_saturated(options.limits.reserved_memory, mul_saturated(bytes.size(), 8)),
                 fmt::format("{} ({})", file, format_bytes(bytes.size())));

    // tinygltf refuses some files without a reason and reads others wrongly without a word;
    // their JSON is checked first, for an error naming the JSON path.
    const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    if (auto problem = gltf_detail::check_gltf_json(
            binary ? text.substr(20, read_u32(bytes.data() + 12)) : text))
        throw Error(fmt::format("{}: {}", file, *problem));

    LoadContext context;
    context.max_input_bytes = options.limits.max_input_bytes;
    context.max_image_pixels = options.limits.max_image_pixels;
    tinygltf::TinyGLTF loader;
    loader.SetFsCallbacks(
        {&file_exists, &expand_path, &read_whole_file, &write_whole_file, &context});
    loader.SetImageLoader(&load_image, &context);
    tinygltf::Model model;
    std::string err, warn;
    const std::filesystem::path base_dir = path.parent_path();
    const std::string base = base_dir.empty() ? "." : base_dir.string();
    bool ok = false;
    try {
        if (binary) {
            ok = loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(),
                                             static_cast<unsigned int>(bytes.size()), base);
        } else {
            ok = loader.LoadASCIIFromString(&model, &err, &warn,
                                            reinterpret_cast<const char*>(bytes.data()),
                                            static_cast<unsigned int>(bytes.size()), base);
        }
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        throw Error(fmt::format("{}: {}", file, e.what()));
    }
    if (!ok)
        throw Error(fmt::format(
            "{}: {}", file,
            err.empty() ? "not a glTF 2.0 file (the parser gives no reason)" : first_line(err)));
    DocumentReader reader(model, file, base_dir, warnings, options, context);
    return reader.read();
}

GltfDocument load_gltf(const std::filesystem::path& path, Warnings& warnings,
                       const GltfOptions& options) {
    const std::string bytes = read_file(path, options.limits.max_input_bytes);
    if (bytes.size() > 0xFFFFFFFFu)
        throw LimitError(Limit::InputBytes,
                         fmt::format("{}: glTF files are read up to 4 GiB", path.string()));
    return parse_gltf({reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()}, path,
                      warnings, options);
}

}  // namespace toonray
