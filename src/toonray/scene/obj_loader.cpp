#include "toonray/scene/obj_loader.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <charconv>
#include <cstring>
#include <fmt/format.h>
#include <memory>
#include <span>
#include <string>
#include <unordered_map>

#include "toonray/core/parallel.h"
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

// The line ends of a text, counted 16 bytes at a time, and whether it holds a NUL byte
// (refuse_binary), found in the same pass.
struct TextCounts {
    std::uint64_t line_ends = 0;
    bool nul = false;
};

TextCounts count_line_ends(const char* s, std::size_t size) {
    TextCounts counts;
    const __m128i newline = _mm_set1_epi8('\n'), zero = _mm_setzero_si128();
    __m128i nul = zero;
    std::size_t i = 0;
    for (; i + 16 <= size; i += 16) {
        const __m128i chars = _mm_loadu_si128(reinterpret_cast<const __m128i*>(s + i));
        nul = _mm_or_si128(nul, _mm_cmpeq_epi8(chars, zero));
        counts.line_ends += static_cast<unsigned>(std::popcount(
            static_cast<unsigned>(_mm_movemask_epi8(_mm_cmpeq_epi8(chars, newline)))));
    }
    counts.nul = _mm_movemask_epi8(nul) != 0;
    for (; i < size; ++i) {
        counts.line_ends += s[i] == '\n';
        counts.nul = counts.nul || s[i] == '\0';
    }
    return counts;
}

// The same for the whole text, in blocks of 1 MiB on the threads there are when it is larger
// than a few: memory, not the count, is what takes time.
TextCounts count_line_ends(std::string_view text, int threads) {
    constexpr std::size_t kBlock = 1 << 20;
    if (threads == 1 || text.size() < 4 * kBlock) return count_line_ends(text.data(), text.size());
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, text.size(), kBlock), TextCounts{},
        [&](const tbb::blocked_range<std::size_t>& r, TextCounts counts) {
            const TextCounts block = count_line_ends(text.data() + r.begin(), r.size());
            return TextCounts{counts.line_ends + block.line_ends, counts.nul || block.nul};
        },
        [](const TextCounts& a, const TextCounts& b) {
            return TextCounts{a.line_ends + b.line_ends, a.nul || b.nul};
        });
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

/// A chunk of the padded zone read ahead by another thread (read_ahead), for ObjReader::merge:
/// its plain v, vn, vt and f lines as elements in order, face indices 0-based and not yet
/// checked against what is defined (the need_* counts say what the merge must have; relative
/// ones are not read ahead), and marks where the other lines are, which the merge reads the
/// general way in their place.
struct Chunk {
    /// Where a line is, and how many elements of each kind come before it in the chunk.
    struct Mark {
        const char* line = nullptr;
        std::size_t lines = 0;  ///< physical lines before it in the chunk
        std::size_t positions = 0, normals = 0, texcoords = 0, triangles = 0;
        bool polygons = false;  ///< a face of more than 3 corners since the previous mark
    };

    const char* begin = nullptr;
    const char* end = nullptr;
    std::vector<Vec3f> positions, normals;
    std::vector<Vec2f> texcoords;
    std::vector<std::array<std::uint32_t, 3>> tri_positions, tri_normals, tri_texcoords;
    std::vector<Mark> others;  ///< the lines left to the general path
    Mark stop;  ///< where reading ahead stopped: `end`, a continued line, a relative index
    /// The most elements of each kind that must be defined before the chunk: each face index
    /// minus the elements of its kind the chunk defines before it.
    std::int64_t need_positions = 0, need_texcoords = 0, need_normals = 0;
    bool failed = false;  ///< out of memory while reading ahead: the merge reads it instead

    enum State : int { kUnclaimed, kReading, kRead, kMain };
    std::atomic<int> state{kUnclaimed};

    /// Frees the elements once merged (the chunk itself stays: other threads may look at its
    /// state).
    void release() {
        std::vector<Vec3f>().swap(positions);
        std::vector<Vec3f>().swap(normals);
        std::vector<Vec2f>().swap(texcoords);
        std::vector<std::array<std::uint32_t, 3>>().swap(tri_positions);
        std::vector<std::array<std::uint32_t, 3>>().swap(tri_normals);
        std::vector<std::array<std::uint32_t, 3>>().swap(tri_texcoords);
    }
};

