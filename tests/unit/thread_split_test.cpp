// ThreadSplit (core/thread_split.hpp): contiguous shares of a loop's items,
// even until measured, then in proportion to the threads' measured speeds; and
// StealingShares: the shares taken in chunks, the last ones by other threads.
#include <gtest/gtest.h>

#include <omp.h>
#include <atomic>
#include <cmath>
#include <vector>

#include "core/thread_split.hpp"

namespace mpmtb {
namespace {

// One loop of n items over `threads` threads of the given speeds (items per
// second): each thread's share as the split gives it, its time as the speed
// makes it; then the split's update.
void run_loop(ThreadSplit& split, const std::vector<double>& speed, long n) {
  const int threads = static_cast<int>(speed.size());
  split.open(threads);
  for (int t = 0; t < threads; ++t) {
    const auto [from, to] = split.range(t, threads, n);
    split.record(t, to - from, static_cast<double>(to - from) / speed[t]);
  }
  split.close(threads);
}

// The shares are contiguous, in thread order, and cover every item once.
void expect_partition(const ThreadSplit& split, int threads, long n) {
  EXPECT_EQ(split.cut(0, threads, n), 0);
  EXPECT_EQ(split.cut(threads, threads, n), n);
  for (int k = 0; k < threads; ++k)
    EXPECT_LE(split.cut(k, threads, n), split.cut(k + 1, threads, n));
}

TEST(ThreadSplit, EvenUntilMeasured) {
  ThreadSplit split;
  for (int k = 0; k <= 4; ++k) EXPECT_EQ(split.cut(k, 4, 1000), 250 * k);
  EXPECT_EQ(split.range(1, 3, 10), std::make_pair(3L, 6L));
  expect_partition(split, 7, 100);
}

TEST(ThreadSplit, SharesFollowTheSpeeds) {
  // Thread 0 twice as fast as thread 1: the first update goes half way from the
  // even split (1/2) to the speeds' (2/3), the next ones converge on 2/3.
  ThreadSplit split;
  run_loop(split, {2.0, 1.0}, 1200);
  EXPECT_NEAR(split.cut(1, 2, 1200), 1200 * (0.5 + 2.0 / 3) / 2, 1);
  for (int i = 0; i < 30; ++i) run_loop(split, {2.0, 1.0}, 1200);
  EXPECT_NEAR(split.cut(1, 2, 1200), 800, 1);
  // Then equal speeds bring it back to the even split.
  for (int i = 0; i < 30; ++i) run_loop(split, {1.0, 1.0}, 1200);
  EXPECT_NEAR(split.cut(1, 2, 1200), 600, 1);
  expect_partition(split, 2, 1200);
}

TEST(ThreadSplit, BalancesThreeUnequalThreads) {
  // After convergence every thread takes the same time for its share.
  ThreadSplit split;
  const std::vector<double> speed = {1.0, 3.0, 2.0};
  for (int i = 0; i < 40; ++i) run_loop(split, speed, 60000);
  expect_partition(split, 3, 60000);
  for (int t = 0; t < 3; ++t) {
    const auto [from, to] = split.range(t, 3, 60000);
    EXPECT_NEAR(static_cast<double>(to - from) / speed[t], 60000.0 / 6, 2) << "thread " << t;
  }
}

TEST(ThreadSplit, NoThreadIsStarved) {
  // A thread measured a thousand times slower keeps a share: at least a quarter
  // of the even one before the shares are normalised, a fifth after.
  ThreadSplit split;
  for (int i = 0; i < 30; ++i) run_loop(split, {1000.0, 1.0}, 100000);
  const auto [from, to] = split.range(1, 2, 100000);
  EXPECT_GE(to - from, 100000 / 2 / 5);
  expect_partition(split, 2, 100000);
}

TEST(ThreadSplit, KeepsItsSharesWithoutAMeasurementAndResetsForAnotherThreadCount) {
  ThreadSplit split;
  for (int i = 0; i < 30; ++i) run_loop(split, {2.0, 1.0}, 1200);
  const long cut = split.cut(1, 2, 1200);
  split.open(2);
  split.record(0, 800, 1.0);
  split.record(1, 400, 0.0);  // no time measured
  split.close(2);
  EXPECT_EQ(split.cut(1, 2, 1200), cut);
  // Shares measured with 2 threads say nothing about 3: even again.
  EXPECT_EQ(split.cut(1, 3, 1200), 400);
  EXPECT_EQ(split.cut(2, 3, 1200), 800);
}

// Serially, thread by thread: a thread takes its own share from the front in
// chunks, then the back of the fullest other share; every item exactly once.
TEST(StealingShares, OwnShareFromTheFrontThenOthersFromTheBack) {
  StealingShares shares;
  shares.open(3);
  shares.set(0, 0, 10), shares.set(1, 10, 30), shares.set(2, 30, 35);
  std::vector<int> taken(35, 0);
  long first = 0, last = 0;
  // Thread 0: its own 10 in chunks of 4 (4, 4, 2) from the front.
  for (const long expected : {0L, 4L, 8L}) {
    ASSERT_TRUE(shares.next(0, 3, 4, first, last));
    EXPECT_EQ(first, expected);
    EXPECT_EQ(last, std::min(expected + 4, 10L));
    for (long i = first; i < last; ++i) ++taken[i];
  }
  // Then the back of thread 1's share (20 left, against thread 2's 5).
  ASSERT_TRUE(shares.next(0, 3, 4, first, last));
  EXPECT_EQ(first, 26);
  EXPECT_EQ(last, 30);
  for (long i = first; i < last; ++i) ++taken[i];
  // Threads 1 and 2 go on from their fronts; all three drain what is left.
  for (int t : {1, 2, 0, 1, 2}) {
    while (shares.next(t, 3, 3, first, last)) {
      EXPECT_LT(first, last);
      for (long i = first; i < last; ++i) ++taken[i];
    }
  }
  for (int i = 0; i < 35; ++i) EXPECT_EQ(taken[i], 1) << "item " << i;
  EXPECT_FALSE(shares.next(2, 3, 3, first, last));
}

// In a parallel region, one thread held up at its first chunk: the loop still
// covers every item exactly once (which thread took what is the schedule's
// business; no item is lost or repeated).
TEST(StealingShares, ParallelLoopCoversEveryItemOnce) {
  const long n = 10007;
  const int threads_before = omp_get_max_threads();
  for (const int threads : {1, 2, 3, 4}) {
    std::vector<std::atomic<int>> hits(n);
    omp_set_num_threads(threads);
    std::atomic<bool> held{true};
    for_each_chunk_balanced(n, 16, true, [&](long first, long last) {
      // Thread 0 spins on its first chunk until another thread has gone through
      // its own share and come to take from the others (or alone: at once).
      if (omp_get_thread_num() == 0 && first == 0) {
        while (held.load() && omp_get_num_threads() == threads && threads > 1) {
        }
      }
      if (omp_get_thread_num() != 0 && last > n * (omp_get_thread_num() + 1) / threads)
        held = false;
      if (omp_get_thread_num() != 0 && first < n * omp_get_thread_num() / threads) held = false;
      for (long i = first; i < last; ++i) hits[i].fetch_add(1);
    });
    for (long i = 0; i < n; ++i) ASSERT_EQ(hits[i].load(), 1) << threads << " threads, item " << i;
  }
  omp_set_num_threads(threads_before);  // as the other tests of this process expect
}

}  // namespace
}  // namespace mpmtb
