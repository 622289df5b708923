#include "toonray/core/limits.h"

#include "toonray/core/saturating.h"

#include <unistd.h>

#include <charconv>
#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "toonray/core/error.h"

namespace toonray {
namespace {

Limits& process_limits() {
    static Limits limits;
    return limits;
}

/// A non-negative number with an optional suffix from `units` (each a power of `base`).
std::uint64_t parse_scaled(std::string_view text, double base, bool bytes) {
    const std::string_view original = text;
    auto bad = [&]() -> std::uint64_t {
        throw Error(fmt::format("expected a positive {} such as {}, got '{}'",
                                bytes ? "size" : "number", bytes ? "512M or 8G" : "50000000 or 50M",
                                original));
    };
    double value = 0;
    auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc() || !std::isfinite(value) || value <= 0) return bad();
    std::string_view suffix(p, static_cast<std::size_t>(text.data() + text.size() - p));
    if (bytes) {
        if (suffix.ends_with("iB")) suffix.remove_suffix(2);
        else if (suffix.ends_with("B") && suffix.size() > 1) suffix.remove_suffix(1);
        else if (suffix == "B") suffix = {};
    }
    double scale = 1;
    if (suffix.size() > 1) return bad();
    if (suffix.size() == 1) {
        switch (suffix[0]) {
            case 'k':
            case 'K': scale = base; break;
            case 'm':
            case 'M': scale = base * base; break;
            case 'g':
            case 'G': scale = base * base * base; break;
            case 't':
            case 'T': scale = base * base * base * base; break;
            default: return bad();
        }
    }
    const double scaled = std::round(value * scale);
    if (!(scaled >= 1)) return bad();
    if (scaled >= 1.8e19) return std::numeric_limits<std::uint64_t>::max();
    return static_cast<std::uint64_t>(scaled);
}

}  // namespace

std::uint64_t Limits::default_max_memory() {
    const long pages = ::sysconf(_SC_PHYS_PAGES);
    const long page_size = ::sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || page_size <= 0) return 8 * kGiB;
    return mul_saturated(static_cast<std::uint64_t>(pages), static_cast<std::uint64_t>(page_size)) /
           4 * 3;
}

const Limits& limits() { return process_limits(); }

void set_limits(const Limits& limits) { process_limits() = limits; }

void check_memory(std::uint64_t bytes, std::string_view what) {
    const std::uint64_t limit = limits().max_memory;
    if (bytes <= limit) return;
    throw LimitError(Limit::Memory,
                     fmt::format("{} needs about {} of memory, more than the limit of {}", what,
                                 format_bytes(bytes), format_bytes(limit)));
}

std::string format_bytes(std::uint64_t bytes) {
    if (bytes < kKiB) return fmt::format("{} bytes", bytes);
    const char* units[] = {"KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
    double v = static_cast<double>(bytes) / 1024.0;
    int u = 0;
    while (v >= 1024.0 && u < 5) {
        v /= 1024.0;
        ++u;
    }
    return v < 10 ? fmt::format("{:.1f} {}", v, units[u]) : fmt::format("{:.0f} {}", v, units[u]);
}

std::uint64_t parse_count(std::string_view text) { return parse_scaled(text, 1000.0, false); }

std::uint64_t parse_bytes(std::string_view text) { return parse_scaled(text, 1024.0, true); }

}  // namespace toonray