/// Reads a chunk ahead (Chunk), from any thread: no messages, no limits, no scene. Lines that
/// end in a continuation stop it (a logical line may run into the next chunk).
void read_ahead(Chunk& chunk, const char* padded_end, std::uint64_t max_line) {
    chunk.positions.reserve(static_cast<std::size_t>(chunk.end - chunk.begin) / 32);
    chunk.tri_positions.reserve(static_cast<std::size_t>(chunk.end - chunk.begin) / 32);
    Chunk::Mark here{chunk.begin};
    auto at = [&](const char* line) {
        here.line = line;
        here.positions = chunk.positions.size();
        here.normals = chunk.normals.size();
        here.texcoords = chunk.texcoords.size();
        here.triangles = chunk.tri_positions.size();
        return here;
    };
    // Indices as written: no relative ones, resolved against more than can be defined.
    const Defined unchecked{kMaxIndexable, kMaxIndexable, kMaxIndexable, false};
    auto need = [](std::int64_t& most, std::uint32_t index, std::size_t defined) {
        if (index != kNoIndex)
            most = std::max(
                most, static_cast<std::int64_t>(index) + 1 - static_cast<std::int64_t>(defined));
    };
    Corner face[kMaxFastCorners];
    const char* p = chunk.begin;
    while (p < chunk.end) {
        const char* next = nullptr;
        float f[3];
        if (p[0] == 'f' && is_blank(p[1])) {
            std::size_t count = 0;
            if ((next = read_face_line(p + 1, padded_end, unchecked, face, count))) {
                for (std::size_t i = 0; i < count; ++i) {
                    need(chunk.need_positions, face[i].v, chunk.positions.size());
                    need(chunk.need_texcoords, face[i].t, chunk.texcoords.size());
                    need(chunk.need_normals, face[i].n, chunk.normals.size());
                }
                for (std::size_t i = 1; i + 1 < count; ++i) {
                    chunk.tri_positions.push_back({face[0].v, face[i].v, face[i + 1].v});
                    chunk.tri_normals.push_back({face[0].n, face[i].n, face[i + 1].n});
                    chunk.tri_texcoords.push_back({face[0].t, face[i].t, face[i + 1].t});
                }
                here.polygons = here.polygons || count > 3;
            }
        } else if (p[0] == 'v') {
            if (is_blank(p[1])) {
                if ((next = read_numbers_line(p + 1, padded_end, f, 3)))
                    chunk.positions.push_back({f[0], f[1], f[2]});
            } else if (p[1] == 'n' && is_blank(p[2])) {
                if ((next = read_numbers_line(p + 2, padded_end, f, 3)))
                    chunk.normals.push_back({f[0], f[1], f[2]});
            } else if (p[1] == 't' && is_blank(p[2])) {
                if ((next = read_numbers_line(p + 2, padded_end, f, 2)))
                    chunk.texcoords.push_back({f[0], f[1]});
            }
        }
        if (next && static_cast<std::uint64_t>(next - p) <= max_line) {
            p = next;
            ++here.lines;
            continue;
        }
        // Any other line. One continued with `\` goes on into the next (LineReader: unless a
        // comment, '#' after blanks): reading ahead stops there; so it does at a face with a
        // relative index, which the fast path reads here but the general path would in the
        // merge (a file that has one likely has them all). Lines with no statement (only
        // spaces, or a '#' after them: Tokens) mean nothing; the rest is the general path's.
        const char* last = p;
        while (*last != '\n' && *last != '\r') ++last;
        next = last + 1 + (*last == '\r' && last[1] == '\n');
        const std::string_view line(p, static_cast<std::size_t>(last - p));
        if (LineReader::continues(line)) break;
        if (p[0] == 'f' && line.find('-') != std::string_view::npos) break;
        if (line.size() <= max_line && Tokens(line).at_end()) {
            p = next;
            ++here.lines;
            continue;
        }
        chunk.others.push_back(at(p));
        here.polygons = false;
        p = next;
        ++here.lines;
    }
    chunk.stop = at(p);
}

