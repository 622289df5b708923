#pragma once
/// The plain forms of the statements that make up nearly all of an OBJ file (v, vn, vt, f),
/// read in one pass over the text (internal to the scene module): no line splitting ahead, no
/// tokens, no keyword comparisons. Each reader returns where the next line starts, or nullptr
/// when the line has any other form (a trailing comment, a continuation, a long number, an
/// error, ...); it has then changed nothing, and parse_obj's general path reads the line with
/// its precise messages. So this path decides only how fast a line is read, never what it
/// means.
///
/// The readers run only on the padded zone of the text (padded_zone_end): lines that end at
/// least kFastPathPadding bytes before the end of the text. A line end stops every scan, so
/// they need no bounds checks, and a number's digits are read 8 at a time (SWAR: one 64-bit
/// word holds 8 characters), which may read up to 17 bytes past the line.

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string_view>

#include "toonray/core/index.h"
#include "toonray/scene/obj_lexer.h"
#include "toonray/scene/obj_loader.h"

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

/// Bytes that follow the end of the last line the fast readers read.
inline constexpr std::size_t kFastPathPadding = 64;

/// Where the padded zone ends: just past the last line end (LF or CR) that is followed by at
/// least kFastPathPadding bytes of `text`; `text.data()` when there is none.
inline const char* padded_zone_end(std::string_view text) {
    if (text.size() <= kFastPathPadding) return text.data();
    for (std::size_t i = text.size() - kFastPathPadding; i-- > 0;)
        if (text[i] == '\n' || text[i] == '\r') return text.data() + i + 1;
    return text.data();
}

/// 8 characters as one word, the first in the lowest byte (on any byte order).
inline std::uint64_t load_chars(const char* p) {
    std::uint64_t w;
    std::memcpy(&w, p, sizeof w);
    if constexpr (std::endian::native == std::endian::big) w = __builtin_bswap64(w);
    return w;
}

/// Per byte of `w`, d = c - '0' is a digit's value; d + 0x76 sets the top bit exactly when d
/// >= 10 (and d < 0x80), d itself when d >= 0x80. Borrows and carries only run from a byte to
/// the next one in text order, and only out of a non-digit, so they cannot change the bytes
/// before the first non-digit: the top bit of the first byte set is the first non-digit's.
inline std::uint64_t non_digit_bits(std::uint64_t digit_values) {
    return ((digit_values + 0x7676767676767676u) | digit_values) & 0x8080808080808080u;
}

/// How many of the characters in `w` (in text order) are decimal digits before the first one
/// that is not: 0 to 8.
inline int leading_digits(std::uint64_t w) {
    const std::uint64_t non_digits = non_digit_bits(w - 0x3030303030303030u);
    return non_digits == 0 ? 8 : std::countr_zero(non_digits) >> 3;
}

/// The 8-digit number whose digits' values are the bytes of `d`, the first the most
/// significant: three multiplications add up pairs, then two pairs each into 4 digits, then the
/// halves.
inline std::uint64_t eight_digits(std::uint64_t d) {
    d = d * 10 + (d >> 8);  // even bytes: 10 * digit + next digit (at most 99, no carries)
    return (((d & 0x000000FF000000FFu) * (100 + (1000000ull << 32))) +
            (((d >> 16) & 0x000000FF000000FFu) * (1 + (10000ull << 32)))) >>
           32;
}

/// The value of the first `n` (1 to 8) characters of `w`, all digits: shifted to the top of
/// the word, they are the last digits of an 8-digit number.
inline std::uint64_t digits_value(std::uint64_t w, int n) {
    return eight_digits((w - 0x3030303030303030u) << (64 - 8 * n));
}

/// The leading digits of 8 characters: how many (0 to 8), their value followed by zeros to 8
/// digits (times 10^(8 - count), which needs no shift by the count), and a mask of their bytes.
struct DigitRun {
    int count;
    std::uint64_t scaled, bytes;
};

inline DigitRun digit_run(std::uint64_t w) {
    const std::uint64_t d = w - 0x3030303030303030u;
    const std::uint64_t non_digits = non_digit_bits(d);
    // The bits below the first non-digit's byte (all of them when there is none).
    const std::uint64_t bytes = ((non_digits & (0 - non_digits)) >> 7) - 1;
    return {non_digits == 0 ? 8 : std::countr_zero(non_digits) >> 3, eight_digits(d & bytes),
            bytes};
}

