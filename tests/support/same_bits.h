#pragma once
/// Bit-for-bit comparisons the test suites share: -0 and 0 differ, and so do NaNs with different
/// payloads.

#include <cstring>
#include <type_traits>
#include <vector>

namespace toonray::test_support {

/// Whether two values of a plain type have the same bytes.
template <typename T>
bool same_bits(const T& a, const T& b) {
    static_assert(std::is_trivially_copyable_v<T>);
    return std::memcmp(&a, &b, sizeof(T)) == 0;
}

/// Whether two vectors of a plain type have the same size and bytes.
template <typename T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
    static_assert(std::is_trivially_copyable_v<T>);
    return a.size() == b.size() &&
           (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

}  // namespace toonray::test_support