/// Splits the padded zone [begin, padded_end) into chunks of about `bytes`, at line starts
/// after LF (a CR-only file is one chunk).
std::vector<std::unique_ptr<Chunk>> split(const char* begin, const char* padded_end,
                                          std::size_t bytes) {
    std::vector<std::unique_ptr<Chunk>> chunks;
    while (begin < padded_end) {
        const char* end = padded_end;
        if (static_cast<std::size_t>(padded_end - begin) > bytes) {
            const void* lf = std::memchr(begin + bytes, '\n',
                                         static_cast<std::size_t>(padded_end - begin) - bytes);
            if (lf) end = static_cast<const char*>(lf) + 1;
        }
        auto chunk = std::make_unique<Chunk>();
        chunk->begin = begin;
        chunk->end = end;
        chunks.push_back(std::move(chunk));
        begin = end;
    }
    return chunks;
}

/// One OBJ text being read into a scene: the general path, the fast path (obj_fast_path.h)
/// and the merging of chunks read ahead.
class ObjReader {
public:
    ObjReader(std::string_view text, const std::filesystem::path& path, Scene& scene,
              Warnings& warnings, const ObjOptions& options)
        : text_(text),
          path_(path),
          file_(path.string()),
          scene_(scene),
          options_(options),
          lim_(options.limits),
          reader_(text, file_, lim_.max_line_bytes),
          warn_(warnings, file_),
          max_vertices_(std::min(lim_.max_vertices, kMaxIndexable)),
          max_triangles_(std::min(lim_.max_triangles, kMaxIndexable)),
          padded_end_(padded_zone_end(text)) {
        corners_.reserve(16);
        refresh_headroom();
    }

    /// Reads the whole text: the padded zone in chunks of about `chunk_bytes` with up to
    /// `threads` threads (0: all chunks read ahead on this one first, for tests), the rest
    /// serially.
    void read(std::size_t chunk_bytes, int threads);

private:
    void read_until(const char* limit);
    void read_in_chunks(std::size_t chunk_bytes, int threads);
    void merge(Chunk& chunk);
    bool append(const Chunk& chunk, const Chunk::Mark& from, const Chunk::Mark& to);
    void read_statement(std::string_view line, std::size_t line_number);

    void index_materials() {
        material_ids_.clear();
        for (std::size_t i = 1; i < scene_.materials.size(); ++i)
            material_ids_[scene_.materials[i].name] = static_cast<std::uint32_t>(i);
    }

    // Non-finite coordinates (nan, inf), which other tools read: the vertex is kept (as 0, so
    // every stored number stays finite) so indices stay right, and faces that use it are
    // dropped (a non-finite normal or texture coordinate only takes the face's normals or
    // texture coordinates). The flags exist only once such a value was read, so clean files
    // pay one predictable branch per face.
    void mark_nonfinite(std::vector<std::uint8_t>& flags, std::size_t count, bool finite,
                        std::size_t line, std::string_view what) {
        if (finite && nonfinite_count_ == 0) return;
        flags.resize(count, 0);
        if (finite) return;
        flags.back() = 1;
        ++nonfinite_count_;
        warn_.add(
            located(file_, line,
                    fmt::format("non-finite coordinate in '{}'; the faces that use it {}", what,
                                what == "v" ? "are dropped"
                                            : (what == "vn" ? "use their geometric normals"
                                                            : "have no texture coordinates"))));
    }
    // After the fast path added a finite element: keeps the flags in step once they exist.
    void keep_flags(std::vector<std::uint8_t>& flags, std::size_t count) const {
        if (nonfinite_count_ != 0) [[unlikely]]
            flags.resize(count, 0);
    }
    static bool flagged(const std::vector<std::uint8_t>& flags, std::uint32_t i) {
        return i != kNoIndex && i < flags.size() && flags[i] != 0;
    }
    // False when the face must be dropped; clears non-finite normals and texture coordinates.
    bool usable_face(std::size_t line, std::span<Corner> face) {
        bool normals_ok = true, texcoords_ok = true;
        for (const Corner& c : face) {
            if (flagged(nonfinite_position_, c.v)) {
                warn_.add(located(file_, line,
                                  "face uses a vertex with a non-finite coordinate; dropped"));
                return false;
            }
            normals_ok = normals_ok && !flagged(nonfinite_normal_, c.n);
            texcoords_ok = texcoords_ok && !flagged(nonfinite_texcoord_, c.t);
        }
        for (Corner& c : face) {
            if (!normals_ok) c.n = kNoIndex;
            if (!texcoords_ok) c.t = kNoIndex;
        }
        return true;
    }

