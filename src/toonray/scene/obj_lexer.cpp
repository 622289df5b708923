#include "toonray/scene/obj_lexer.h"

#include <algorithm>
#include <charconv>
#include <limits>
#include <cmath>
#include <cstring>
#include <fmt/format.h>

#include "toonray/core/limits.h"

namespace toonray::wavefront {
namespace {

bool ends_with_backslash(std::string_view s) { return !s.empty() && s.back() == '\\'; }

bool is_comment(std::string_view s) {
    std::size_t i = s.find_first_not_of(" \t");
    return i != std::string_view::npos && s[i] == '#';
}

}  // namespace

bool LineReader::continues(std::string_view physical) {
    return ends_with_backslash(physical) && !is_comment(physical);
}

LineReader::LineReader(std::string_view text, std::string_view file, std::uint64_t max_line)
    : text_(text), file_(file), max_line_(max_line) {
    if (text_.size() >= 3 && std::memcmp(text_.data(), "\xEF\xBB\xBF", 3) == 0)
        text_.remove_prefix(3);
}

bool LineReader::next(std::string_view& line, std::size_t& line_number) {
    if (pos_ >= text_.size()) return false;
    line_number = ++physical_;
    std::string_view piece = take_physical();
    if (!continues(piece)) {
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

std::string_view LineReader::take_physical() {
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

void LineReader::too_long(std::size_t line, bool joined) const {
    LineParser(file_, line)
        .fail_limit(Limit::LineBytes, fmt::format("line{} longer than the limit of {}",
                                                  joined ? " (with its continuations)" : "",
                                                  format_bytes(max_line_)));
}

void LineParser::fail(std::string_view message) const { throw_at(file_, line_, message); }

void LineParser::fail_limit(Limit limit, std::string_view message) const {
    throw LimitError(limit, located(file_, line_, message));
}

namespace {

// How Microsoft's C runtime prints non-finite values ("1.#IND", "-1.#INF", "1.#QNAN0"), which
// files written with it hold.
bool is_msvc_nonfinite(std::string_view tok) {
    const std::size_t hash = tok.find(".#");
    if (hash == std::string_view::npos || hash == 0) return false;
    const std::string_view digits = tok.substr(tok[0] == '-' || tok[0] == '+' ? 1 : 0,
                                               hash - (tok[0] == '-' || tok[0] == '+' ? 1 : 0));
    if (digits.empty()) return false;
    for (char c : digits)
        if (!is_digit(c)) return false;
    const std::string_view rest = tok.substr(hash + 2);
    return rest.starts_with("IND") || rest.starts_with("INF") || rest.starts_with("QNAN") ||
           rest.starts_with("SNAN");
}

}  // namespace

float LineParser::number(Tokens& t, std::string_view what) const {
    bool finite = true;
    return read_number(t, what, finite, false);
}

float LineParser::coordinate(Tokens& t, std::string_view what, bool& finite) const {
    return read_number(t, what, finite, true);
}

float LineParser::read_number(Tokens& t, std::string_view what, bool& finite,
                              bool allow_nonfinite) const {
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
        // that write doubles produce such values); too large is an error, or an infinite
        // coordinate where those are allowed.
        double d;
        auto [dptr, dec] = std::from_chars(b, e, d);
        std::string_view digits(b, static_cast<std::size_t>(e - b));
        bool underflow = dec == std::errc() ? std::abs(d) < 1.0
                                            : digits.find("e-") != std::string_view::npos ||
                                                  digits.find("E-") != std::string_view::npos;
        if (!underflow) {
            if (!allow_nonfinite)
                fail(fmt::format("number '{}' out of range in '{}' statement", tok, what));
            finite = false;
            return std::numeric_limits<float>::infinity();
        }
        v = dec == std::errc() ? static_cast<float>(d) : 0.0f;
        ec = std::errc();
    }
    if (ec != std::errc() || ptr != e) {
        if (allow_nonfinite && is_msvc_nonfinite(tok)) {
            finite = false;
            return std::numeric_limits<float>::quiet_NaN();
        }
        fail(fmt::format("malformed number '{}' in '{}' statement", tok, what));
    }
    if (!std::isfinite(v)) {
        if (!allow_nonfinite)
            fail(fmt::format("non-finite number '{}' in '{}' statement", tok, what));
        finite = false;
    }
    return v;
}

void refuse_binary(std::string_view text, std::string_view file, std::string_view what) {
    const std::size_t nul = text.find('\0');
    if (nul == std::string_view::npos) return;
    const auto line =
        1 + static_cast<std::size_t>(std::count(text.begin(), text.begin() + nul, '\n'));
    throw_at(file, line, fmt::format("binary data (NUL byte): not {} text file", what));
}

}  // namespace toonray::wavefront
