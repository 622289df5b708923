#include "toonray/core/parallel.h"

#include <gtest/gtest.h>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>

namespace toonray {
namespace {

// The threads that run a TBB loop of many slow-enough items.
std::set<std::thread::id> threads_of_a_loop() {
    std::mutex mutex;
    std::set<std::thread::id> seen;
    tbb::parallel_for(0, 256, [&](int) {
        volatile double x = 0;
        for (int k = 0; k < 20000; ++k) x = x + k;
        std::lock_guard lock(mutex);
        seen.insert(std::this_thread::get_id());
    });
    return seen;
}

TEST(Parallel, WithThreadsKeepsTheTbbAlgorithmsInsideToThatCount) {
    int inside = 0;
    std::set<std::thread::id> seen;
    with_threads(1, [&] {
        inside = tbb::this_task_arena::max_concurrency();
        seen = threads_of_a_loop();
    });
    EXPECT_EQ(inside, 1);
    ASSERT_EQ(seen.size(), 1u);
    EXPECT_EQ(*seen.begin(), std::this_thread::get_id());  // the caller runs it all
    with_threads(2, [&] { inside = tbb::this_task_arena::max_concurrency(); });
    EXPECT_EQ(inside, 2);
    with_threads(0, [&] { inside = tbb::this_task_arena::max_concurrency(); });
    EXPECT_EQ(inside, hardware_threads());
}

TEST(Parallel, WithThreadsPassesOnWhatTheWorkThrows) {
    EXPECT_THROW(with_threads(1, [] { throw std::runtime_error("stop"); }), std::runtime_error);
    EXPECT_THROW(with_threads(0, [] { throw std::runtime_error("stop"); }), std::runtime_error);
}

}  // namespace
}  // namespace toonray
