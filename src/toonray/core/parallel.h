#pragma once
/// Thread control. Work is split into fixed tiles or rows, each written by exactly one task,
/// so results never depend on the thread count.

#include <functional>

#include <tbb/enumerable_thread_specific.h>

namespace toonray {

/// Runs body(begin, end) over [0, count) in chunks of `grain`, on at most `threads` threads
/// (0 = all hardware threads). Blocks until done.
void parallel_for(int count, int grain, int threads, const std::function<void(int, int)>& body);

/// Runs work() with the TBB algorithms it calls (a BVH build's tasks and loops) on at most
/// `threads` threads (0 = all hardware threads), so that a thread count asked for holds for
/// every stage of a frame, not only those that take one. Blocks until done.
void with_threads(int threads, const std::function<void()>& work);

/// Hardware threads available to this process.
int hardware_threads();

/// One T for each thread that runs parallel_for bodies, made on its first use there and kept,
/// so that per-thread buffers are allocated once for a whole animation. What a T holds must not
/// decide any result (which thread runs which work varies from run to run).
template <typename T>
class PerThread {
public:
    /// The calling thread's T.
    T& local() { return values_.local(); }
    /// Every T made so far.
    template <typename F>
    void for_each(F&& f) const {
        for (const T& value : values_) f(value);
    }

private:
    tbb::enumerable_thread_specific<T> values_;
};

}  // namespace toonray
