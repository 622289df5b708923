#pragma once
/// Image comparisons the test suites share.

#include <cstddef>
#include <cstdlib>

#include "toonray/core/image.h"

namespace toonray::test_support {

/// Share of pixels of two same-sized images with a channel that differs by more than
/// `tolerance`.
inline double share_differing(const ImageRgb8& a, const ImageRgb8& b, int tolerance) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
        for (int c = 0; c < 3; ++c)
            if (std::abs(a.data()[i][c] - b.data()[i][c]) > tolerance) {
                ++n;
                break;
            }
    return static_cast<double>(n) / static_cast<double>(a.size());
}

}  // namespace toonray::test_support
