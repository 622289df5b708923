#pragma once
/// Parallel work in fixed chunks, each chunk's output kept apart and joined in chunk order, so
/// that results do not depend on the thread count or on how tasks were scheduled.

#include <algorithm>
#include <vector>

#include "toonray/core/parallel.h"

namespace toonray::ink {

/// Runs body(begin, end, out) over [0, count) in chunks of `chunk` items, each with its own
/// output vector, and returns the outputs concatenated in chunk order.
template <typename T, typename Body>
std::vector<T> gather_chunks(int count, int chunk, int threads, const Body& body) {
    const int chunks = count <= 0 ? 0 : (count + chunk - 1) / chunk;
    std::vector<std::vector<T>> parts(static_cast<std::size_t>(chunks));
    parallel_for(chunks, 1, threads, [&](int c0, int c1) {
        for (int c = c0; c < c1; ++c)
            body(c * chunk, std::min(count, (c + 1) * chunk), parts[static_cast<std::size_t>(c)]);
    });
    std::size_t total = 0;
    for (const auto& p : parts) total += p.size();
    std::vector<T> out;
    out.reserve(total);
    for (auto& p : parts)
        out.insert(out.end(), std::make_move_iterator(p.begin()), std::make_move_iterator(p.end()));
    return out;
}

}  // namespace toonray::ink
