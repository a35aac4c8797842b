// The work pool: every index once, in parallel; and (issue 18) an exception from a loop body on
// any thread reaches the caller instead of ending the process, and the pool goes on working.

#include "common/work_pool.hpp"

#include <atomic>
#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace surroundd {
namespace {

TEST(WorkPool, CoversEveryIndexOnce) {
  WorkPool pool(4);
  std::vector<std::atomic<int>> seen(1000);
  pool.parallelFor(
      1000,
      [&](int begin, int end) {
        for (int i = begin; i < end; ++i) ++seen[static_cast<std::size_t>(i)];
      },
      16);
  for (const auto& count : seen) EXPECT_EQ(count, 1);
}

TEST(WorkPool, AnExceptionOnAnyThreadReachesTheCallerAndThePoolGoesOn) {
  WorkPool pool(4);
  const auto caller = std::this_thread::get_id();
  // Every chunk but the caller's throws: the exception comes from a worker at least once.
  for (int round = 0; round < 20; ++round) {
    EXPECT_THROW(pool.parallelFor(
                     64,
                     [&](int begin, int /*end*/) {
                       if (std::this_thread::get_id() != caller || begin % 2 == 0) {
                         throw std::runtime_error("chunk " + std::to_string(begin));
                       }
                     },
                     64),
                 std::runtime_error);
  }
  std::atomic<int> sum{0};
  pool.parallelFor(100, [&](int begin, int end) {
    for (int i = begin; i < end; ++i) sum += i;
  });
  EXPECT_EQ(sum, 4950);
}

}  // namespace
}  // namespace surroundd
