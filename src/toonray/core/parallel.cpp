#include "toonray/core/parallel.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <thread>

namespace toonray {

int hardware_threads() { return tbb::this_task_arena::max_concurrency(); }

void parallel_for(int count, int grain, int threads, const std::function<void(int, int)>& body) {
    if (count <= 0) return;
    if (threads == 1) {
        body(0, count);
        return;
    }
    auto run = [&] {
        tbb::parallel_for(tbb::blocked_range<int>(0, count, grain),
                          [&](const tbb::blocked_range<int>& r) { body(r.begin(), r.end()); });
    };
    with_threads(threads, run);
}

void with_threads(int threads, const std::function<void()>& work) {
    if (threads <= 0) {
        work();
        return;
    }
    tbb::task_arena arena(threads);
    arena.execute(work);
}

}  // namespace toonray
