#pragma once
/// The hash of the open-addressing tables in ink/ (positions in welding, endpoint keys in
/// chaining): three 32-bit words mixed into a table index.

#include <cstddef>
#include <cstdint>

namespace toonray::ink {

/// Three words mixed by multiplication with odd constants; the table masks the low bits.
inline std::size_t hash_words(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    std::uint64_t h = (static_cast<std::uint64_t>(a) * 0x9e3779b97f4a7c15ull) ^
                      (static_cast<std::uint64_t>(b) * 0xc2b2ae3d27d4eb4full) ^
                      (static_cast<std::uint64_t>(c) * 0x165667b19e3779f9ull);
    return static_cast<std::size_t>(h ^ (h >> 29));
}

}  // namespace toonray::ink
