#pragma once
/// Large build buffers on transparent huge pages (internal to the accel module). A BVH build
/// touches a few hundred megabytes of fresh memory for a million triangles; with 4 KiB pages
/// that is one page fault every 4 KiB, a measurable part of the build. Linux backs 2 MiB-aligned
/// ranges advised with MADV_HUGEPAGE with 2 MiB pages when transparent huge pages are enabled
/// ("always" or "madvise"): one fault per 2 MiB. Elsewhere the advice is a no-op.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <new>
#include <type_traits>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace toonray::accel {

inline constexpr std::size_t kHugePage = std::size_t{1} << 21;

/// Advises the whole 2 MiB pages inside [p, p + bytes) for huge pages. Call before the memory is
/// first touched; a hint, harmless where it is not supported.
inline void advise_huge_pages(const void* p, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    auto begin = reinterpret_cast<std::uintptr_t>(p);
    auto end = begin + bytes;
    begin = (begin + kHugePage - 1) & ~(kHugePage - 1);
    end &= ~(kHugePage - 1);
    if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
    (void)p;
    (void)bytes;
#endif
}

struct FreeDeleter {
    void operator()(void* p) const { std::free(p); }
};

/// An array of `n` uninitialised T (trivial types only), 2 MiB-aligned and advised for huge
/// pages when it spans at least one.
template <class T>
using HugeArray = std::unique_ptr<T[], FreeDeleter>;

template <class T>
HugeArray<T> make_huge_array(std::size_t n) {
    static_assert(std::is_trivially_default_constructible_v<T> &&
                  std::is_trivially_destructible_v<T>);
    const std::size_t bytes = std::max<std::size_t>(n * sizeof(T), 1);
    void* p = nullptr;
    if (bytes >= kHugePage) {
        p = std::aligned_alloc(kHugePage, (bytes + kHugePage - 1) & ~(kHugePage - 1));
        if (p) advise_huge_pages(p, bytes);
    }
    if (!p)
        p = std::aligned_alloc(alignof(T) > 16 ? alignof(T) : 16, (bytes + 63) & ~std::size_t{63});
    if (!p) throw std::bad_alloc();
    return HugeArray<T>(static_cast<T*>(p));
}

/// Reserves room for `n` elements in `v` and advises it for huge pages (before its first use).
template <class Vector>
void reserve_huge(Vector& v, std::size_t n) {
    v.reserve(n);
    advise_huge_pages(v.data(), v.capacity() * sizeof(typename Vector::value_type));
}

}  // namespace toonray::accel
