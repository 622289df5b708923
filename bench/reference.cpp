#include "reference.h"

#include <fmt/format.h>
#include <png.h>
#include <tiny_obj_loader.h>
#include <bit>
#include <stdexcept>

namespace toonray::bench {
namespace {

struct TinyObj {
    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
};

void load(const std::filesystem::path& path, TinyObj& t) {
    std::string warn, err;
    std::string dir = path.parent_path().string();
    if (!dir.empty()) dir += '/';
    if (!tinyobj::LoadObj(&t.attrib, &t.shapes, &t.materials, &warn, &err, path.c_str(),
                          dir.c_str(), /*triangulate=*/true))
        throw std::runtime_error(
            fmt::format("tinyobjloader cannot load {}: {}", path.string(), err));
}

bool same_bits(float a, float b) {
    return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b);
}
bool same_bits(const Vec3f& a, const Vec3f& b) {
    return same_bits(a.x, b.x) && same_bits(a.y, b.y) && same_bits(a.z, b.z);
}
Vec3f at3(const std::vector<tinyobj::real_t>& v, int i) {
    std::size_t k = static_cast<std::size_t>(i) * 3;
    return {static_cast<float>(v[k]), static_cast<float>(v[k + 1]), static_cast<float>(v[k + 2])};
}

}  // namespace

std::size_t tinyobj_load(const std::filesystem::path& path) {
    TinyObj t;
    load(path, t);
    std::size_t n = 0;
    for (const auto& s : t.shapes) n += s.mesh.num_face_vertices.size();
    return n;
}

std::vector<std::string> compare_with_tinyobj(const Scene& ours, const std::filesystem::path& path,
                                              std::size_t max_lines) {
    TinyObj t;
    load(path, t);
    std::vector<std::string> out;
    std::size_t tri = 0;
    auto note = [&](std::string s) {
        if (out.size() < max_lines) out.push_back(std::move(s));
    };
    for (const auto& shape : t.shapes) {
        std::size_t corner = 0;
        for (std::size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f, ++tri) {
            if (shape.mesh.num_face_vertices[f] != 3) {
                note("tinyobjloader left a face untriangulated");
                return out;
            }
            if (tri >= ours.triangle_count()) {
                note(fmt::format("tinyobjloader has more triangles than ours ({})",
                                 ours.triangle_count()));
                return out;
            }
            for (int k = 0; k < 3; ++k, ++corner) {
                const tinyobj::index_t& idx = shape.mesh.indices[corner];
                if (!same_bits(at3(t.attrib.vertices, idx.vertex_index),
                               ours.positions[ours.tri_positions[tri][k]]))
                    note(fmt::format("triangle {} corner {}: positions differ", tri, k));
                std::uint32_t n = ours.tri_normals[tri][k];
                if ((idx.normal_index >= 0) != (n != kNoIndex) ||
                    (n != kNoIndex &&
                     !same_bits(at3(t.attrib.normals, idx.normal_index), ours.normals[n])))
                    note(fmt::format("triangle {} corner {}: normals differ", tri, k));
            }
            const Material& m = ours.materials[ours.tri_material[tri]];
            int id = shape.mesh.material_ids[f];
            bool same_material =
                id < 0 ? ours.tri_material[tri] == 0
                       : (m.name == t.materials[id].name &&
                          same_bits(m.kd, Vec3f(static_cast<float>(t.materials[id].diffuse[0]),
                                                static_cast<float>(t.materials[id].diffuse[1]),
                                                static_cast<float>(t.materials[id].diffuse[2]))));
            if (!same_material) note(fmt::format("triangle {}: materials differ", tri));
        }
    }
    if (tri != ours.triangle_count())
        note(fmt::format("triangle count: ours {}, tinyobjloader {}", ours.triangle_count(), tri));
    return out;
}

std::vector<std::uint8_t> libpng_encode_rgb(int width, int height, const std::uint8_t* pixels) {
    std::vector<std::uint8_t> out;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    if (!info) throw std::runtime_error("libpng: out of memory");
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        throw std::runtime_error("libpng: encoding failed");
    }
    png_set_write_fn(
        png, &out,
        [](png_structp p, png_bytep data, png_size_t size) {
            auto* v = static_cast<std::vector<std::uint8_t>*>(png_get_io_ptr(p));
            v->insert(v->end(), data, data + size);
        },
        [](png_structp) {});
    // Defaults only: no png_set_compression_level or png_set_filter, as a caller would start.
    png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8,
                 PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    const std::size_t stride = static_cast<std::size_t>(width) * 3;
    for (int y = 0; y < height; ++y) png_write_row(png, pixels + stride * y);
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    return out;
}

}  // namespace toonray::bench
