#include "toonray/scene/obj_loader.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fmt/format.h>
#include <string>
#include <unordered_map>

#include "toonray/io/file.h"

namespace toonray {
namespace {

/// Splits text into logical lines: a line ends at LF, CRLF or a lone CR (old Mac files; as
/// tinyobjloader reads them), lines ending in a backslash are joined, and physical lines are
/// counted for messages. Comments are left to the callers ('#' starts one).
/// parse_obj reads its common statements straight from the text (cursor(), consumed_line());
/// everything else goes through next().
class LineReader {
public:
    LineReader(std::string_view text, std::string_view file, std::uint64_t max_line)
        : text_(text), file_(file), max_line_(max_line) {
        if (text_.size() >= 3 && std::memcmp(text_.data(), "\xEF\xBB\xBF", 3) == 0)
            text_.remove_prefix(3);
    }

    /// Next logical line, or false at the end. `line_number` is the physical line it starts on.
    bool next(std::string_view& line, std::size_t& line_number) {
        if (pos_ >= text_.size()) return false;
        line_number = ++physical_;
        std::string_view piece = take_physical();
        // A comment is a whole line: "# C:\models\" must not swallow the next line.
        if (!ends_with_backslash(piece) || is_comment(piece)) {
            line = piece;
            return true;
        }
        joined_.assign(piece.data(), piece.size() - 1);
        while (pos_ < text_.size()) {
            ++physical_;
            piece = take_physical();
            if (joined_.size() + 1 + piece.size() > max_line_) too_long(line_number, true);
            joined_.push_back(' ');
            if (ends_with_backslash(piece)) {
                joined_.append(piece.data(), piece.size() - 1);
            } else {
                joined_.append(piece.data(), piece.size());
                break;
            }
        }
        line = joined_;
        return true;
    }

    /// The unread text, for a caller that reads a line itself.
    const char* cursor() const { return text_.data() + pos_; }
    const char* end() const { return text_.data() + text_.size(); }
    std::uint64_t max_line() const { return max_line_; }
    /// Marks one physical line, read by the caller, as consumed; `next_line` is where the next
    /// one starts. Returns its line number.
    std::size_t consumed_line(const char* next_line) {
        pos_ = static_cast<std::size_t>(next_line - text_.data());
        return ++physical_;
    }

private:
    static bool ends_with_backslash(std::string_view s) { return !s.empty() && s.back() == '\\'; }
    static bool is_comment(std::string_view s) {
        std::size_t i = s.find_first_not_of(" \t");
        return i != std::string_view::npos && s[i] == '#';
    }

    std::string_view take_physical() {
        const char* begin = text_.data() + pos_;
        const char* end = text_.data() + text_.size();
        const char* p = begin;
        while (p < end && *p != '\n' && *p != '\r') ++p;
        const std::size_t len = static_cast<std::size_t>(p - begin);
        if (len > max_line_) too_long(physical_, false);
        if (p < end && *p++ == '\r' && p < end && *p == '\n') ++p;  // CRLF is one line end
        pos_ = static_cast<std::size_t>(p - text_.data());
        return {begin, len};
    }

    [[noreturn]] void too_long(std::size_t line, bool joined) const {
        throw_at(file_, line,
                 fmt::format("line{} longer than the limit of {}", joined ? " (with its continuations)" : "",
                             format_bytes(max_line_)));
    }

    std::string_view text_;
    std::string_view file_;
    std::uint64_t max_line_;
    std::size_t pos_ = 0;
    std::size_t physical_ = 0;
    std::string joined_;
};

inline bool is_digit(char c) { return static_cast<unsigned char>(c - '0') < 10; }
inline bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

/// Cursor over one line's whitespace-separated tokens.
struct Tokens {
    const char* p;
    const char* end;

