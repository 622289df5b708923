#include "toonray/core/limits.h"

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

/// Multiplies without overflow: saturates at the largest value.
std::uint64_t mul_sat(std::uint64_t a, std::uint64_t b) {
    std::uint64_t r;
    return __builtin_mul_overflow(a, b, &r) ? std::numeric_limits<std::uint64_t>::max() : r;
}

std::uint64_t add_sat(std::uint64_t a, std::uint64_t b) {
    std::uint64_t r;
    return __builtin_add_overflow(a, b, &r) ? std::numeric_limits<std::uint64_t>::max() : r;
}

/// A non-negative number with an optional suffix from `units` (each a power of `base`).
std::uint64_t parse_scaled(std::string_view text, double base, bool bytes) {
    const std::string_view original = text;
    auto bad = [&]() -> std::uint64_t {
        throw Error(fmt::format("expected a positive {} such as {}, got '{}'", bytes ? "size" : "number",
                                bytes ? "512M or 8G" : "50000000 or 50M", original));
    };
    double value = 0;
    auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc() || !std::isfinite(value) || value <= 0) return bad();
    std::string_view suffix(p, static_cast<std::size_t>(text.data() + text.size() - p));
    if (bytes) {
        if (suffix.ends_with("iB"))
            suffix.remove_suffix(2);
        else if (suffix.ends_with("B") && suffix.size() > 1)
            suffix.remove_suffix(1);
        else if (suffix == "B")
            suffix = {};
    }
    double scale = 1;
    if (suffix.size() > 1) return bad();
    if (suffix.size() == 1) {
        switch (suffix[0]) {
            case 'k': case 'K': scale = base; break;
            case 'm': case 'M': scale = base * base; break;
            case 'g': case 'G': scale = base * base * base; break;
            case 't': case 'T': scale = base * base * base * base; break;
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
    return mul_sat(static_cast<std::uint64_t>(pages), static_cast<std::uint64_t>(page_size)) / 4 * 3;
}

const Limits& limits() { return process_limits(); }

void set_limits(const Limits& limits) { process_limits() = limits; }

std::uint64_t frame_buffer_bytes(std::uint64_t pixels, int samples) {
    // Measured peak (maximum resident size) of `toonray render` at 2048x2048, less the scene:
    // 58 bytes per pixel in classic mode, 72 / 196 / 688 at 1 / 4 / 16 samples in robust mode,
    // so about 31 per pixel plus 41 per sample. Per sample: depth, view depth, material,
    // object, line seeds and distances, normals and colour; per pixel: the feature images, the
    // final image, the PNG filter buffer and its compressed copy. Rounded up by ~20%.
    const std::uint64_t per_sample = 48;
    const std::uint64_t per_pixel = 40;
    const std::uint64_t s = samples < 1 ? 1 : static_cast<std::uint64_t>(samples);
    return mul_sat(pixels, add_sat(mul_sat(per_sample, s), per_pixel));
}

std::uint64_t scene_bytes(std::uint64_t vertices, std::uint64_t triangles) {
    // Per vertex: the position and, at worst, a normal and a texture coordinate. Per triangle:
    // 5 index arrays (44 bytes), the BVH build (boxes, centres, indices, nodes: ~100 bytes),
    // the packed triangles (36 bytes) and the corner list the automatic camera gathers (36
    // bytes). Measured: a 2M-triangle, 1M-vertex grid peaks at 431 MB including its 55 MB of
    // text; this estimates 518 MB.
    return add_sat(mul_sat(vertices, 12 + 12 + 8), mul_sat(triangles, 44 + 100 + 36 + 36));
}

void check_memory(std::uint64_t bytes, std::string_view what, std::string_view) {
    const std::uint64_t limit = limits().max_memory;
    if (bytes <= limit) return;
    throw LimitError(Limit::Memory, fmt::format("{} needs about {} of memory, more than the limit of {}", what,
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