    // Memory: the text, the scene, its BVH, times the scenes loaded at once, plus what the
    // caller has committed elsewhere (frame buffers); with `vertices` and `triangles` more.
    std::uint64_t estimate(std::uint64_t vertices = 0, std::uint64_t triangles = 0) const {
        vertices += scene_.positions.size() + scene_.normals.size() + scene_.texcoords.size();
        triangles += scene_.triangle_count();
        const std::uint64_t names = scene_.objects.size() + scene_.materials.size();
        return lim_.reserved_memory + text_.size() +
               std::max<std::uint64_t>(lim_.scenes_in_flight, 1) *
                   (scene_bytes(vertices, triangles) + names * kNamedBytes);
    }
    void check_estimate(const LineParser& parse) const {
        const std::uint64_t bytes = estimate();
        if (bytes > lim_.max_memory)
            parse.fail_limit(
                Limit::Memory,
                fmt::format(
                    "the scene so far ({} vertices, {} triangles) needs about {} of memory, "
                    "more than the limit of {}",
                    scene_.positions.size(), scene_.triangle_count(), format_bytes(bytes),
                    format_bytes(lim_.max_memory)));
    }
    std::uint64_t elements() const {
        return scene_.positions.size() + scene_.normals.size() + scene_.texcoords.size() +
               scene_.triangle_count() + scene_.objects.size();
    }
    void grew(const LineParser& parse) {
        if (memory_.due(elements())) check_estimate(parse);
    }

    // What both paths do before adding an element (so a limit names the line that exceeds it),
    // and a face's triangles.
    void adding_position(const LineParser& parse) {
        check_count(parse, scene_.positions.size() + 1, max_vertices_, "vertices ('v')",
                    Limit::Vertices);
        grew(parse);
    }
    void adding_normal(const LineParser& parse) {
        check_count(parse, scene_.normals.size() + 1, max_vertices_, "normals ('vn')",
                    Limit::Vertices);
        grew(parse);
    }
    void adding_texcoord(const LineParser& parse) {
        check_count(parse, scene_.texcoords.size() + 1, max_vertices_, "texture coordinates ('vt')",
                    Limit::Vertices);
        grew(parse);
    }
    void add_face(const LineParser& parse, std::size_t line, std::span<Corner> face) {
        if (nonfinite_count_ != 0 && !usable_face(line, face)) [[unlikely]]
            return;
        if (scene_.triangle_count() + (face.size() - 2) > max_triangles_)
            parse.fail_limit(Limit::Triangles,
                             fmt::format("more than {} triangles (the limit)", max_triangles_));
        grew(parse);
        append_fan(scene_, face.data(), face.size(), material_, object_);
    }

    // The fast path skips those checks while `headroom_` lasts: how many vertices or triangles
    // can be added before a count could pass its limit or the memory estimate is due. Each
    // element takes it down by what it adds; at 0 (and always once a non-finite value was
    // read, whose flags must be kept) an element takes the checked way, which does exactly
    // what the general path does.
    void refresh_headroom() {
        headroom_ = nonfinite_count_ != 0 ? 0
                                          : std::min({max_vertices_ - scene_.positions.size(),
                                                      max_vertices_ - scene_.normals.size(),
                                                      max_vertices_ - scene_.texcoords.size(),
                                                      max_triangles_ - scene_.triangle_count(),
                                                      memory_.until_due(elements())});
    }
    // A plain v, vn or vt line read by the fast path.
    template <typename T, typename Adding>
    void add_vertex(std::vector<T>& values, const T& value, std::vector<std::uint8_t>& flags,
                    std::size_t line, Adding adding) {
        if (headroom_ != 0) [[likely]] {
            --headroom_;
            values.push_back(value);
            return;
        }
        (this->*adding)(LineParser(file_, line));
        values.push_back(value);
        keep_flags(flags, values.size());
        refresh_headroom();
    }

    std::string_view text_;
    const std::filesystem::path& path_;
    const std::string file_;
    Scene& scene_;
    const ObjOptions& options_;
    const Limits& lim_;
    LineReader reader_;
    WarningSink warn_;
    const std::uint64_t max_vertices_, max_triangles_;
    const char* const padded_end_;