/// A number of the padded zone, "[-]digits[.digits][(e|E)[+-]digits]" with 1 to 15 digits
/// before the exponent, read to the float from_chars<float> reads: the digits, 8 at a time,
/// make an exact m < 10^15, and m times or over a power of ten up to 10^22 rounds once
/// (nearest_float). False for any other number (longer, a larger power, a leading '+', nan,
/// ...), which the general path then reads; `end` (any bound past the line) only serves
/// integer parts of 8 or more digits, which go to scan_short_decimal.
inline bool read_number(const char*& pos, const char* end, float& out) {
    static constexpr double kPow10Negative[23] = {
        1e0,   1e-1,  1e-2,  1e-3,  1e-4,  1e-5,  1e-6,  1e-7,  1e-8,  1e-9,  1e-10, 1e-11,
        1e-12, 1e-13, 1e-14, 1e-15, 1e-16, 1e-17, 1e-18, 1e-19, 1e-20, 1e-21, 1e-22};
    static constexpr std::uint64_t kPow10Int[8] = {1,     10,     100,     1000,
                                                   10000, 100000, 1000000, 10000000};
    const char* p = pos;
    const bool negative = *p == '-';
    p += negative;
    const std::uint64_t w = load_chars(p);
    const DigitRun whole = digit_run(w);
    if (whole.count == 8) [[unlikely]]
        return scan_short_decimal(pos, end, out);
    // m times 10^power: the digits make m, with zeros after them up to 8 digits.
    std::uint64_t m;
    int digits, power = whole.count - 8;
    if (p[whole.count] != '.') {
        if (whole.count == 0) return false;
        m = whole.scaled;
        digits = whole.count;
        p += digits;
    } else {
        // The digits on both sides of the point as one run: the point's byte dropped. Its
        // value, with zeros after it to 8 digits, is the number's times 10^(8 - whole.count).
        const DigitRun run = digit_run((w & whole.bytes) | (load_chars(p + 1) & ~whole.bytes));
        digits = run.count;
        if (digits == 0) return false;
        m = run.scaled;
        if (digits == 8) {
            const std::uint64_t next = load_chars(p + 9);
            const int more = leading_digits(next);
            if (more != 0) {
                if (more == 8) return false;  // 16 digits or more
                m = m * kPow10Int[more] + digits_value(next, more);
                digits += more;
                power -= more;
            }
        }
        p += digits + 1;
    }
    if ((*p | 0x20) == 'e') {
        const char* q = p + 1;
        const bool negative_exponent = *q == '-';
        q += negative_exponent || *q == '+';
        int exponent = 0;
        const char* first = q;
        for (; is_digit(*q) && q - first < 3; ++q) exponent = exponent * 10 + (*q - '0');
        if (q == first || is_digit(*q)) return false;  // no digits, or more than 3
        power += negative_exponent ? -exponent : exponent;
        p = q;
    }
    if (digits > 15 || power < -22 || power > 22) return false;
    const auto mantissa = static_cast<double>(static_cast<std::int64_t>(m));  // m < 10^15
    float v;
    if (power >= 0) {
        if (!nearest_float(mantissa * kPowersOfTen[power], v)) return false;
    } else {
        // A division takes 3 to 4 times as long as a product, and its result is waited for:
        // multiplying by 10^-k, itself rounded, is within 2 units in the last place (ulp) of
        // the exact quotient, so its nearest float is the quotient's unless the product lies
        // within a few ulps of a midpoint between floats. Then the exact way decides.
        const double product = mantissa * kPow10Negative[-power];
        const auto low_bits = std::bit_cast<std::uint64_t>(product) & 0x1FFFFFFFu;
        if (low_bits - (0x10000000u - 8) <= 16) [[unlikely]] {
            if (!nearest_float(mantissa / kPowersOfTen[-power], v)) return false;
        } else {
            v = static_cast<float>(product);
        }
    }
    // The sign without a branch: signs follow no pattern a branch predictor could learn.
    out = std::bit_cast<float>(std::bit_cast<std::uint32_t>(v) |
                               static_cast<std::uint32_t>(negative) << 31);
    pos = p;
    return true;
}

