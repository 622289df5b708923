#include "toonray/scene/obj_loader.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cstring>
#include <fmt/format.h>
#include <span>
#include <string>
#include <unordered_map>

#include "toonray/core/simd_sse.h"
#include "toonray/io/file.h"
#include "toonray/scene/mtl_loader.h"
#include "toonray/scene/obj_fast_path.h"
#include "toonray/scene/obj_lexer.h"
#include "toonray/scene/read_checks.h"

namespace toonray {

using namespace wavefront;

namespace {

std::uint32_t intern(std::unordered_map<std::string, std::uint32_t>& ids,
                     std::vector<std::string>& names, std::string_view name) {
    auto [it, inserted] =
        ids.try_emplace(std::string(name), static_cast<std::uint32_t>(names.size()));
    if (inserted) names.emplace_back(name);
    return it->second;
}

// The lines of the text, counted 16 bytes at a time, and whether it holds a NUL byte
// (refuse_binary), found in the same pass.
struct TextCounts {
    std::uint64_t lines = 1;
    bool nul = false;
};

TextCounts count_lines(std::string_view text) {
    TextCounts counts;
    const char* s = text.data();
    const std::size_t size = text.size();
    const __m128i newline = _mm_set1_epi8('\n'), zero = _mm_setzero_si128();
    __m128i nul = zero;
    std::size_t i = 0;
    for (; i + 16 <= size; i += 16) {
        const __m128i chars = _mm_loadu_si128(reinterpret_cast<const __m128i*>(s + i));
        nul = _mm_or_si128(nul, _mm_cmpeq_epi8(chars, zero));
        counts.lines += static_cast<unsigned>(std::popcount(
            static_cast<unsigned>(_mm_movemask_epi8(_mm_cmpeq_epi8(chars, newline)))));
    }
    counts.nul = _mm_movemask_epi8(nul) != 0;
    for (; i < size; ++i) {
        counts.lines += s[i] == '\n';
        counts.nul = counts.nul || s[i] == '\0';
    }
    return counts;
}

// Reserves for as many vertices of each kind and triangles as the text has lines: growing the
// arrays by doubling costs more than that count, and counting each kind of statement costs
// more than reserving too much. What is reserved and not used is never touched, so it costs
// address space only. A polygon's extra triangles simply grow the arrays. The count comes
// from the file, so it is held to the limits first: a file of 700 million "f" lines must fail
// at the limit's line with its message, not in a 30 GB reservation.
void reserve_for(std::uint64_t lines, Scene& scene, const Limits& limits) {
    const std::uint64_t v = std::min({lines, limits.max_vertices, kMaxIndexable});
    const std::uint64_t f = std::min({lines, limits.max_triangles, kMaxIndexable});
    if (scene_bytes(3 * v, f) > limits.max_memory) return;  // the parse stops at the limit
    scene.positions.reserve(v);
    scene.normals.reserve(v);
    scene.texcoords.reserve(v);
    scene.tri_positions.reserve(f);
    scene.tri_normals.reserve(f);
    scene.tri_texcoords.reserve(f);
    scene.tri_material.reserve(f);
    scene.tri_object.reserve(f);
}

/// A face's triangles, a fan from its first corner.
void append_fan(Scene& scene, const Corner* c, std::size_t count, std::uint32_t material,
                std::uint32_t object) {
    for (std::size_t i = 1; i + 1 < count; ++i)
        scene.add_triangle({c[0].v, c[i].v, c[i + 1].v}, material, object,
                           {c[0].n, c[i].n, c[i + 1].n}, {c[0].t, c[i].t, c[i + 1].t});
}

/// The corners of an 'f' statement in any form, with a precise message for each malformed
/// index and each vertex index out of range. A texture or normal index that points at no `vt` or
/// `vn` (0 or out of range) is read as other tools read it: the face keeps its geometry and
/// loses its texture coordinates or normals, with a warning (`warn_at` gets its message).
/// Returns false, with a warning, for a face of fewer than 3 corners, which is dropped.
template <typename Warn>
bool read_face_corners(const LineParser& parse, Tokens& t, const Scene& scene,
                       std::vector<Corner>& corners, const Warn& warn_at) {
    corners.clear();
    bool drop_texcoords = false, drop_normals = false;
    while (!t.at_end()) {
        std::string_view tok = t.next();
        const char* p = tok.data();
        const char* e = p + tok.size();
        long long idx[3] = {0, 0, 0};
        bool present[3] = {false, false, false};
        for (int slot = 0; slot < 3; ++slot) {
            if (p < e && *p != '/') {
                const char* q = p;
                if (parse_index(q, e, idx[slot]) && (q == e || *q == '/')) {
                    present[slot] = true;
                    p = q;
                    if (p < e) {
                        if (slot == 2) parse.fail(fmt::format("malformed face corner '{}'", tok));
                        ++p;
                    }
                    continue;
                }
                // Slow path, for its precise messages.
                auto [ptr, ec] = std::from_chars(p, e, idx[slot]);
                if (ec == std::errc::result_out_of_range && (ptr == e || *ptr == '/'))
                    parse.fail(fmt::format("face {} index in '{}' out of range",
                                           slot == 0   ? "vertex"
                                           : slot == 1 ? "texture"
                                                       : "normal",
                                           tok));
                if (ec != std::errc() || (ptr != e && *ptr != '/'))
                    parse.fail(fmt::format("malformed face corner '{}'", tok));
                present[slot] = true;
                p = ptr;
            }
            if (p < e) {
                if (*p != '/' || slot == 2)
                    parse.fail(fmt::format("malformed face corner '{}'", tok));
                ++p;
            }
        }
        if (!present[0]) parse.fail(fmt::format("face corner '{}' has no vertex index", tok));
        Corner c{0, kNoIndex, kNoIndex};
        if (!resolve_index(idx[0], scene.positions.size(), c.v))
            parse.fail(
                idx[0] == 0
                    ? fmt::format("face vertex index 0 in '{}' (OBJ indices start at 1)", tok)
                    : fmt::format("face vertex index {} out of range ({} vertices defined so far)",
                                  idx[0], scene.positions.size()));
        if (present[1] && !resolve_index(idx[1], scene.texcoords.size(), c.t) && !drop_texcoords) {
            drop_texcoords = true;
            warn_at(
                fmt::format("face texture index {} out of range ({} defined so far); the "
                            "face has no texture coordinates",
                            idx[1], scene.texcoords.size()));
        }
        if (present[2] && !resolve_index(idx[2], scene.normals.size(), c.n) && !drop_normals) {
            drop_normals = true;
            warn_at(
                fmt::format("face normal index {} out of range ({} defined so far); the "
                            "face uses its geometric normal",
                            idx[2], scene.normals.size()));
        }
        corners.push_back(c);
    }
    if (corners.size() < 3) {
        // A point or a line written as a face: other readers skip it.
        warn_at(fmt::format("face needs at least 3 corners, has {}; dropped", corners.size()));
        return false;
    }
    for (Corner& c : corners) {
        if (drop_texcoords) c.t = kNoIndex;
        if (drop_normals) c.n = kNoIndex;
    }
    return true;
}

/// Names in an `mtllib` statement: separated by blanks, where `\ ` is a space inside a name
/// (`mtllib my\ file.mtl`, as shells and some exporters escape it).
std::vector<std::string> library_names(std::string_view rest) {
    std::vector<std::string> names;
    std::string name;
    for (std::size_t i = 0; i < rest.size(); ++i) {
        const char ch = rest[i];
        if (ch == '\\' && i + 1 < rest.size() && is_blank(rest[i + 1])) {
            name += rest[++i];
        } else if (is_space(ch)) {
            if (!name.empty()) names.push_back(std::move(name));
            name.clear();
        } else {
            name += ch;
        }
    }
    if (!name.empty()) names.push_back(std::move(name));
    return names;
}

/// The points of an `l` element ("v" or "v/vt" each; texture coordinates are ignored) as
/// position indices appended to `points`. A vertex index of 0 or out of range is an error, as
/// in faces.
void read_polyline(const LineParser& parse, Tokens& t, const Scene& scene,
                   std::vector<std::uint32_t>& points) {
    std::size_t count = 0;
    while (!t.at_end()) {
        std::string_view tok = t.next();
        const char* p = tok.data();
        const char* e = p + tok.size();
        long long index;
        if (!parse_index(p, e, index) || (p != e && *p != '/'))
            parse.fail(fmt::format("malformed line point '{}'", tok));
        if (p != e) {
            ++p;
            long long texture;
            if (!parse_index(p, e, texture) || p != e)
                parse.fail(fmt::format("malformed line point '{}'", tok));
        }
        std::uint32_t v;
        if (!resolve_index(index, scene.positions.size(), v))
            parse.fail(
                index == 0
                    ? fmt::format("line vertex index 0 in '{}' (OBJ indices start at 1)", tok)
                    : fmt::format("line vertex index {} out of range ({} vertices defined so far)",
                                  index, scene.positions.size()));
        points.push_back(v);
        ++count;
    }
    if (count < 2) parse.fail(fmt::format("line element needs at least 2 points, has {}", count));
}

/// The camera block statement `c eye gaze up`: the indices of two vertices and a normal.
CameraSpec read_camera(const LineParser& parse, Tokens& t, const Scene& scene) {
    long long idx[3];
    for (long long& i : idx) {
        std::string_view tok = t.next();
        auto [ptr, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), i);
        if (tok.empty() || ec != std::errc() || ptr != tok.data() + tok.size())
            parse.fail("camera statement needs three indices: c eye gaze up");
    }
    if (!t.at_end()) parse.fail("camera statement has more than three indices: c eye gaze up");
    std::uint32_t eye, gaze, up;
    if (!resolve_index(idx[0], scene.positions.size(), eye))
        parse.fail(fmt::format("camera eye index {} out of range ({} vertices defined so far)",
                               idx[0], scene.positions.size()));
    if (!resolve_index(idx[1], scene.positions.size(), gaze))
        parse.fail(fmt::format("camera gaze index {} out of range ({} vertices defined so far)",
                               idx[1], scene.positions.size()));
    if (!resolve_index(idx[2], scene.normals.size(), up))
        parse.fail(fmt::format("camera up index {} out of range ({} normals defined so far)",
                               idx[2], scene.normals.size()));
    CameraSpec cam{scene.positions[eye], scene.positions[gaze], scene.normals[up]};
    try {
        validate_camera(cam);
    } catch (const Error& e) {
        parse.fail(e.what());
    }
    return cam;
}

/// Statements that are accepted and ignored: smoothing groups are implied by vn; free-form
/// geometry is not rendered.
bool is_ignored_statement(std::string_view kw) {
    return kw == "s" || kw == "vp" || kw == "cstype" || kw == "deg" || kw == "curv" ||
           kw == "curv2" || kw == "surf" || kw == "parm" || kw == "end" || kw == "mg" ||
           kw == "lod" || kw == "usemap" || kw == "maplib" || kw == "shadow_obj" ||
           kw == "trace_obj" || kw == "bevel" || kw == "c_interp" || kw == "d_interp" ||
           kw == "ctech" || kw == "stech" || kw == "trim" || kw == "hole" || kw == "scrv" ||
           kw == "sp" || kw == "con" || kw == "bmat" || kw == "step";
}

}  // namespace

