#pragma once
/// The traversal kernels' instruction sets, for tests that run on each one the CPU has.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "toonray/accel/triangle_accel.h"

namespace toonray::test_support {

/// The portable instruction set, and AVX2 and AVX-512 when this CPU has them.
inline std::vector<std::string> isas() {
    std::vector<std::string> out{"sse4.2"};
    for (const char* isa : {"avx2", "avx512"})
        if (set_accel_isa(isa)) out.push_back(isa);
    set_accel_isa("auto");
    return out;
}

/// Selects an instruction set for its lifetime, then the best again.
struct IsaGuard {
    explicit IsaGuard(const std::string& isa) { EXPECT_TRUE(set_accel_isa(isa)); }
    ~IsaGuard() { set_accel_isa("auto"); }
};

}  // namespace toonray::test_support