/// read_index's other forms: a sign, 8 digits or more. Apart, so that the common form is
/// small enough to be inlined.
[[gnu::noinline]] inline bool read_other_index(const char*& pos, const char* end, std::size_t count,
                                               bool relative, std::uint32_t& out) {
    if (*pos == '-' && relative) {  // relative: "-3" is the third from the last
        const std::uint64_t after = load_chars(pos + 1);
        const int back_digits = leading_digits(after);
        if (static_cast<unsigned>(back_digits - 1) < 7) {
            const std::uint64_t back = digits_value(after, back_digits);
            pos += 1 + back_digits;
            if (back - 1 >= count) return false;  // also 0, which wraps
            out = static_cast<std::uint32_t>(count - back);
            return true;
        }
    }
    long long index;
    return parse_index(pos, end, index) && (relative || index > 0) &&
           resolve_index(index, count, out);
}

/// A face index of the padded zone, "[+-]digits" (parse_index), resolved against `count`
/// (resolve_index), negative (relative) ones only when `relative`; up to 7 digits, without a
/// sign or after '-', are read at once. False when malformed or out of range.
inline bool read_index(const char*& pos, const char* end, std::size_t count, bool relative,
                       std::uint32_t& out) {
    const std::uint64_t w = load_chars(pos);
    const int digits = leading_digits(w);
    if (static_cast<unsigned>(digits - 1) < 7) [[likely]] {
        const std::uint64_t index = digits_value(w, digits);
        pos += digits;
        if (index - 1 >= count) return false;  // also 0, which wraps
        out = static_cast<std::uint32_t>(index - 1);
        return true;
    }
    return read_other_index(pos, end, count, relative, out);
}

/// Skips blanks, then expects the end of the line; returns the start of the next line.
inline const char* after_line_end(const char* p) {
    while (is_blank(*p)) ++p;
    if (*p == '\n') return p + 1;
    if (*p == '\r') return p + 1 + (p[1] == '\n');
    return nullptr;
}

/// Exactly `count` numbers (read_number), each after blanks, then the line's end.
inline const char* read_numbers_line(const char* p, const char* end, float* out, int count) {
    for (int i = 0; i < count; ++i) {
        if (!is_blank(*p)) return nullptr;
        do ++p;
        while (is_blank(*p));
        if (!read_number(p, end, out[i])) return nullptr;
    }
    return after_line_end(p);
}

/// The most corners a face may have on the fast path; longer polygons go the general way.
inline constexpr std::size_t kMaxFastCorners = 64;

/// Counts of the elements a face's indices are resolved against: those defined so far; and
/// whether relative (negative) indices are read.
struct Defined {
    std::size_t positions, texcoords, normals;
    bool relative;
};

/// A face corner "v", "v/t", "v//n" or "v/t/n", resolved.
inline bool read_corner(const char*& pos, const char* end, const Defined& defined, Corner& c) {
    const char* p = pos;
    c.t = c.n = kNoIndex;
    if (!read_index(p, end, defined.positions, defined.relative, c.v)) return false;
    if (*p == '/') {
        ++p;
        if (*p != '/' && !read_index(p, end, defined.texcoords, defined.relative, c.t))
            return false;
        if (*p == '/') {
            ++p;
            if (!read_index(p, end, defined.normals, defined.relative, c.n)) return false;
        }
    }
    pos = p;
    return true;
}

/// The corners of a face, each after blanks, resolved against the elements `defined` so far,
/// into `corners` (kMaxFastCorners room); at least 3, their number in `count`.
inline const char* read_face_line(const char* p, const char* end, const Defined& defined,
                                  Corner* corners, std::size_t& count) {
    std::size_t n = 0;
    while (is_blank(*p)) {  // corners are separated by blanks
        do ++p;
        while (is_blank(*p));
        if (*p == '\n' || *p == '\r') break;
        if (n == kMaxFastCorners || !read_corner(p, end, defined, corners[n++])) return nullptr;
    }
    if (n < 3) return nullptr;
    count = n;
    return after_line_end(p);
}

/// parse_obj with the padded zone in chunks of about `chunk_bytes`, read ahead by up to
/// `threads` - 1 other threads (0: every chunk read ahead on this thread first, then merged).
/// The result is the same for any chunks and threads; parse_obj chooses them, tests vary them.
void parse_obj_in_chunks(std::string_view text, const std::filesystem::path& path, Scene& scene,
                         Warnings& warnings, const ObjOptions& options, std::size_t chunk_bytes,
                         int threads);

}  // namespace toonray::wavefront
