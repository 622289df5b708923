#pragma once
/// Saturating unsigned arithmetic for size and memory estimates: an input that asks for more
/// than 2^64 bytes must compare as "too much", never wrap around to a small number.

#include <cstdint>
#include <limits>

namespace toonray {

[[nodiscard]] inline std::uint64_t add_saturated(std::uint64_t a, std::uint64_t b) {
    std::uint64_t r;
    return __builtin_add_overflow(a, b, &r) ? std::numeric_limits<std::uint64_t>::max() : r;
}

[[nodiscard]] inline std::uint64_t mul_saturated(std::uint64_t a, std::uint64_t b) {
    std::uint64_t r;
    return __builtin_mul_overflow(a, b, &r) ? std::numeric_limits<std::uint64_t>::max() : r;
}

}  // namespace toonray
