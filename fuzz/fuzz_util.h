#pragma once
// Shared helpers for the libFuzzer targets (fuzz/README in docs/robustness.md).
//
// A target feeds its input to one parser. toonray::Error is the parser's way of saying "bad
// input" and is expected; anything else (another exception, a sanitizer report, a FUZZ_CHECK
// failing, a timeout, running out of memory) is a bug.

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <string_view>

#define FUZZ_CHECK(cond)                                                                        \
    do {                                                                                        \
        if (!(cond)) {                                                                          \
            std::fprintf(stderr, "FUZZ_CHECK failed: %s (%s:%d)\n", #cond, __FILE__, __LINE__); \
            std::abort();                                                                       \
        }                                                                                       \
    } while (0)

namespace toonray_fuzz {

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
    return {reinterpret_cast<const char*>(data), size};
}

inline std::span<const std::uint8_t> as_bytes(const std::uint8_t* data, std::size_t size) {
    return {data, size};
}

}  // namespace toonray_fuzz
