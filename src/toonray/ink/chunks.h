#pragma once
/// Parallel work in fixed chunks, each chunk's output kept apart and joined in chunk order, so
/// that results do not depend on the thread count or on how tasks were scheduled.

#include <algorithm>
#include <iterator>
#include <vector>

#include "toonray/core/parallel.h"

namespace toonray::ink {

/// Runs body(begin, end, out) over [0, count) in chunks of `chunk` items, each with its own
/// output vector, and returns those outputs in chunk order.
template <typename T, typename Body>
std::vector<std::vector<T>> chunk_outputs(int count, int chunk, int threads, const Body& body) {
    const int chunks = count <= 0 ? 0 : (count + chunk - 1) / chunk;
    std::vector<std::vector<T>> parts(static_cast<std::size_t>(chunks));
    parallel_for(chunks, 1, threads, [&](int c0, int c1) {
        for (int c = c0; c < c1; ++c)
            body(c * chunk, std::min(count, (c + 1) * chunk), parts[static_cast<std::size_t>(c)]);
    });
    return parts;
}

/// How many bytes of freed parts append_parts lets pile up before it hands free memory back to
/// the system: parts smaller than the allocator's mmap threshold are freed into its arenas,
/// where they would stay resident beside the joined copy.
inline constexpr std::size_t kReturnToSystem = std::size_t{64} << 20;

/// Gives the allocator's free memory back to the system (glibc's malloc_trim; elsewhere nothing).
void return_free_memory();

/// Appends `parts` to `out` in order, growing `out` once by `extra` more items than the parts
/// hold (for what the caller appends next), and frees each part once it is moved: the
/// joined items are then held about once rather than twice (large outputs, a crowd's lines).
template <typename T>
void append_parts(std::vector<std::vector<T>>& parts, std::vector<T>& out, std::size_t extra = 0) {
    std::size_t total = out.size() + extra;
    for (const auto& p : parts) total += p.size();
    out.reserve(total);
    std::size_t freed = 0;
    for (auto& p : parts) {
        out.insert(out.end(), std::make_move_iterator(p.begin()), std::make_move_iterator(p.end()));
        freed += p.capacity() * sizeof(T);
        std::vector<T>().swap(p);
        if (freed >= kReturnToSystem) {
            return_free_memory();
            freed = 0;
        }
    }
}

/// chunk_outputs joined into one vector.
template <typename T, typename Body>
std::vector<T> gather_chunks(int count, int chunk, int threads, const Body& body) {
    std::vector<std::vector<T>> parts = chunk_outputs<T>(count, chunk, threads, body);
    std::vector<T> out;
    append_parts(parts, out);
    return out;
}

}  // namespace toonray::ink
