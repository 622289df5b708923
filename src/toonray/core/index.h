#pragma once
/// The one "no index" value of 32-bit indices: a corner without a normal or texture coordinate,
/// a ray that hits no triangle, a sample without a material or object.

#include <cstdint>

namespace toonray {

/// 2^32 - 1: never a valid index (limits stop every count at kMaxIndexable, one below).
inline constexpr std::uint32_t kNoIndex = 0xffffffffu;

}  // namespace toonray