    std::unordered_map<std::string, std::uint32_t> object_ids_{{"(default)", 0}};
    std::unordered_map<std::string, std::uint32_t> warned_materials_, warned_statements_;
    // Material names to indices, rebuilt after each mtllib (the last definition of a name wins).
    std::unordered_map<std::string_view, std::uint32_t> material_ids_;
    std::unordered_map<std::string, bool> libraries_;  // each MTL file is read once
    std::uint32_t material_ = 0, object_ = 0;
    bool warned_points_ = false;
    std::vector<Corner> corners_;
    std::size_t nonfinite_count_ = 0;
    std::vector<std::uint8_t> nonfinite_position_, nonfinite_normal_, nonfinite_texcoord_;
    MemoryCheck memory_;
    std::uint64_t headroom_ = 0;
};

void ObjReader::read_statement(std::string_view line, std::size_t line_number) {
    Tokens t(line);
    if (t.at_end()) return;
    std::string_view kw = t.next();
    LineParser parse(file_, line_number);

    if (kw == "v") {
        adding_position(parse);
        bool finite = true;
        const Vec3f position = parse.coordinates3(t, kw, finite);
        scene_.positions.push_back(finite ? position : Vec3f(0.0f));
        // Optional w (or vertex colour) values are accepted and ignored, but must be numbers.
        while (!t.at_end()) parse.number(t, kw);
        mark_nonfinite(nonfinite_position_, scene_.positions.size(), finite, line_number, kw);
    } else if (kw == "f") {
        if (read_face_corners(parse, t, scene_, corners_, [&](std::string message) {
                warn_.add(located(file_, line_number, message));
            }))
            add_face(parse, line_number, corners_);
    } else if (kw == "vn") {
        adding_normal(parse);
        bool finite = true;
        const Vec3f normal = parse.coordinates3(t, kw, finite);
        scene_.normals.push_back(finite ? normal : Vec3f(0.0f));
        mark_nonfinite(nonfinite_normal_, scene_.normals.size(), finite, line_number, kw);
    } else if (kw == "vt") {
        adding_texcoord(parse);
        bool finite = true;
        Vec2f uv;
        uv.x = parse.coordinate(t, kw, finite);
        if (!t.at_end()) uv.y = parse.coordinate(t, kw, finite);
        if (!t.at_end()) parse.number(t, kw);
        scene_.texcoords.push_back(finite ? uv : Vec2f{});
        mark_nonfinite(nonfinite_texcoord_, scene_.texcoords.size(), finite, line_number, kw);
    } else if (kw == "l") {
        Polyline polyline;
        polyline.first = static_cast<std::uint32_t>(scene_.polyline_points.size());
        read_polyline(parse, t, scene_, scene_.polyline_points);
        polyline.count = static_cast<std::uint32_t>(scene_.polyline_points.size() - polyline.first);
        check_count(parse, scene_.polyline_points.size(), max_vertices_, "polyline points ('l')",
                    Limit::Vertices);
        grew(parse);
        polyline.material = material_;
        polyline.object = object_;
        bool finite = true;
        for (std::uint32_t i = polyline.first; i < polyline.first + polyline.count; ++i)
            finite = finite && !flagged(nonfinite_position_, scene_.polyline_points[i]);
        if (finite) {
            scene_.polylines.push_back(polyline);
        } else {
            scene_.polyline_points.resize(polyline.first);
            warn_.add(located(file_, line_number,
                              "line uses a vertex with a non-finite coordinate; dropped"));
        }
    } else if (kw == "p") {
        if (!warned_points_) {
            warned_points_ = true;
            warn_.add(located(file_, line_number,
                              "point elements ('p') are not drawn; ignored (this warning is "
                              "given once a file)"));
        }
    } else if (kw == "usemtl") {
        std::string_view name = t.rest();
        auto it = material_ids_.find(name);
        material_ = it == material_ids_.end() ? 0 : it->second;
        if (material_ == 0 && !name.empty() && warned_materials_.size() < 10'000 &&
            warned_materials_.emplace(std::string(name), 0).second)
            warn_.add(
                located(file_, line_number,
                        fmt::format("unknown material '{}'; using the default material", name)));
    } else if (kw == "o" || kw == "g") {
        std::string_view name = t.rest();
        if (!name.empty() && scene_.objects.size() >= kMaxIndexable &&
            !object_ids_.contains(std::string(name)))
            check_indexable(parse, scene_.objects.size() + 1, "objects ('o' and 'g')");
        object_ = name.empty() ? 0 : intern(object_ids_, scene_.objects, name);
        grew(parse);
    } else if (kw == "mtllib") {
        if (!options_.load_materials) return;
        for (const std::string& name : library_names(t.rest())) {
            std::filesystem::path library = (path_.parent_path() / name).lexically_normal();
            // Each library once: "mtllib a.mtl a.mtl ..." must not read a.mtl again and again.
            if (!libraries_.emplace(library.string(), true).second) continue;
            Warnings library_warnings;
            load_mtl_library(library, scene_.materials, library_warnings, file_, line_number);
            for (std::string& w : library_warnings) warn_.add(std::move(w));
            check_indexable(parse, scene_.materials.size(), "materials");
            check_estimate(parse);
        }
        index_materials();
    } else if (kw == "c") {
        scene_.camera = read_camera(parse, t, scene_);
    } else if (!is_ignored_statement(kw) && warned_statements_.size() < 10'000 &&
               warned_statements_.emplace(std::string(kw), 0).second) {
        warn_.add(located(file_, line_number, fmt::format("unknown statement '{}' ignored", kw)));
    }
}