void parse_obj(std::string_view text, const std::filesystem::path& path, Scene& scene,
               Warnings& warnings, const ObjOptions& options) {
    scene.clear();
    const std::string file = path.string();
    const TextCounts counts = count_lines(text);
    if (counts.nul) refuse_binary(text, file, "an OBJ");
    const Limits& lim = options.limits;
    LineReader reader(text, file, lim.max_line_bytes);
    WarningSink warn(warnings, file);
    reserve_for(counts.lines, scene, options.limits);

    std::unordered_map<std::string, std::uint32_t> object_ids{{"(default)", 0}};
    std::unordered_map<std::string, std::uint32_t> warned_materials, warned_statements;
    // Material names to indices, rebuilt after each mtllib (the last definition of a name wins).
    std::unordered_map<std::string_view, std::uint32_t> material_ids;
    auto index_materials = [&] {
        material_ids.clear();
        for (std::size_t i = 1; i < scene.materials.size(); ++i)
            material_ids[scene.materials[i].name] = static_cast<std::uint32_t>(i);
    };
    std::unordered_map<std::string, bool> libraries;  // each MTL file is read once
    std::uint32_t material = 0, object = 0;
    bool warned_points = false;
    std::vector<Corner> corners;
    corners.reserve(16);

    // Non-finite coordinates (nan, inf), which other tools read: the vertex is kept (as 0, so
    // every stored number stays finite) so indices stay right, and faces that use it are dropped (a non-finite normal or texture coordinate
    // only takes the face's normals or texture coordinates). The flags exist only once such a
    // value was read, so clean files pay one predictable branch per face.
    std::size_t nonfinite_count = 0;
    std::vector<std::uint8_t> nonfinite_position, nonfinite_normal, nonfinite_texcoord;
    auto mark_nonfinite = [&](std::vector<std::uint8_t>& flags, std::size_t count, bool finite,
                              std::size_t line, std::string_view what) {
        if (finite && nonfinite_count == 0) return;
        flags.resize(count, 0);
        if (finite) return;
        flags.back() = 1;
        ++nonfinite_count;
        warn.add(
            located(file, line,
                    fmt::format("non-finite coordinate in '{}'; the faces that use it {}", what,
                                what == "v" ? "are dropped"
                                            : (what == "vn" ? "use their geometric normals"
                                                            : "have no texture coordinates"))));
    };
    // After the fast path added a finite element: keeps the flags in step once they exist.
    auto keep_flags = [&](std::vector<std::uint8_t>& flags, std::size_t count) {
        if (nonfinite_count != 0) [[unlikely]]
            flags.resize(count, 0);
    };
    auto flagged = [](const std::vector<std::uint8_t>& flags, std::uint32_t i) {
        return i != kNoIndex && i < flags.size() && flags[i] != 0;
    };
    // False when the face must be dropped; clears non-finite normals and texture coordinates.
    auto usable_face = [&](std::size_t line, std::span<Corner> face) {
        bool normals_ok = true, texcoords_ok = true;
        for (const Corner& c : face) {
            if (flagged(nonfinite_position, c.v)) {
                warn.add(located(file, line,
                                 "face uses a vertex with a non-finite coordinate; dropped"));
                return false;
            }
            normals_ok = normals_ok && !flagged(nonfinite_normal, c.n);
            texcoords_ok = texcoords_ok && !flagged(nonfinite_texcoord, c.t);
        }
        for (Corner& c : face) {
            if (!normals_ok) c.n = kNoIndex;
            if (!texcoords_ok) c.t = kNoIndex;
        }
        return true;
    };

    // Memory: the text, the scene, its BVH, times the scenes loaded at once, plus what the
    // caller has committed elsewhere (frame buffers).
    MemoryCheck memory;
    const std::uint64_t max_vertices = std::min(lim.max_vertices, kMaxIndexable);
    const std::uint64_t max_triangles = std::min(lim.max_triangles, kMaxIndexable);
    auto estimate = [&] {
        const std::uint64_t vertices =
            scene.positions.size() + scene.normals.size() + scene.texcoords.size();
        const std::uint64_t names = scene.objects.size() + scene.materials.size();
        return lim.reserved_memory + text.size() +
               std::max<std::uint64_t>(lim.scenes_in_flight, 1) *
                   (scene_bytes(vertices, scene.triangle_count()) + names * kNamedBytes);
    };
    auto check_estimate = [&](const LineParser& parse) {
        const std::uint64_t bytes = estimate();
        if (bytes > lim.max_memory)
            parse.fail_limit(
                Limit::Memory,
                fmt::format(
                    "the scene so far ({} vertices, {} triangles) needs about {} of memory, "
                    "more than the limit of {}",
                    scene.positions.size(), scene.triangle_count(), format_bytes(bytes),
                    format_bytes(lim.max_memory)));
    };
    auto grew = [&](const LineParser& parse) {
        if (memory.due(scene.positions.size() + scene.normals.size() + scene.texcoords.size() +
                       scene.triangle_count() + scene.objects.size()))
            check_estimate(parse);
    };

    // What both paths do before adding an element (so a limit names the line that exceeds it),
    // and a face's triangles.
    auto adding_position = [&](const LineParser& parse) {
        check_count(parse, scene.positions.size() + 1, max_vertices, "vertices ('v')",
                    Limit::Vertices);
        grew(parse);
    };
    auto adding_normal = [&](const LineParser& parse) {
        check_count(parse, scene.normals.size() + 1, max_vertices, "normals ('vn')",
                    Limit::Vertices);
        grew(parse);
    };
    auto adding_texcoord = [&](const LineParser& parse) {
        check_count(parse, scene.texcoords.size() + 1, max_vertices, "texture coordinates ('vt')",
                    Limit::Vertices);
        grew(parse);
    };
    auto add_face = [&](const LineParser& parse, std::size_t line, std::span<Corner> face) {
        if (nonfinite_count != 0 && !usable_face(line, face)) [[unlikely]]
            return;
        if (scene.triangle_count() + (face.size() - 2) > max_triangles)
            parse.fail_limit(Limit::Triangles,
                             fmt::format("more than {} triangles (the limit)", max_triangles));
        grew(parse);
        append_fan(scene, face.data(), face.size(), material, object);
    };

    // The fast path skips those checks while `headroom` lasts: how many vertices or triangles
    // can be added before a count could pass its limit or the memory estimate is due. Each
    // element takes it down by what it adds; at 0 (and always once a non-finite value was
    // read, whose flags must be kept) an element takes the checked way, which does exactly
    // what the general path does.
    std::uint64_t headroom = 0;
    auto refresh_headroom = [&] {
        headroom =
            nonfinite_count != 0
                ? 0
                : std::min({max_vertices - scene.positions.size(),
                            max_vertices - scene.normals.size(),
                            max_vertices - scene.texcoords.size(),
                            max_triangles - scene.triangle_count(),
                            memory.until_due(scene.positions.size() + scene.normals.size() +
                                             scene.texcoords.size() + scene.triangle_count() +
                                             scene.objects.size())});
    };
    // A plain v, vn or vt line read by the fast path.
    auto add_vertex = [&]<typename T>(std::vector<T>& values, const T& value,
                                      std::vector<std::uint8_t>& flags, std::size_t line,
                                      const auto& adding) {
        if (headroom != 0) [[likely]] {
            --headroom;
            values.push_back(value);
            return;
        }
        adding(LineParser(file, line));
        values.push_back(value);
        keep_flags(flags, values.size());
        refresh_headroom();
    };

    // Any statement in any form, with its precise messages.
    auto read_statement = [&](std::string_view line, std::size_t line_number) {
        Tokens t(line);
        if (t.at_end()) return;
        std::string_view kw = t.next();
        LineParser parse(file, line_number);

        if (kw == "v") {
            adding_position(parse);
            bool finite = true;
            const Vec3f position = parse.coordinates3(t, kw, finite);
            scene.positions.push_back(finite ? position : Vec3f(0.0f));
            // Optional w (or vertex colour) values are accepted and ignored, but must be numbers.
            while (!t.at_end()) parse.number(t, kw);
            mark_nonfinite(nonfinite_position, scene.positions.size(), finite, line_number, kw);
        } else if (kw == "f") {
            if (read_face_corners(parse, t, scene, corners, [&](std::string message) {
                    warn.add(located(file, line_number, message));
                }))
                add_face(parse, line_number, corners);
        } else if (kw == "vn") {
            adding_normal(parse);
            bool finite = true;
            const Vec3f normal = parse.coordinates3(t, kw, finite);
            scene.normals.push_back(finite ? normal : Vec3f(0.0f));
            mark_nonfinite(nonfinite_normal, scene.normals.size(), finite, line_number, kw);
        } else if (kw == "vt") {
            adding_texcoord(parse);
            bool finite = true;
            Vec2f uv;
            uv.x = parse.coordinate(t, kw, finite);
            if (!t.at_end()) uv.y = parse.coordinate(t, kw, finite);
            if (!t.at_end()) parse.number(t, kw);
            scene.texcoords.push_back(finite ? uv : Vec2f{});
            mark_nonfinite(nonfinite_texcoord, scene.texcoords.size(), finite, line_number, kw);
        } else if (kw == "l") {
            Polyline line;
            line.first = static_cast<std::uint32_t>(scene.polyline_points.size());
            read_polyline(parse, t, scene, scene.polyline_points);
            line.count = static_cast<std::uint32_t>(scene.polyline_points.size() - line.first);
            check_count(parse, scene.polyline_points.size(), max_vertices, "polyline points ('l')",
                        Limit::Vertices);
            grew(parse);
            line.material = material;
            line.object = object;
            bool finite = true;
            for (std::uint32_t i = line.first; i < line.first + line.count; ++i)
                finite = finite && !flagged(nonfinite_position, scene.polyline_points[i]);
            if (finite) {
                scene.polylines.push_back(line);
            } else {
                scene.polyline_points.resize(line.first);
                warn.add(located(file, line_number,
                                 "line uses a vertex with a non-finite coordinate; dropped"));
            }
        } else if (kw == "p") {
            if (!warned_points) {
                warned_points = true;
                warn.add(located(file, line_number,
                                 "point elements ('p') are not drawn; ignored (this warning is "
                                 "given once a file)"));
            }
        } else if (kw == "usemtl") {
            std::string_view name = t.rest();
            auto it = material_ids.find(name);
            material = it == material_ids.end() ? 0 : it->second;
            if (material == 0 && !name.empty() && warned_materials.size() < 10'000 &&
                warned_materials.emplace(std::string(name), 0).second)
                warn.add(located(
                    file, line_number,
                    fmt::format("unknown material '{}'; using the default material", name)));
        } else if (kw == "o" || kw == "g") {
            std::string_view name = t.rest();
            if (!name.empty() && scene.objects.size() >= kMaxIndexable &&
                !object_ids.contains(std::string(name)))
                check_indexable(parse, scene.objects.size() + 1, "objects ('o' and 'g')");
            object = name.empty() ? 0 : intern(object_ids, scene.objects, name);
            grew(parse);
        } else if (kw == "mtllib") {
            if (!options.load_materials) return;
            for (const std::string& name : library_names(t.rest())) {
                std::filesystem::path library = (path.parent_path() / name).lexically_normal();
                // Each library once: "mtllib a.mtl a.mtl ..." must not read a.mtl again and again.
                if (!libraries.emplace(library.string(), true).second) continue;
                Warnings library_warnings;
                load_mtl_library(library, scene.materials, library_warnings, file, line_number);
                for (std::string& w : library_warnings) warn.add(std::move(w));
                check_indexable(parse, scene.materials.size(), "materials");
                check_estimate(parse);
            }
            index_materials();
        } else if (kw == "c") {
            scene.camera = read_camera(parse, t, scene);
        } else if (!is_ignored_statement(kw) && warned_statements.size() < 10'000 &&
                   warned_statements.emplace(std::string(kw), 0).second) {
            warn.add(located(file, line_number, fmt::format("unknown statement '{}' ignored", kw)));
        }
    };

    // The common statements in their plain form, straight from the padded zone of the text
    // (obj_fast_path.h); lines past it and any other form go the general way. A line longer
    // than the limit also goes the general way, which reports it.
    const char* const padded_end = padded_zone_end(text);
    Corner face[kMaxFastCorners];
    refresh_headroom();
    std::string_view line;
    std::size_t line_number = 0;
    for (;;) {
        const char* begin = reader.cursor();
        if (begin < padded_end) {
            auto within_limit = [&](const char* next) {
                return next && static_cast<std::uint64_t>(next - begin) <= reader.max_line();
            };
            float f[3];
            const char* next;
            if (begin[0] == 'f') {
                std::size_t count = 0;
                if (is_blank(begin[1]) &&
                    within_limit(
                        next = read_face_line(
                            begin + 1, padded_end,
                            {scene.positions.size(), scene.texcoords.size(), scene.normals.size()},
                            face, count))) {
                    const std::size_t n = reader.consumed_line(next);
                    if (count - 2 <= headroom) [[likely]] {
                        headroom -= count - 2;
                        if (count == 3)
                            scene.add_triangle({face[0].v, face[1].v, face[2].v}, material, object,
                                               {face[0].n, face[1].n, face[2].n},
                                               {face[0].t, face[1].t, face[2].t});
                        else append_fan(scene, face, count, material, object);
                    } else {
                        add_face(LineParser(file, n), n, {face, count});
                        refresh_headroom();
                    }
                    continue;
                }
            } else if (begin[0] == 'v') {
                if (is_blank(begin[1])) {
                    if (within_limit(next = read_numbers_line(begin + 1, padded_end, f, 3))) {
                        add_vertex(scene.positions, Vec3f{f[0], f[1], f[2]}, nonfinite_position,
                                   reader.consumed_line(next), adding_position);
                        continue;
                    }
                } else if (begin[1] == 'n' && is_blank(begin[2])) {
                    if (within_limit(next = read_numbers_line(begin + 2, padded_end, f, 3))) {
                        add_vertex(scene.normals, Vec3f{f[0], f[1], f[2]}, nonfinite_normal,
                                   reader.consumed_line(next), adding_normal);
                        continue;
                    }
                } else if (begin[1] == 't' && is_blank(begin[2])) {
                    if (within_limit(next = read_numbers_line(begin + 2, padded_end, f, 2))) {
                        add_vertex(scene.texcoords, Vec2f{f[0], f[1]}, nonfinite_texcoord,
                                   reader.consumed_line(next), adding_texcoord);
                        continue;
                    }
                }
            }
        }

        // Everything else: the general path.
        if (!reader.next(line, line_number)) break;
        read_statement(line, line_number);
        refresh_headroom();
    }
    check_estimate(LineParser(file, 0));
}

void load_obj(const std::filesystem::path& path, Scene& scene, Warnings& warnings,
              const ObjOptions& options) {
    std::string text = read_file(path, options.limits.max_input_bytes);
    // An empty file is a failed download or export, not a scene.
    if (text.find_first_not_of(" \t\r\n\f\v") == std::string::npos)
        throw Error(located(
            path.string(), 0,
            text.empty() ? "empty file: no OBJ statements" : "blank file: no OBJ statements"));
    parse_obj(text, path, scene, warnings, options);
}

}  // namespace toonray