    explicit Tokens(std::string_view line) : p(line.data()), end(line.data() + line.size()) {}
    void skip_space() {
        while (p < end && is_space(*p)) ++p;
    }
    bool at_end() {
        skip_space();
        return p >= end || *p == '#';
    }
    std::string_view next() {
        skip_space();
        const char* begin = p;
        while (p < end && !is_space(*p)) ++p;
        return {begin, static_cast<std::size_t>(p - begin)};
    }
    /// The rest of the line, trimmed, with a trailing comment removed. A comment starts at a
    /// '#' that begins a word: names may contain '#' ("usemtl Mat#2", as Blender writes a
    /// material of that name; tinyobjloader keeps it too), and cutting there would merge
    /// "Mat#1" and "Mat#2" into one material.
    std::string_view rest() {
        skip_space();
        const char* e = end;
        for (const char* q = p; q < end; ++q)
            if (*q == '#' && (q == p || is_space(q[-1]))) {
                e = q;
                break;
            }
        while (e > p && is_space(e[-1])) --e;
        return {p, static_cast<std::size_t>(e - p)};
    }
};

/// The common case of OBJ numbers, "[-]ddd.ddd" with up to 15 significant digits and at most
/// 15 decimals, parsed without from_chars. The mantissa m < 10^15 and 10^k are exact doubles,
/// so m / 10^k rounds once to double; rounding that to float gives the correctly rounded float
/// of the decimal because double rounding is innocuous for division when 53 >= 2 * 24 + 2
/// (Figueroa, "When is double rounding innocuous?", 1995). So the result is bit for bit what
/// from_chars<float> gives. Reads from `p` up to the first character that cannot continue the
/// number and advances `p` there; the caller checks what follows (a separator, or the end of
/// the token). Returns false, `p` unspecified, for anything else (exponents, longer numbers).
inline bool scan_short_decimal(const char*& pos, const char* e, float& out) {
    static constexpr double kPow10[16] = {1e0, 1e1, 1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                          1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15};
    const char* p = pos;  // a local cursor: the compiler keeps it in a register
    const bool negative = p < e && *p == '-';
    p += negative;
    std::uint64_t m = 0;
    std::size_t digits = 0, decimals = 0;  // size_t: a line may be longer than 2^31 bytes
    for (; p < e && is_digit(*p); ++p, ++digits) m = m * 10 + static_cast<std::uint64_t>(*p - '0');
    if (p < e && *p == '.')
        for (++p; p < e && is_digit(*p); ++p, ++decimals) m = m * 10 + static_cast<std::uint64_t>(*p - '0');
    digits += decimals;
    // Past 15 digits m may have wrapped, but then the result is not used.
    if (digits == 0 || digits > 15) return false;
    const float v = static_cast<float>(static_cast<double>(m) / kPow10[decimals]);
    out = negative ? -v : v;
    pos = p;
    return true;
}

/// A face or camera index "[+-]digits" (up to 18 digits); false when malformed.
inline bool parse_index(const char*& pos, const char* e, long long& out) {
    const char* p = pos;  // a local cursor: the compiler keeps it in a register
    bool negative = false;
    if (p < e && (*p == '-' || *p == '+')) {
        negative = *p == '-';
        ++p;
    }
    const char* start = p;
    std::uint64_t v = 0;
    for (; p < e && is_digit(*p); ++p) v = v * 10 + static_cast<std::uint64_t>(*p - '0');
    // 18 digits always fit a long long; a longer number may have wrapped, and is refused.
    if (p == start || p - start > 18) return false;
    pos = p;
    out = negative ? -static_cast<long long>(v) : static_cast<long long>(v);
    return true;
}

class Parser {
public:
    Parser(std::string_view file, std::size_t line) : file_(file), line_(line) {}

    [[noreturn]] void fail(std::string_view message) const { throw_at(file_, line_, message); }

    float number(Tokens& t, std::string_view what) const {
        std::string_view tok = t.next();
        if (tok.empty()) fail(fmt::format("missing number in '{}' statement", what));
        const char* b = tok.data();
        const char* e = b + tok.size();
        float v;
        const char* scanned = b;
        if (scan_short_decimal(scanned, e, v) && scanned == e) return v;
        if (*b == '+') ++b;
        auto [ptr, ec] = std::from_chars(b, e, v);
        if (ec == std::errc::result_out_of_range && ptr == e) {
            // Too small for a float reads as zero (as strtof and other readers do: exporters
            // that write doubles produce such values); too large is an error.
            double d;
            auto [dptr, dec] = std::from_chars(b, e, d);
            std::string_view digits(b, static_cast<std::size_t>(e - b));
            bool underflow = dec == std::errc() ? std::abs(d) < 1.0
                                                : digits.find("e-") != std::string_view::npos ||
                                                      digits.find("E-") != std::string_view::npos;
            if (!underflow) fail(fmt::format("number '{}' out of range in '{}' statement", tok, what));
            v = dec == std::errc() ? static_cast<float>(d) : 0.0f;
            ec = std::errc();
        }
        if (ec != std::errc() || ptr != e)
            fail(fmt::format("malformed number '{}' in '{}' statement", tok, what));
        if (!std::isfinite(v))
            fail(fmt::format("non-finite number '{}' in '{}' statement", tok, what));
        return v;
    }