void ObjReader::read_until(const char* limit) {
    Corner face[kMaxFastCorners];
    std::string_view line;
    std::size_t line_number = 0;
    for (;;) {
        // The common statements in their plain form, straight from the padded zone of the text
        // (obj_fast_path.h); lines past it and any other form go the general way. A line longer
        // than the limit also goes the general way, which reports it.
        const char* begin = reader_.cursor();
        if (begin >= limit) return;
        if (begin < padded_end_) {
            auto within_limit = [&](const char* next) {
                return next && static_cast<std::uint64_t>(next - begin) <= reader_.max_line();
            };
            float f[3];
            const char* next;
            if (begin[0] == 'f') {
                std::size_t count = 0;
                if (is_blank(begin[1]) &&
                    within_limit(
                        next = read_face_line(begin + 1, padded_end_,
                                              {scene_.positions.size(), scene_.texcoords.size(),
                                               scene_.normals.size(), true},
                                              face, count))) {
                    const std::size_t n = reader_.consumed_line(next);
                    if (count - 2 <= headroom_) [[likely]] {
                        headroom_ -= count - 2;
                        if (count == 3)
                            scene_.add_triangle({face[0].v, face[1].v, face[2].v}, material_,
                                                object_, {face[0].n, face[1].n, face[2].n},
                                                {face[0].t, face[1].t, face[2].t});
                        else append_fan(scene_, face, count, material_, object_);
                    } else {
                        add_face(LineParser(file_, n), n, {face, count});
                        refresh_headroom();
                    }
                    continue;
                }
            } else if (begin[0] == 'v') {
                if (is_blank(begin[1])) {
                    if (within_limit(next = read_numbers_line(begin + 1, padded_end_, f, 3))) {
                        add_vertex(scene_.positions, Vec3f{f[0], f[1], f[2]}, nonfinite_position_,
                                   reader_.consumed_line(next), &ObjReader::adding_position);
                        continue;
                    }
                } else if (begin[1] == 'n' && is_blank(begin[2])) {
                    if (within_limit(next = read_numbers_line(begin + 2, padded_end_, f, 3))) {
                        add_vertex(scene_.normals, Vec3f{f[0], f[1], f[2]}, nonfinite_normal_,
                                   reader_.consumed_line(next), &ObjReader::adding_normal);
                        continue;
                    }
                } else if (begin[1] == 't' && is_blank(begin[2])) {
                    if (within_limit(next = read_numbers_line(begin + 2, padded_end_, f, 2))) {
                        add_vertex(scene_.texcoords, Vec2f{f[0], f[1]}, nonfinite_texcoord_,
                                   reader_.consumed_line(next), &ObjReader::adding_texcoord);
                        continue;
                    }
                }
            }
        }

        // Everything else: the general path.
        if (!reader_.next(line, line_number)) return;
        read_statement(line, line_number);
        refresh_headroom();
    }
}

