// The process's thread pool (cpp/src/core/thread_pool.hpp, private): every index run once, the
// slots distinct among the threads running at once, the error of the lowest piece rethrown as a
// serial loop would meet it, a nested loop run serially on its caller, and many loops in a row on
// the same threads.
#include "../../cpp/src/core/thread_pool.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <numeric>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

using kincal::detail::parallel_pieces;
using kincal::detail::pool_threads;

TEST(ThreadPool, EveryIndexOnceInManyLoops) {
  for (int loop = 0; loop < 200; ++loop) {
    const size_t n = 1 + static_cast<size_t>(loop) * 37 % 5000, grain = 1 + static_cast<size_t>(loop) % 300;
    std::vector<std::atomic<int>> seen(n);
    std::mutex m;
    std::set<size_t> slots;
    parallel_pieces(n, grain, 0, [&](size_t b, size_t e, size_t slot) {
      ASSERT_LT(slot, pool_threads());
      {
        std::lock_guard<std::mutex> lock(m);
        slots.insert(slot);
      }
      for (size_t i = b; i < e; ++i) seen[i]++;
    });
    for (size_t i = 0; i < n; ++i) ASSERT_EQ(seen[i].load(), 1) << "loop " << loop << " index " << i;
    // (the caller may find every piece taken before it looks: slot 0 need not appear)
    ASSERT_LE(slots.size(), std::min(pool_threads(), (n + grain - 1) / grain));
  }
}

TEST(ThreadPool, TheLowestPiecesErrorIsRethrown) {
  // pieces 3 and 7 throw: whichever thread meets its error first, piece 3's is the one reported
  for (int rep = 0; rep < 50; ++rep) {
    try {
      parallel_pieces(10, 1, 0, [&](size_t b, size_t, size_t) {
        if (b == 7) throw std::runtime_error("piece 7");
        if (b == 3) {
          std::this_thread::yield();
          throw std::runtime_error("piece 3");
        }
      });
      FAIL() << "no exception";
    } catch (const std::runtime_error& e) {
      // piece 7 may run first and stop the handing out before 3 starts only if 3 was not handed out:
      // pieces go in increasing order, so 3 was handed out before 7 and runs to its error
      EXPECT_EQ(std::string(e.what()), "piece 3");
    }
  }
}

TEST(ThreadPool, NestedLoopsRunOnTheirCaller) {
  std::atomic<size_t> total{0};
  parallel_pieces(8, 1, 0, [&](size_t, size_t, size_t) {
    const std::thread::id me = std::this_thread::get_id();
    parallel_pieces(100, 10, 0, [&](size_t b, size_t e, size_t slot) {
      EXPECT_EQ(std::this_thread::get_id(), me);  // no other thread takes an inner piece
      EXPECT_EQ(slot, 0u);
      total += e - b;
    });
  });
  EXPECT_EQ(total.load(), 800u);
}

TEST(ThreadPool, AtMostTheThreadsAsked) {
  std::mutex m;
  std::set<size_t> slots;
  parallel_pieces(1000, 1, 1, [&](size_t, size_t, size_t slot) {
    std::lock_guard<std::mutex> lock(m);
    slots.insert(slot);
  });
  EXPECT_EQ(slots, std::set<size_t>{0});
}