    Vec3f vec3(Tokens& t, std::string_view what) const {
        Vec3f v;
        v.x = number(t, what);
        v.y = number(t, what);
        v.z = number(t, what);
        return v;
    }

private:
    std::string_view file_;
    std::size_t line_;
};

/// Resolves a 1-based or negative (relative) OBJ index against `count` defined so far.
/// Returns false for 0 or out-of-range indices.
inline bool resolve_index(long long idx, std::size_t count, std::uint32_t& out) {
    if (idx > 0) {
        if (static_cast<unsigned long long>(idx) > count) return false;
        out = static_cast<std::uint32_t>(idx - 1);
        return true;
    }
    if (idx < 0) {
        // -(idx + 1) cannot overflow, also for the most negative long long.
        const auto back = static_cast<unsigned long long>(-(idx + 1)) + 1;
        if (back > count) return false;
        out = static_cast<std::uint32_t>(count - back);
        return true;
    }
    return false;
}

struct Corner {
    std::uint32_t v, t, n;
};

// The fast paths below read the plain forms of the statements that make up nearly all of a
// file (v, vn, vt, f) in one pass over the text: no line splitting ahead, no tokens, no keyword
// comparisons. Each returns where the next line starts, or nullptr when the line has any other
// form (a trailing comment, a continuation, an exponent, an error, ...); it has then changed
// nothing, and the general path reads the line with its precise messages. So the fast paths
// decide only how fast a line is read, never what it means.

inline bool is_blank(char c) { return c == ' ' || c == '\t'; }

/// Skips blanks, then expects the end of the line; returns the start of the next line.
inline const char* after_line_end(const char* p, const char* end) {
    while (p < end && is_blank(*p)) ++p;
    if (p == end) return p;
    if (*p == '\n') return p + 1;
    if (*p == '\r') return p + 1 + (p + 1 < end && p[1] == '\n');
    return nullptr;
}

/// Exactly `count` short decimals (scan_short_decimal), each after blanks, then the line's end.
inline const char* read_numbers_line(const char* p, const char* end, float* out, int count) {
    for (int i = 0; i < count; ++i) {
        if (p == end || !is_blank(*p)) return nullptr;
        do ++p;
        while (p < end && is_blank(*p));
        if (!scan_short_decimal(p, end, out[i])) return nullptr;
    }
    return after_line_end(p, end);
}

/// The corners of a face, each "v", "v/t", "v//n" or "v/t/n" after blanks, resolved against the
/// vertices defined so far, into `corners`; at least 3.
inline const char* read_face_line(const char* p, const char* end, const Scene& scene,
                                  std::vector<Corner>& corners) {
    corners.clear();
    for (;;) {
        const char* before = p;
        while (p < end && is_blank(*p)) ++p;
        if (p == end || *p == '\n' || *p == '\r') break;
        if (p == before) return nullptr;  // corners are separated by blanks
        long long index;
        Corner c{0, kNoIndex, kNoIndex};
        if (!parse_index(p, end, index) || !resolve_index(index, scene.positions.size(), c.v)) return nullptr;
        if (p < end && *p == '/') {
            ++p;
            if (p < end && *p != '/' &&
                (!parse_index(p, end, index) || !resolve_index(index, scene.texcoords.size(), c.t)))
                return nullptr;
            if (p < end && *p == '/') {
                ++p;
                if (!parse_index(p, end, index) || !resolve_index(index, scene.normals.size(), c.n))
                    return nullptr;
            }
        }
        corners.push_back(c);
    }
    if (corners.size() < 3) return nullptr;
    return after_line_end(p, end);
}

std::uint32_t intern(std::unordered_map<std::string, std::uint32_t>& ids,
                     std::vector<std::string>& names, std::string_view name) {
    auto [it, inserted] = ids.try_emplace(std::string(name), static_cast<std::uint32_t>(names.size()));
    if (inserted) names.emplace_back(name);
    return it->second;
}

/// Bytes a material or an object name costs, for the memory estimate.
constexpr std::uint64_t kNamedBytes = 160;

/// Checks a count against its limit (never above what 32-bit indices can address).
void check_count(const Parser& parse, std::uint64_t count, std::uint64_t limit, std::string_view what,
                 std::string_view option) {
    limit = std::min(limit, kMaxIndexable);
    if (count > limit)
        parse.fail(fmt::format("more than {} {} (the limit{})", limit, what,
                               option.empty() ? std::string() : fmt::format("; {} raises it", option)));
}

/// Checks the memory estimate every time `count` doubles (so the cost is O(1) per element).
class MemoryCheck {
public:
    bool due(std::uint64_t count) {
        if (count < next_) return false;
        next_ = count * 2;
        return true;
    }

private:
    std::uint64_t next_ = 1 << 16;
};

void load_mtl_file(const std::filesystem::path& path, std::vector<Material>& materials,
                   Warnings& warnings, std::string_view obj_file, std::size_t obj_line) {
    std::string text;
    try {
        text = read_file(path);
    } catch (const Error& e) {
        warnings.push_back(located(obj_file, obj_line,
                                   fmt::format("cannot read material library '{}' ({}); faces "
                                               "using its materials get the default material",
                                               path.string(), e.what())));
        return;
    }
    parse_mtl(text, path, materials, warnings);
}

/// The camera block's checks, in double precision so that large values cannot overflow into a
/// camera that passes here and fails (or yields NaN rays) in the renderer. The thresholds are
/// make_view_plane's: up must be at least ~0.06 degrees away from the view direction.
void check_camera(const Parser& parse, const CameraSpec& cam) {
    const double vx = double{cam.gaze.x} - cam.eye.x, vy = double{cam.gaze.y} - cam.eye.y,
                 vz = double{cam.gaze.z} - cam.eye.z;
    const double ux = cam.up.x, uy = cam.up.y, uz = cam.up.z;
    const double view = std::sqrt(vx * vx + vy * vy + vz * vz);
    const double up = std::sqrt(ux * ux + uy * uy + uz * uz);
    if (!(view > 0)) parse.fail("invalid camera: eye and gaze point are the same point");
    // |gaze - eye| sets the field of view (2 atan(1 / |gaze - eye|)) and up is a direction:
    // beyond 1e6 neither means anything, and the renderer's float arithmetic overflows.
    if (view > 1e6)
        parse.fail(fmt::format("invalid camera: the gaze point is {:g} from the eye (at most 1e6; the "
                               "distance sets the field of view, 1 gives 90 degrees)",
                               view));
    if (up > 1e6) parse.fail(fmt::format("invalid camera: up vector of length {:g} (at most 1e6)", up));
    const double cx = vy * uz - vz * uy, cy = vz * ux - vx * uz, cz = vx * uy - vy * ux;
    const double sine = std::sqrt(cx * cx + cy * cy + cz * cz) / (view * up);
    if (!(up > 0) || !(sine > 1e-3))
        parse.fail("invalid camera: up vector is zero or parallel to the view direction");
}

/// Text files hold no NUL bytes: one means a binary file (an image, an archive, a .blend) given
/// where text was expected. Throws Error naming the line of the first.
void refuse_binary(std::string_view text, std::string_view file, std::string_view what) {
    const std::size_t nul = text.find('\0');
    if (nul == std::string_view::npos) return;
    const auto line = 1 + static_cast<std::size_t>(std::count(text.begin(), text.begin() + nul, '\n'));
    throw_at(file, line, fmt::format("binary data (NUL byte): not {} text file", what));
}

/// Collects a file's warnings, at most kMaxWarnings of them: a hostile file could otherwise
/// produce one per line.
class WarningSink {
public:
    static constexpr std::size_t kMaxWarnings = 100;