// Appends the elements a chunk read between two marks, as the fast path would have added them
// one by one. False, having changed nothing, when that would pass a limit, or when the memory
// estimate is due among them and then too much or not to be emulated (polygons): the caller
// then reads the lines from `from` itself.
bool ObjReader::append(const Chunk& chunk, const Chunk::Mark& from, const Chunk::Mark& to) {
    const std::size_t positions = to.positions - from.positions,
                      normals = to.normals - from.normals,
                      texcoords = to.texcoords - from.texcoords,
                      triangles = to.triangles - from.triangles;
    const std::uint64_t added = positions + normals + texcoords + triangles;
    const bool checked = added > headroom_;
    if (checked) {
        if (scene_.positions.size() + positions > max_vertices_ ||
            scene_.normals.size() + normals > max_vertices_ ||
            scene_.texcoords.size() + texcoords > max_vertices_ ||
            scene_.triangle_count() + triangles > max_triangles_)
            return false;
        // The estimate grows with the scene: within the limit at the end, it is within it
        // wherever it falls due among these elements. One element at a time (each adds one to
        // the count the check goes by) its pace can be emulated (MemoryCheck::skip).
        if (memory_.until_due(elements()) < added &&
            (to.polygons || estimate(positions + normals + texcoords, triangles) > lim_.max_memory))
            return false;
        memory_.skip(elements(), added);
    } else {
        headroom_ -= added;
    }
    auto copy = [](auto& into, const auto& from_chunk, std::size_t first, std::size_t count) {
        into.insert(into.end(), from_chunk.begin() + static_cast<std::ptrdiff_t>(first),
                    from_chunk.begin() + static_cast<std::ptrdiff_t>(first + count));
    };
    copy(scene_.positions, chunk.positions, from.positions, positions);
    copy(scene_.normals, chunk.normals, from.normals, normals);
    copy(scene_.texcoords, chunk.texcoords, from.texcoords, texcoords);
    copy(scene_.tri_positions, chunk.tri_positions, from.triangles, triangles);
    copy(scene_.tri_normals, chunk.tri_normals, from.triangles, triangles);
    copy(scene_.tri_texcoords, chunk.tri_texcoords, from.triangles, triangles);
    scene_.tri_material.insert(scene_.tri_material.end(), triangles, material_);
    scene_.tri_object.insert(scene_.tri_object.end(), triangles, object_);
    reader_.skip_lines(to.line, to.lines - from.lines);
    if (checked) refresh_headroom();
    return true;
}

// A chunk read ahead, added to the scene as reading its lines here would have: its elements
// in runs between the other lines, which are read here in their place. Whatever the chunk
// cannot vouch for is read here instead, from the first line concerned: a chunk that does not
// start where reading is (a line continued into it), face indices that need more elements
// than are defined (an error or a warning to give), non-finite values read before, limits.
void ObjReader::merge(Chunk& chunk) {
    if (chunk.failed || reader_.cursor() != chunk.begin || nonfinite_count_ != 0 ||
        chunk.need_positions > static_cast<std::int64_t>(scene_.positions.size()) ||
        chunk.need_texcoords > static_cast<std::int64_t>(scene_.texcoords.size()) ||
        chunk.need_normals > static_cast<std::int64_t>(scene_.normals.size()))
        return read_until(chunk.end);
    Chunk::Mark from{chunk.begin};
    std::string_view line;
    std::size_t line_number = 0;
    for (const Chunk::Mark& other : chunk.others) {
        if (!append(chunk, from, other)) return read_until(chunk.end);
        reader_.next(line, line_number);
        read_statement(line, line_number);
        refresh_headroom();
        if (nonfinite_count_ != 0) return read_until(chunk.end);
        from = other;
        from.line = reader_.cursor();
        ++from.lines;
    }
    if (!append(chunk, from, chunk.stop)) return read_until(chunk.end);
    read_until(chunk.end);  // from a continued line on, if reading ahead stopped there
}

