#include "toonray/scene/obj_writer.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fmt/compile.h>
#include <fmt/format.h>
#include <span>
#include <vector>

#include "toonray/core/error.h"
#include "toonray/io/file.h"

namespace toonray {
namespace {

/// Appends text to a std::string through a raw pointer. Each caller reserves room for one
/// statement first (reserve), so the per-number work is a formatting call and a pointer bump;
/// going through std::string::append per token costs several times more for a 40k-triangle
/// frame.
class Appender {
public:
    explicit Appender(std::string& out) : out_(out) {
        out_.resize(out_.capacity() > 0 ? out_.capacity() : 4096);
        p_ = out_.data();
        end_ = p_ + out_.size();
    }
    ~Appender() { out_.resize(static_cast<std::size_t>(p_ - out_.data())); }
    Appender(const Appender&) = delete;
    Appender& operator=(const Appender&) = delete;

    /// Makes sure at least `n` more characters fit.
    void reserve(std::size_t n) {
        if (static_cast<std::size_t>(end_ - p_) >= n) return;
        std::size_t used = static_cast<std::size_t>(p_ - out_.data());
        out_.resize(std::max(out_.size() * 2, used + n));
        p_ = out_.data() + used;
        end_ = out_.data() + out_.size();
    }
    [[nodiscard]] std::size_t offset() const { return static_cast<std::size_t>(p_ - out_.data()); }
    void text(std::string_view s) {
        reserve(s.size());
        std::memcpy(p_, s.data(), s.size());
        p_ += s.size();
    }
    // The calls below assume the caller reserved room (kMaxFloat characters per float, kMaxInt
    // per integer).
    void ch(char c) { *p_++ = c; }
    void number(float v) { p_ = fmt::format_to(p_, FMT_COMPILE("{}"), v); }
    void number(std::uint64_t v) { p_ = fmt::format_to(p_, FMT_COMPILE("{}"), v); }
    void number(std::int64_t v) { p_ = fmt::format_to(p_, FMT_COMPILE("{}"), v); }

private:
    std::string& out_;
    char* p_;
    char* end_;
};

// Generous bounds: fmt's shortest float form is at most 15 characters ("-1.1754944e-38") and
// switches to exponent notation before fixed notation gets long.
constexpr std::size_t kMaxFloat = 24;
constexpr std::size_t kMaxInt = 20;

/// Names go through the loader's `rest()` (trimmed, cut at '#'), so only names that survive it
/// can be written faithfully.
void check_name(std::string_view name, std::string_view what) {
    bool ok = !name.empty() && name.find_first_of("#\n\r") == std::string_view::npos;
    auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\f' || c == '\v'; };
    if (ok) ok = !is_space(name.front()) && !is_space(name.back());
    if (!ok)
        throw Error(
            fmt::format("cannot write {} name '{}' to OBJ/MTL: it must be non-empty, "
                        "without '#' or line breaks and without surrounding white space",
                        what, name));
}

void check_finite(const Vec3f& v, std::string_view what, std::size_t index) {
    if (!is_finite(v))
        throw Error(fmt::format("cannot write OBJ: {} {} is not finite ({}, {}, {})", what, index,
                                v.x, v.y, v.z));
}

void vec3_line(Appender& a, std::string_view keyword, const Vec3f& v) {
    a.reserve(keyword.size() + 3 * (kMaxFloat + 1) + 1);
    a.text(keyword);
    a.ch(' ');
    a.number(v.x);
    a.ch(' ');
    a.number(v.y);
    a.ch(' ');
    a.number(v.z);
    a.ch('\n');
}

void colour_line(std::string& out, std::string_view keyword, const Vec3f& c) {
    fmt::format_to(std::back_inserter(out), "{} {} {} {}\n", keyword, c.x, c.y, c.z);
}

}  // namespace

std::filesystem::path mtl_path_for(const std::filesystem::path& obj_path) {
    std::filesystem::path p = obj_path;
    p.replace_extension(".mtl");
    return p;
}

struct ObjWriter::Cache {
    std::string text;  ///< the OBJ text this cache describes
    std::vector<Vec3f> positions, normals;
    /// Start offsets in `text` of each `v` / `vn` line, plus the end of the last one.
    std::vector<std::size_t> position_lines, normal_lines;
    // The face section (from the first `o` or `f` to the last face) and what it depended on.
    bool has_faces = false;
    std::size_t face_begin = 0, face_end = 0;
    bool any_normals = false, any_texcoords = false;
    std::size_t texcoord_count = 0;
    std::vector<std::array<std::uint32_t, 3>> tri_positions, tri_normals, tri_texcoords;
    std::vector<std::uint32_t> tri_material, tri_object;
    std::vector<std::string> objects, materials;
};

namespace {

bool same_bits(const Vec3f& a, const Vec3f& b) { return std::memcmp(&a, &b, sizeof(Vec3f)) == 0; }

template <typename T>
bool same_vector(const std::vector<T>& a, const std::vector<T>& b) {
    return a.size() == b.size() &&
           (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

bool same_faces(const ObjWriter::Cache& c, const Scene& s, bool any_normals, bool any_texcoords) {
    if (!c.has_faces || c.any_normals != any_normals || c.any_texcoords != any_texcoords)
        return false;
    // Same counts too: the old face lines were checked against them.
    if (c.positions.size() != s.positions.size() || c.texcoord_count != s.texcoords.size() ||
        (any_normals && c.normals.size() != s.normals.size()))
        return false;
    if (!same_vector(c.tri_positions, s.tri_positions) ||
        !same_vector(c.tri_normals, s.tri_normals) ||
        !same_vector(c.tri_texcoords, s.tri_texcoords) ||
        !same_vector(c.tri_material, s.tri_material) || !same_vector(c.tri_object, s.tri_object) ||
        c.objects != s.objects || c.materials.size() != s.materials.size())
        return false;
    for (std::size_t i = 0; i < s.materials.size(); ++i)
        if (c.materials[i] != s.materials[i].name) return false;
    return true;
}

/// Writes `v`/`vn` lines, copying the previous text of values that have not changed.
void vec3_lines(Appender& a, std::string_view keyword, const std::vector<Vec3f>& values,
                std::string_view what, const std::vector<Vec3f>* prev_values,
                const std::vector<std::size_t>* prev_lines, const std::string* prev_text,
                std::vector<std::size_t>* lines) {
    if (lines) {
        lines->clear();
        lines->reserve(values.size() + 1);
    }
    const std::size_t reusable = prev_values ? std::min(prev_values->size(), values.size()) : 0;
    for (std::size_t i = 0; i < values.size(); ++i) {
        if (lines) lines->push_back(a.offset());
        if (i < reusable && same_bits(values[i], (*prev_values)[i])) {
            std::size_t b = (*prev_lines)[i], e = (*prev_lines)[i + 1];
            a.text(std::string_view(prev_text->data() + b, e - b));
            continue;
        }
        check_finite(values[i], what, i + 1);
        vec3_line(a, keyword, values[i]);
    }
    if (lines) lines->push_back(a.offset());
}

/// The OBJ formatter behind format_obj and ObjWriter. `prev` (may be null) is the previous
/// call's cache (its arrays may be taken over); `next` (may be null) receives this call's,
/// whose text is `out`.
void format_obj_impl(const Scene& scene, std::string_view mtl_name, std::string& out,
                     const ObjWriteOptions& options, ObjWriter::Cache* prev,
                     ObjWriter::Cache* next) {
    const std::size_t tris = scene.triangle_count();
    if (scene.tri_normals.size() != tris || scene.tri_texcoords.size() != tris ||
        scene.tri_material.size() != tris || scene.tri_object.size() != tris)
        throw Error("cannot write OBJ: the scene's per-triangle arrays have different sizes");
    for (std::size_t i = 1; i < scene.objects.size(); ++i) check_name(scene.objects[i], "object");
    for (std::size_t i = 1; i < scene.materials.size(); ++i)
        check_name(scene.materials[i].name, "material");
    if (!mtl_name.empty()) check_name(mtl_name, "material library");

    // Which optional attributes the faces use decides which are written.
    bool any_normals = false, any_texcoords = false;
    if (options.write_normals && !scene.normals.empty())
        for (const auto& n : scene.tri_normals)
            if (n[0] != kNoIndex || n[1] != kNoIndex || n[2] != kNoIndex) {
                any_normals = true;
                break;
            }
    if (options.write_texcoords && !scene.texcoords.empty())
        for (const auto& t : scene.tri_texcoords)
            if (t[0] != kNoIndex || t[1] != kNoIndex || t[2] != kNoIndex) {
                any_texcoords = true;
                break;
            }
    const bool camera = options.write_camera && scene.camera.has_value();
    const bool reuse_faces = prev && same_faces(*prev, scene, any_normals, any_texcoords);

    out.clear();
    Appender a(out);
    a.text(fmt::format("# toonray OBJ: {} vertices, {} triangles, {} objects\n",
                       scene.positions.size(), tris, scene.objects.size() - 1));
    if (!mtl_name.empty()) {
        a.text("mtllib ");
        a.text(mtl_name);
        a.text("\n");
    }

    vec3_lines(a, "v", scene.positions, "vertex", prev ? &prev->positions : nullptr,
               prev ? &prev->position_lines : nullptr, prev ? &prev->text : nullptr,
               next ? &next->position_lines : nullptr);
    if (any_texcoords)
        for (std::size_t i = 0; i < scene.texcoords.size(); ++i) {
            const Vec2f& t = scene.texcoords[i];
            if (!std::isfinite(t.x) || !std::isfinite(t.y))
                throw Error(
                    fmt::format("cannot write OBJ: texture coordinate {} is not finite", i + 1));
            a.reserve(3 + 2 * (kMaxFloat + 1) + 1);
            a.text("vt ");
            a.number(t.x);
            a.ch(' ');
            a.number(t.y);
            a.ch('\n');
        }
    if (any_normals) {
        vec3_lines(a, "vn", scene.normals, "normal", prev ? &prev->normals : nullptr,
                   prev ? &prev->normal_lines : nullptr, prev ? &prev->text : nullptr,
                   next ? &next->normal_lines : nullptr);
    } else if (next) {
        next->normal_lines.clear();
    }

    const std::size_t face_begin = a.offset();
    if (reuse_faces) {
        a.text(std::string_view(prev->text.data() + prev->face_begin,
                                prev->face_end - prev->face_begin));
    } else {
        // The loader numbers objects in order of first appearance (object 0 is "(default)").
        // When the scene's order differs, or an object has no triangles, name every object once
        // up front (empty groups) so the indices load back unchanged.
        std::uint32_t next_object = 1;
        bool in_order = true;
        std::vector<bool> seen(scene.objects.size(), false);
        if (!seen.empty()) seen[0] = true;
        for (std::uint32_t o : scene.tri_object) {
            if (o >= scene.objects.size())
                throw Error(fmt::format("cannot write OBJ: object index {} out of range", o));
            if (seen[o]) continue;
            seen[o] = true;
            if (o != next_object) in_order = false;
            ++next_object;
        }
        if (!in_order || next_object != scene.objects.size())
            for (std::size_t i = 1; i < scene.objects.size(); ++i) {
                a.text("o ");
                a.text(scene.objects[i]);
                a.text("\n");
            }

        const std::size_t npos = scene.positions.size(), nnorm = scene.normals.size(),
                          ntex = scene.texcoords.size();
        std::uint32_t object = 0, material = 0;
        for (std::size_t i = 0; i < tris; ++i) {
            if (scene.tri_object[i] != object) {
                object = scene.tri_object[i];
                a.text("o ");
                a.text(scene.objects[object]);
                a.text("\n");
            }
            if (scene.tri_material[i] != material) {
                material = scene.tri_material[i];
                if (material >= scene.materials.size())
                    throw Error(
                        fmt::format("cannot write OBJ: material index {} out of range", material));
                a.text(material == 0 ? std::string_view("usemtl") : std::string_view("usemtl "));
                if (material != 0) a.text(scene.materials[material].name);
                a.text("\n");
            }
            const auto& v = scene.tri_positions[i];
            const auto& n = scene.tri_normals[i];
            const auto& t = scene.tri_texcoords[i];
            a.reserve(2 + 3 * (3 * kMaxInt + 3) + 1);
            a.ch('f');
            for (int c = 0; c < 3; ++c) {
                if (v[c] >= npos)
                    throw Error(fmt::format("cannot write OBJ: triangle {} uses vertex {} of {}", i,
                                            v[c], npos));
                a.ch(' ');
                a.number(static_cast<std::uint64_t>(v[c]) + 1);
                bool has_t = any_texcoords && t[c] != kNoIndex;
                bool has_n = any_normals && n[c] != kNoIndex;
                if (has_t && t[c] >= ntex)
                    throw Error(
                        fmt::format("cannot write OBJ: triangle {} uses texture coordinate "
                                    "{} of {}",
                                    i, t[c], ntex));
                if (has_n && n[c] >= nnorm)
                    throw Error(fmt::format("cannot write OBJ: triangle {} uses normal {} of {}", i,
                                            n[c], nnorm));
                if (has_t || has_n) {
                    a.ch('/');
                    if (has_t) a.number(static_cast<std::uint64_t>(t[c]) + 1);
                    if (has_n) {
                        a.ch('/');
                        a.number(static_cast<std::uint64_t>(n[c]) + 1);
                    }
                }
            }
            a.ch('\n');
        }
    }
    const std::size_t face_end = a.offset();

    if (camera) {
        const CameraSpec& cam = *scene.camera;
        check_finite(cam.eye, "camera eye", 1);
        check_finite(cam.gaze, "camera gaze point", 1);
        check_finite(cam.up, "camera up vector", 1);
        a.text("# Camera start\n");
        vec3_line(a, "v", cam.eye);
        vec3_line(a, "v", cam.gaze);
        vec3_line(a, "vn", cam.up);
        a.text("c -2 -1 -1\n# Camera end\n");
    }

    if (next) {
        next->positions.assign(scene.positions.begin(), scene.positions.end());
        if (any_normals) next->normals.assign(scene.normals.begin(), scene.normals.end());
        else next->normals.clear();
        next->face_begin = face_begin;
        next->face_end = face_end;
        next->any_normals = any_normals;
        next->any_texcoords = any_texcoords;
        next->texcoord_count = scene.texcoords.size();
        next->has_faces = true;
        if (!reuse_faces) {
            next->tri_positions = scene.tri_positions;
            next->tri_normals = scene.tri_normals;
            next->tri_texcoords = scene.tri_texcoords;
            next->tri_material = scene.tri_material;
            next->tri_object = scene.tri_object;
            next->objects = scene.objects;
            next->materials.clear();
            for (const Material& m : scene.materials) next->materials.push_back(m.name);
        } else {
            // Same content as prev's: take it over without copying the big arrays twice.
            // Same content as prev's, which is discarded after this call: take it over.
            next->tri_positions.swap(prev->tri_positions);
            next->tri_normals.swap(prev->tri_normals);
            next->tri_texcoords.swap(prev->tri_texcoords);
            next->tri_material.swap(prev->tri_material);
            next->tri_object.swap(prev->tri_object);
            next->objects.swap(prev->objects);
            next->materials.swap(prev->materials);
        }
    }
}

}  // namespace

void format_obj(const Scene& scene, std::string_view mtl_name, std::string& out,
                const ObjWriteOptions& options) {
    format_obj_impl(scene, mtl_name, out, options, nullptr, nullptr);
}

void format_mtl(const Scene& scene, const std::filesystem::path& mtl_dir, std::string& out) {
    out.clear();
    fmt::format_to(std::back_inserter(out), "# toonray MTL: {} materials\n",
                   scene.materials.size() > 0 ? scene.materials.size() - 1 : 0);
    for (std::size_t i = 1; i < scene.materials.size(); ++i) {
        const Material& m = scene.materials[i];
        check_name(m.name, "material");
        for (const Vec3f* c : {&m.ka, &m.kd, &m.ks})
            if (!is_finite(*c))
                throw Error(
                    fmt::format("cannot write MTL: material '{}' has a non-finite colour", m.name));
        if (!std::isfinite(m.ns) || !std::isfinite(m.d))
            throw Error(
                fmt::format("cannot write MTL: material '{}' has a non-finite value", m.name));
        fmt::format_to(std::back_inserter(out), "\nnewmtl {}\n", m.name);
        colour_line(out, "Ka", m.ka);
        colour_line(out, "Kd", m.kd);
        colour_line(out, "Ks", m.ks);
        fmt::format_to(std::back_inserter(out), "Ns {}\nd {}\nillum {}\n", m.ns, m.d, m.illum);
        if (!m.map_kd.empty()) {
            // The loader joined the name onto its MTL's directory; undo that for the new place.
            std::filesystem::path tex(m.map_kd);
            std::filesystem::path rel = tex.lexically_proximate(mtl_dir.empty() ? "." : mtl_dir);
            fmt::format_to(std::back_inserter(out), "map_Kd {}\n", rel.generic_string());
        }
    }
}

ObjWriter::ObjWriter() : cache_(std::make_unique<Cache>()), next_(std::make_unique<Cache>()) {}
ObjWriter::~ObjWriter() = default;
ObjWriter::ObjWriter(ObjWriter&&) noexcept = default;
ObjWriter& ObjWriter::operator=(ObjWriter&&) noexcept = default;

const std::string& ObjWriter::format(const Scene& scene, std::string_view mtl_name,
                                     const ObjWriteOptions& options) {
    try {
        format_obj_impl(scene, mtl_name, next_->text, options, cache_.get(), next_.get());
    } catch (...) {
        // A half-built cache must not be trusted next time.
        *cache_ = Cache{};
        *next_ = Cache{};
        throw;
    }
    std::swap(cache_, next_);
    next_->has_faces = false;
    return cache_->text;
}

void ObjWriter::write(const std::filesystem::path& obj_path, const Scene& scene,
                      const ObjWriteOptions& options) {
    const std::filesystem::path mtl_path = mtl_path_for(obj_path);
    // The OBJ names its MTL even when this call does not rewrite it (a frame sequence writes the
    // MTL once); a scene with only the default material needs none.
    const std::string mtl_name =
        scene.materials.size() > 1 ? mtl_path.filename().string() : std::string();
    const std::string& obj = format(scene, mtl_name, options);
    const bool mtl = options.write_mtl && !mtl_name.empty();
    if (mtl) format_mtl(scene, mtl_path.parent_path(), mtl_);
    auto bytes = [](const std::string& s) {
        return std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(s.data()),
                                             s.size());
    };
    // MTL first: a reader that sees the new OBJ also finds its materials.
    if (mtl) write_file_atomic(mtl_path, bytes(mtl_));
    write_file_atomic(obj_path, bytes(obj));
}

void write_obj(const std::filesystem::path& obj_path, const Scene& scene,
               const ObjWriteOptions& options) {
    ObjWriter writer;
    writer.write(obj_path, scene, options);
}

}  // namespace toonray