    WarningSink(Warnings& warnings, std::string_view file) : warnings_(warnings), file_(file) {}
    ~WarningSink() {
        if (dropped_ > 0)
            warnings_.push_back(located(file_, 0, fmt::format("{} more warning{} not shown", dropped_,
                                                              dropped_ == 1 ? "" : "s")));
    }
    void add(std::string message) {
        if (count_++ < kMaxWarnings)
            warnings_.push_back(std::move(message));
        else
            ++dropped_;
    }

private:
    Warnings& warnings_;
    std::string_view file_;
    std::size_t count_ = 0, dropped_ = 0;
};

}  // namespace

void parse_mtl(std::string_view text, const std::filesystem::path& path,
               std::vector<Material>& materials, Warnings& warnings) {
    const std::string file = path.string();
    refuse_binary(text, file, "an MTL");
    const Limits& lim = limits();
    LineReader reader(text, file, lim.max_line_bytes);
    std::string_view line;
    std::size_t line_number = 0;
    Material* current = nullptr;
    Material ignored;  // receives the statements of a name defined again
    WarningSink warn(warnings, file);
    std::unordered_map<std::string, std::size_t> index;
    for (std::size_t i = 0; i < materials.size(); ++i) index[materials[i].name] = i;
    MemoryCheck memory;

    while (reader.next(line, line_number)) {
        Tokens t(line);
        if (t.at_end()) continue;
        std::string_view kw = t.next();
        Parser parse(file, line_number);
        if (kw == "newmtl") {
            std::string_view name = t.rest();
            if (name.empty()) parse.fail("'newmtl' needs a material name");
            std::string key(name);
            if (index.contains(key)) {
                // The first definition wins, in this file or an earlier library, as in
                // tinyobjloader: replacing it would recolour the faces already given it.
                warn.add(located(file, line_number,
                                 fmt::format("material '{}' defined again; the first definition is kept", key)));
                ignored = Material{key};
                current = &ignored;
            } else {
                check_count(parse, materials.size() + 1, kMaxIndexable, "materials", "");
                if (memory.due(materials.size()))
                    check_memory(text.size() + materials.size() * kNamedBytes,
                                 fmt::format("{}: {} materials", file, materials.size()));
                index.emplace(key, materials.size());
                materials.push_back(Material{key});
                current = &materials.back();
            }
            continue;
        }
        if (kw != "Kd" && kw != "Ka" && kw != "Ks" && kw != "Ns" && kw != "d" && kw != "Tr" &&
            kw != "illum" && kw != "map_Kd")
            continue;  // unknown statements are ignored by design
        if (!current) parse.fail(fmt::format("'{}' before any 'newmtl'", kw));
        if (kw == "Kd" || kw == "Ka" || kw == "Ks") {
            Tokens probe = t;
            std::string_view first = probe.next();
            if (first == "spectral" || first == "xyz") continue;  // not supported; keep default
            Vec3f c;
            c.x = parse.number(t, kw);
            // "Kd r" alone means r = g = b (MTL specification).
            if (t.at_end()) {
                c.y = c.z = c.x;
            } else {
                c.y = parse.number(t, kw);
                c.z = parse.number(t, kw);
            }
            (kw == "Kd" ? current->kd : kw == "Ka" ? current->ka : current->ks) = c;
        } else if (kw == "Ns") {
            current->ns = parse.number(t, kw);
        } else if (kw == "d") {
            Tokens probe = t;
            if (probe.next() == "-halo") t.next();
            current->d = parse.number(t, kw);
        } else if (kw == "Tr") {
            current->d = 1.0f - parse.number(t, kw);
        } else if (kw == "illum") {
            // The specification has models 0 to 10; any whole number that fits is kept.
            const float v = parse.number(t, kw);
            if (!(v >= -1e9f && v <= 1e9f)) parse.fail(fmt::format("illumination model {} out of range", v));
            current->illum = static_cast<int>(v);
        } else if (kw == "map_Kd") {
            // Options (-s 1 1 1, -clamp on, ...) come first; the file name is the last token.
            std::string_view rest = t.rest();
            std::size_t cut = rest.find_last_of(" \t");
            std::string_view name = cut == std::string_view::npos ? rest : rest.substr(cut + 1);
            if (name.empty()) parse.fail("'map_Kd' needs a file name");
            current->map_kd = (path.parent_path() / std::string(name)).string();
        }
    }
}

namespace {

// Counts the statements that add vertices and faces (a cheap pass over line starts) and
// reserves for them: growing the arrays by doubling costs more than the count. Faces are
// counted as one triangle each, the common case; polygons simply grow the arrays.
// The counts come from the file, so they are held to the limits first: a file of 700 million
// "f" lines must fail at the limit's line with its message, not in a 30 GB reservation.
void reserve_for(std::string_view text, Scene& scene, const Limits& limits) {
    std::size_t v = 0, vn = 0, vt = 0, f = 0;
    const char* p = text.data();
    const char* end = p + text.size();
    while (p < end) {
        if (end - p >= 2) {
            if (p[0] == 'v') {
                if (p[1] == ' ' || p[1] == '\t') ++v;
                else if (p[1] == 'n') ++vn;
                else if (p[1] == 't') ++vt;
            } else if (p[0] == 'f' && (p[1] == ' ' || p[1] == '\t')) {
                ++f;
            }
        }
        const void* nl = std::memchr(p, '\n', static_cast<std::size_t>(end - p));
        if (!nl) break;
        p = static_cast<const char*>(nl) + 1;
    }
    const std::uint64_t max_vertices = std::min(limits.max_vertices, kMaxIndexable);
    v = std::min<std::uint64_t>(v, max_vertices);
    vn = std::min<std::uint64_t>(vn, max_vertices);
    vt = std::min<std::uint64_t>(vt, max_vertices);
    f = std::min<std::uint64_t>(f, std::min(limits.max_triangles, kMaxIndexable));
    if (scene_bytes(v + vn + vt, f) > limits.max_memory) return;  // the parse stops at the limit
    scene.positions.reserve(v);
    scene.normals.reserve(vn);
    scene.texcoords.reserve(vt);
    scene.tri_positions.reserve(f);
    scene.tri_normals.reserve(f);
    scene.tri_texcoords.reserve(f);
    scene.tri_material.reserve(f);
    scene.tri_object.reserve(f);
}

}  // namespace

void parse_obj(std::string_view text, const std::filesystem::path& path, Scene& scene,
               Warnings& warnings, const ObjOptions& options) {
    scene.clear();
    const std::string file = path.string();
    refuse_binary(text, file, "an OBJ");
    const Limits& lim = options.limits;
    LineReader reader(text, file, lim.max_line_bytes);
    std::string_view line;
    std::size_t line_number = 0;
    WarningSink warn(warnings, file);
    reserve_for(text, scene, options.limits);

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
    std::vector<Corner> corners;
    corners.reserve(16);

    // Memory: the text, the scene, its BVH, times the scenes loaded at once, plus what the
    // caller has committed elsewhere (frame buffers).
    MemoryCheck memory;
    const std::uint64_t max_vertices = std::min(lim.max_vertices, kMaxIndexable);
    const std::uint64_t max_triangles = std::min(lim.max_triangles, kMaxIndexable);
    auto estimate = [&] {
        const std::uint64_t vertices = scene.positions.size() + scene.normals.size() + scene.texcoords.size();
        const std::uint64_t names = scene.objects.size() + scene.materials.size();
        return lim.reserved_memory + text.size() +
               std::max<std::uint64_t>(lim.scenes_in_flight, 1) *
                   (scene_bytes(vertices, scene.triangle_count()) + names * kNamedBytes);
    };
    auto check_estimate = [&](const Parser& parse) {
        const std::uint64_t bytes = estimate();
        if (bytes > lim.max_memory)
            parse.fail(fmt::format("the scene so far ({} vertices, {} triangles) needs about {} of memory, "
                                   "more than the limit of {} (--max-memory raises it)",
                                   scene.positions.size(), scene.triangle_count(), format_bytes(bytes),
                                   format_bytes(lim.max_memory)));
    };
    auto grew = [&](const Parser& parse) {
        if (memory.due(scene.positions.size() + scene.normals.size() + scene.texcoords.size() +
                       scene.triangle_count() + scene.objects.size()))
            check_estimate(parse);
    };

    // What both paths do before adding an element (so a limit names the line that exceeds it),
    // and the face's triangles from `corners`.
    auto adding_position = [&](const Parser& parse) {
        check_count(parse, scene.positions.size() + 1, max_vertices, "vertices ('v')", "--max-vertices");
        grew(parse);
    };
    auto adding_normal = [&](const Parser& parse) {
        check_count(parse, scene.normals.size() + 1, max_vertices, "normals ('vn')", "--max-vertices");
        grew(parse);
    };
    auto adding_texcoord = [&](const Parser& parse) {
        check_count(parse, scene.texcoords.size() + 1, max_vertices, "texture coordinates ('vt')",
                    "--max-vertices");
        grew(parse);
    };
    auto add_face = [&](const Parser& parse) {
        if (scene.triangle_count() + (corners.size() - 2) > max_triangles)
            parse.fail(fmt::format("more than {} triangles (the limit; --max-triangles raises it)",
                                   max_triangles));
        grew(parse);
        for (std::size_t i = 1; i + 1 < corners.size(); ++i) {
            const Corner& a = corners[0];
            const Corner& b = corners[i];
            const Corner& c = corners[i + 1];
            scene.add_triangle({a.v, b.v, c.v}, material, object, {a.n, b.n, c.n}, {a.t, b.t, c.t});
        }
    };

    for (;;) {
        // The common statements in their plain form, straight from the text (see
        // read_numbers_line). A line longer than the limit goes the general way, which reports it.
        const char* begin = reader.cursor();
        const char* end = reader.end();
        if (end - begin >= 2 && (begin[0] == 'v' || begin[0] == 'f')) {
            auto within_limit = [&](const char* next) {
                return next && static_cast<std::uint64_t>(next - begin) <= reader.max_line();
            };
            float f[3];
            const char* next;
            if (begin[0] == 'f') {
                if (is_blank(begin[1]) && within_limit(next = read_face_line(begin + 1, end, scene, corners))) {
                    add_face(Parser(file, reader.consumed_line(next)));
                    continue;
                }
            } else if (is_blank(begin[1])) {
                if (within_limit(next = read_numbers_line(begin + 1, end, f, 3))) {
                    adding_position(Parser(file, reader.consumed_line(next)));
                    scene.positions.push_back({f[0], f[1], f[2]});
                    continue;
                }
            } else if (begin[1] == 'n' && end - begin >= 3 && is_blank(begin[2])) {
                if (within_limit(next = read_numbers_line(begin + 2, end, f, 3))) {
                    adding_normal(Parser(file, reader.consumed_line(next)));
                    scene.normals.push_back({f[0], f[1], f[2]});
                    continue;
                }
            } else if (begin[1] == 't' && end - begin >= 3 && is_blank(begin[2])) {
                if (within_limit(next = read_numbers_line(begin + 2, end, f, 2))) {
                    adding_texcoord(Parser(file, reader.consumed_line(next)));
                    scene.texcoords.push_back({f[0], f[1]});
                    continue;
                }
            }
        }

        // Everything else: the general path.
        if (!reader.next(line, line_number)) break;
        Tokens t(line);
        if (t.at_end()) continue;
        std::string_view kw = t.next();
        Parser parse(file, line_number);

        if (kw == "v") {
            adding_position(parse);
            scene.positions.push_back(parse.vec3(t, kw));
            // Optional w (or vertex colour) values are accepted and ignored, but must be numbers.
            while (!t.at_end()) parse.number(t, kw);
        } else if (kw == "f") {
            corners.clear();
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
                                                   slot == 0 ? "vertex" : slot == 1 ? "texture" : "normal", tok));
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
                    parse.fail(idx[0] == 0 ? fmt::format("face vertex index 0 in '{}' (OBJ indices start at 1)", tok)
                                           : fmt::format("face vertex index {} out of range ({} vertices defined so far)",
                                                         idx[0], scene.positions.size()));
                if (present[1] && !resolve_index(idx[1], scene.texcoords.size(), c.t))
                    parse.fail(fmt::format("face texture index {} out of range ({} defined so far)",
                                           idx[1], scene.texcoords.size()));
                if (present[2] && !resolve_index(idx[2], scene.normals.size(), c.n))
                    parse.fail(fmt::format("face normal index {} out of range ({} defined so far)",
                                           idx[2], scene.normals.size()));
                corners.push_back(c);
            }
            if (corners.size() < 3)
                parse.fail(fmt::format("face needs at least 3 corners, has {}", corners.size()));
            add_face(parse);
        } else if (kw == "vn") {
            adding_normal(parse);
            scene.normals.push_back(parse.vec3(t, kw));
        } else if (kw == "vt") {
            adding_texcoord(parse);
            Vec2f uv;
            uv.x = parse.number(t, kw);
            if (!t.at_end()) uv.y = parse.number(t, kw);
            if (!t.at_end()) parse.number(t, kw);
            scene.texcoords.push_back(uv);
        } else if (kw == "usemtl") {
            std::string_view name = t.rest();
            auto it = material_ids.find(name);
            material = it == material_ids.end() ? 0 : it->second;
            if (material == 0 && !name.empty() && warned_materials.size() < 10'000 &&
                warned_materials.emplace(std::string(name), 0).second)
                warn.add(located(file, line_number,
                                 fmt::format("unknown material '{}'; using the default material", name)));
        } else if (kw == "o" || kw == "g") {
            std::string_view name = t.rest();
            if (!name.empty() && scene.objects.size() >= kMaxIndexable && !object_ids.contains(std::string(name)))
                check_count(parse, scene.objects.size() + 1, kMaxIndexable, "objects ('o' and 'g')", "");
            object = name.empty() ? 0 : intern(object_ids, scene.objects, name);
            grew(parse);
        } else if (kw == "mtllib") {
            if (!options.load_materials) continue;
            while (!t.at_end()) {
                std::string_view name = t.next();
                std::filesystem::path library = (path.parent_path() / std::string(name)).lexically_normal();
                // Each library once: "mtllib a.mtl a.mtl ..." must not read a.mtl again and again.
                if (!libraries.emplace(library.string(), true).second) continue;
                Warnings library_warnings;
                load_mtl_file(library, scene.materials, library_warnings, file, line_number);
                for (std::string& w : library_warnings) warn.add(std::move(w));
                check_count(parse, scene.materials.size(), kMaxIndexable, "materials", "");
                check_estimate(parse);
            }
            index_materials();
        } else if (kw == "c") {
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
            check_camera(parse, cam);
            scene.camera = cam;
        } else if (kw == "s" || kw == "l" || kw == "p" || kw == "vp" || kw == "cstype" ||
                   kw == "deg" || kw == "curv" || kw == "curv2" || kw == "surf" || kw == "parm" ||
                   kw == "end" || kw == "mg" || kw == "lod" || kw == "usemap" || kw == "maplib" ||
                   kw == "shadow_obj" || kw == "trace_obj" || kw == "bevel" || kw == "c_interp" ||
                   kw == "d_interp" || kw == "ctech" || kw == "stech" || kw == "trim" ||
                   kw == "hole" || kw == "scrv" || kw == "sp" || kw == "con" || kw == "bmat" ||
                   kw == "step") {
            // Accepted: smoothing groups are implied by vn; lines, points and free-form
            // geometry are not rendered.
        } else {
            if (warned_statements.size() < 10'000 && warned_statements.emplace(std::string(kw), 0).second)
                warn.add(located(file, line_number, fmt::format("unknown statement '{}' ignored", kw)));
        }
    }
    check_estimate(Parser(file, 0));
}

void load_obj(const std::filesystem::path& path, Scene& scene, Warnings& warnings,
              const ObjOptions& options) {
    std::string text = read_file(path, options.limits.max_input_bytes);
    // An empty file is a failed download or export, not a scene.
    if (text.find_first_not_of(" \t\r\n\f\v") == std::string::npos)
        throw Error(located(path.string(), 0, text.empty() ? "empty file: no OBJ statements"
                                                            : "blank file: no OBJ statements"));
    parse_obj(text, path, scene, warnings, options);
}

}  // namespace toonray
