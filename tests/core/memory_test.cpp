#include "toonray/core/memory.h"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cstddef>
#include <cstdlib>
#include <cstring>

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

#if defined(__GLIBC__)
TEST(Memory, AFreedBlockIsReusedWithoutFaultingItsPagesAgain) {
    retain_freed_memory();
    constexpr std::size_t kBytes = std::size_t{16} << 20;  // 4,096 pages of 4 KiB
    const long first = faults_to_fill(kBytes);
    const long second = faults_to_fill(kBytes);
    EXPECT_GT(first, 64);  // fresh memory, faulted in
    // Handed back to the system, the block would be faulted in again, page by page (or by
    // huge page: still more than a few).
    EXPECT_LT(second, 8) << "first fill took " << first << " faults";
}
#endif

}  // namespace
}  // namespace toonray
