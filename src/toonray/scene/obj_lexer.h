#pragma once
/// The text level of Wavefront OBJ and MTL files (internal to the scene module): logical lines
/// (LF, CRLF and CR endings, `\` continuations, line numbers for messages), whitespace-separated
/// tokens, numbers and face indices, and the located errors of one statement.

#include <bit>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "toonray/core/error.h"
#include "toonray/core/math.h"

namespace toonray::wavefront {

inline bool is_digit(char c) { return static_cast<unsigned char>(c - '0') < 10; }
inline bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}
/// Blanks: the separators of a line's tokens in the plain statement forms.
inline bool is_blank(char c) { return c == ' ' || c == '\t'; }

/// Splits text into logical lines: a line ends at LF, CRLF or a lone CR (old Mac files; as
/// tinyobjloader reads them), lines ending in a backslash are joined, and physical lines are
/// counted for messages. Comments are left to the callers ('#' starts one). A UTF-8 byte-order
/// mark at the start is skipped. A line longer than `max_line` bytes throws
/// LimitError(Limit::LineBytes). A caller may also read plain physical lines straight from the
/// text (cursor(), consumed_line()) and leave the others to next().
class LineReader {
public:
    LineReader(std::string_view text, std::string_view file, std::uint64_t max_line);

    /// Next logical line, or false at the end. `line_number` is the physical line it starts on.
    bool next(std::string_view& line, std::size_t& line_number);

    /// Whether a physical line (without its line break) goes on into the next one: it ends in
    /// a backslash and is not a comment ("# C:\models\" must not swallow the next line).
    static bool continues(std::string_view physical);

    /// The unread text, for a caller that reads a line itself.
    [[nodiscard]] const char* cursor() const { return text_.data() + pos_; }
    [[nodiscard]] const char* end() const { return text_.data() + text_.size(); }
    [[nodiscard]] std::uint64_t max_line() const { return max_line_; }
    /// Marks one physical line, read by the caller, as consumed; `next_line` is where the next
    /// one starts. Returns its line number.
    std::size_t consumed_line(const char* next_line) {
        pos_ = static_cast<std::size_t>(next_line - text_.data());
        return ++physical_;
    }
    /// Marks `lines` plain physical lines, read by the caller, as consumed up to `next_line`.
    void skip_lines(const char* next_line, std::size_t lines) {
        pos_ = static_cast<std::size_t>(next_line - text_.data());
        physical_ += lines;
    }

private:
    std::string_view take_physical();
    [[noreturn]] void too_long(std::size_t line, bool joined) const;

    std::string_view text_;
    std::string_view file_;
    std::uint64_t max_line_;
    std::size_t pos_ = 0;
    std::size_t physical_ = 0;
    std::string joined_;
};

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

/// The float nearest to a decimal whose value was computed as `d`, one correctly rounded double
/// operation on exact operands (m / 10^k or m * 10^k, m < 2^53, k <= 22): rounding `d` to float
/// gives it, unless `d` lies exactly halfway between two floats. Rounding to double never moves
/// a value across such a midpoint, only onto it (midpoints are doubles), so the exact value is
/// on the same side as `d` of every midpoint but that one; on it, the exact value may be just
/// off it either way ("0.83888378739357" is), and this returns false. For results in the
/// range of normal floats.
inline bool nearest_float(double d, float& out) {
    const auto bits = std::bit_cast<std::uint64_t>(d);
    // The 29 low bits of the significand, which a float drops: 1000...0 is a midpoint.
    if ((bits & 0x1FFFFFFFu) == 0x10000000u) return false;
    out = static_cast<float>(d);
    return true;
}

/// 10^0 to 10^22: every power of ten that is an exact double.
inline constexpr double kPowersOfTen[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                            1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                            1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/// The common case of OBJ numbers, "[-]ddd.ddd" with up to 15 significant digits and at most
/// 15 decimals, parsed without from_chars. The mantissa m < 10^15 and 10^k are exact doubles,
/// so m / 10^k rounds once to double, and nearest_float gives the float from_chars<float>
/// gives, bit for bit (or declines). Reads from `p` up to the first character that cannot
/// continue the number and advances `p` there; the caller checks what follows (a separator,
/// or the end of the token). Returns false, `p` unspecified, for anything else (exponents,
/// longer numbers, the rare values nearest_float declines).
inline bool scan_short_decimal(const char*& pos, const char* e, float& out) {
    const char* p = pos;  // a local cursor: the compiler keeps it in a register
    const bool negative = p < e && *p == '-';
    p += negative;
    std::uint64_t m = 0;
    std::size_t digits = 0, decimals = 0;  // size_t: a line may be longer than 2^31 bytes
    for (; p < e && is_digit(*p); ++p, ++digits) m = m * 10 + static_cast<std::uint64_t>(*p - '0');
    if (p < e && *p == '.')
        for (++p; p < e && is_digit(*p); ++p, ++decimals)
            m = m * 10 + static_cast<std::uint64_t>(*p - '0');
    digits += decimals;
    // Past 15 digits m may have wrapped, but then the result is not used.
    if (digits == 0 || digits > 15) return false;
    float v;
    if (!nearest_float(static_cast<double>(m) / kPowersOfTen[decimals], v)) return false;
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

/// One statement being read: where it is, for messages, and its numbers.
class LineParser {
public:
    LineParser(std::string_view file, std::size_t line) : file_(file), line_(line) {}

    /// Throws Error("file:line: message").
    [[noreturn]] void fail(std::string_view message) const;
    /// Throws LimitError(limit, "file:line: message").
    [[noreturn]] void fail_limit(Limit limit, std::string_view message) const;

    /// The next token as a finite float, bit for bit what from_chars gives ("+" allowed; too
    /// small for a float reads as zero). `what` names the statement in messages.
    float number(Tokens& t, std::string_view what) const;
    Vec3f vec3(Tokens& t, std::string_view what) const {
        Vec3f v;
        v.x = number(t, what);
        v.y = number(t, what);
        v.z = number(t, what);
        return v;
    }
    /// As number(), but a non-finite value ("nan", "inf", or too large for a float) is read
    /// rather than refused, and clears `finite`: a coordinate other tools read, whose faces the
    /// OBJ reader drops.
    float coordinate(Tokens& t, std::string_view what, bool& finite) const;
    Vec3f coordinates3(Tokens& t, std::string_view what, bool& finite) const {
        Vec3f v;
        v.x = coordinate(t, what, finite);
        v.y = coordinate(t, what, finite);
        v.z = coordinate(t, what, finite);
        return v;
    }

private:
    float read_number(Tokens& t, std::string_view what, bool& finite, bool allow_nonfinite) const;

    std::string_view file_;
    std::size_t line_;
};

/// Text files hold no NUL bytes: one means a binary file (an image, an archive, a .blend) given
/// where text was expected (`what`: "an OBJ"). Throws Error naming the line of the first.
void refuse_binary(std::string_view text, std::string_view file, std::string_view what);

}  // namespace toonray::wavefront
