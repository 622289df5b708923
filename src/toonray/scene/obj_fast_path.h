#pragma once
/// The plain forms of the statements that make up nearly all of an OBJ file (v, vn, vt, f),
/// read in one pass over the text (internal to the scene module): no line splitting ahead, no
/// tokens, no keyword comparisons. Each reader returns where the next line starts, or nullptr
/// when the line has any other form (a trailing comment, a continuation, an exponent, an
/// error, ...); it has then changed nothing, and parse_obj's general path reads the line with
/// its precise messages. So this path decides only how fast a line is read, never what it
/// means.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "toonray/core/index.h"
#include "toonray/scene/obj_lexer.h"
#include "toonray/scene/scene.h"

namespace toonray::wavefront {

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

/// A face corner: its position, texture coordinate and normal indices (kNoIndex when absent).
struct Corner {
    std::uint32_t v, t, n;
};

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
        if (!parse_index(p, end, index) || !resolve_index(index, scene.positions.size(), c.v))
            return nullptr;
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

}  // namespace toonray::wavefront