void ObjReader::read_in_chunks(std::size_t chunk_bytes, int threads) {
    std::vector<std::unique_ptr<Chunk>> chunks = split(reader_.cursor(), padded_end_, chunk_bytes);
    if (chunks.size() < 2) return;
    const std::uint64_t max_line = reader_.max_line();
    // Other threads read chunks ahead from the last one back, while this one reads from the
    // first on; where they meet, this one merges what they read. So this thread never waits,
    // and one thread (or none free) simply reads it all.
    chunks[0]->state = Chunk::kMain;
    std::atomic<bool> stop{false};
    // What is read ahead is held until merged, so it never holds more elements than the
    // limits let the scene hold: a file past a limit then fails at the same line without
    // first filling the memory with what comes after that line. A chunk has at most an
    // element for every 2 bytes (a polygon's corner " 1"); what it did not use is given back.
    std::atomic<std::int64_t> budget{static_cast<std::int64_t>(
        std::min({max_vertices_, max_triangles_,
                  lim_.max_memory > estimate()
                      ? (lim_.max_memory - estimate()) /
                            (scene_bytes(1, 1) * std::max<std::uint64_t>(lim_.scenes_in_flight, 1))
                      : 0}))};
    auto read_ahead_from_the_end = [&] {
        for (std::size_t i = chunks.size(); i-- > 1 && !stop.load(std::memory_order_relaxed);) {
            Chunk& chunk = *chunks[i];
            const auto most = static_cast<std::int64_t>(chunk.end - chunk.begin) / 2 + 1;
            if (budget.fetch_sub(most) < most) {
                budget.fetch_add(most);
                return;
            }
            int state = Chunk::kUnclaimed;
            if (!chunk.state.compare_exchange_strong(state, Chunk::kReading)) {
                budget.fetch_add(most);
                if (state == Chunk::kMain) return;  // met this thread
                continue;                           // another thread's
            }
            try {
                read_ahead(chunk, padded_end_, max_line);
            } catch (...) {  // out of memory: this thread then reads it itself
                chunk.failed = true;
            }
            budget.fetch_add(most - static_cast<std::int64_t>(
                                        chunk.positions.size() + chunk.normals.size() +
                                        chunk.texcoords.size() + chunk.tri_positions.size()));
            chunk.state.store(Chunk::kRead);
        }
    };
    tbb::task_group helpers;
    struct Join {  // the helpers read the text and the chunks: they end before either does
        tbb::task_group& group;
        std::atomic<bool>& stop;
        ~Join() {
            stop = true;
            group.wait();
        }
    } join{helpers, stop};
    if (threads == 0) read_ahead_from_the_end();
    for (int i = 1; i < threads; ++i) helpers.run(read_ahead_from_the_end);
    for (std::unique_ptr<Chunk>& chunk : chunks) {
        int state = Chunk::kUnclaimed;
        // A chunk still being read ahead is read here too, rather than waited for: that costs
        // at most a chunk's reading, and never waits on a thread the machine has put aside.
        if (chunk->state.load() == Chunk::kMain ||
            chunk->state.compare_exchange_strong(state, Chunk::kMain) || state == Chunk::kReading) {
            read_until(chunk->end);
            continue;
        }
        merge(*chunk);
        chunk->release();
    }
}

void ObjReader::read(std::size_t chunk_bytes, int threads) {
    if (threads != 1 &&
        padded_end_ - reader_.cursor() >= 2 * static_cast<std::ptrdiff_t>(chunk_bytes))
        read_in_chunks(chunk_bytes, threads);
    read_until(text_.data() + text_.size());
    check_estimate(LineParser(file_, 0));
}

}  // namespace

namespace wavefront {

void parse_obj_in_chunks(std::string_view text, const std::filesystem::path& path, Scene& scene,
                         Warnings& warnings, const ObjOptions& options, std::size_t chunk_bytes,
                         int threads) {
    scene.clear();
    const TextCounts counts = count_line_ends(text, threads);
    if (counts.nul) refuse_binary(text, path.string(), "an OBJ");
    reserve_for(counts.line_ends + 1, scene, options.limits);
    ObjReader(text, path, scene, warnings, options).read(chunk_bytes, threads);
}

}  // namespace wavefront

void parse_obj(std::string_view text, const std::filesystem::path& path, Scene& scene,
               Warnings& warnings, const ObjOptions& options) {
    // Chunks of a sixteenth of the text per thread, at least 64 KiB: enough for the threads to
    // meet near the middle, few enough that each is worth a thread's start.
    const int threads = hardware_threads();
    const std::size_t chunk_bytes =
        std::max<std::size_t>(64 * 1024, text.size() / (16 * static_cast<std::size_t>(threads)));
    wavefront::parse_obj_in_chunks(text, path, scene, warnings, options, chunk_bytes, threads);
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
