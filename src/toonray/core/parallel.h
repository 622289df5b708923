#pragma once
/// Thread control. Work is split into fixed tiles or rows, each written by exactly one task,
/// so results never depend on the thread count.

#include <functional>

namespace toonray {

/// Runs body(begin, end) over [0, count) in chunks of `grain`, on at most `threads` threads
/// (0 = all hardware threads). Blocks until done.
void parallel_for(int count, int grain, int threads, const std::function<void(int, int)>& body);

/// Hardware threads available to this process.
int hardware_threads();

}  // namespace toonray
