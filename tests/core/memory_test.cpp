#include "toonray/core/memory.h"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cstddef>
#include <cstdlib>
#include <cstring>

// AddressSanitizer replaces glibc's allocator with its own, which keeps freed blocks out of use
// for a while: there is no glibc policy to observe in that build.
#if defined(__SANITIZE_ADDRESS__)
#define TOONRAY_ADDRESS_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define TOONRAY_ADDRESS_SANITIZER 1
#endif
#endif

#if defined(__GLIBC__) && !defined(TOONRAY_ADDRESS_SANITIZER)

namespace toonray {
namespace {

long minor_faults() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return usage.ru_minflt;
}

// Faults taken to allocate, fill and free a block of `bytes`.
long faults_to_fill(std::size_t bytes) {
    const long before = minor_faults();
    auto* p = static_cast<unsigned char*>(std::malloc(bytes));
    EXPECT_NE(p, nullptr);
    std::memset(p, 1, bytes);
    const long after = minor_faults() + p[bytes / 2] - 1;  // read, so the fill is not dropped
    std::free(p);
    return after - before;
}

TEST(Memory, AFreedBlockIsReusedWithoutFaultingItsPagesAgain) {
    retain_freed_memory();
    constexpr std::size_t kBytes = std::size_t{16} << 20;  // 4,096 pages of 4 KiB
    const long first = faults_to_fill(kBytes);
    const long second = faults_to_fill(kBytes);
    EXPECT_GT(first, 64);  // fresh memory, faulted in
    // Handed back to the system, the block would be faulted in again as many times (an
    // emulator running the test may take a few faults of its own).
    EXPECT_LT(second, first / 16) << "first fill took " << first << " faults";
}

}  // namespace
}  // namespace toonray

#endif
