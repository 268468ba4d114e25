// Contiguous shares of a parallel loop's items per thread, sized by the
// threads' measured speeds. The cores of a shared machine do not run at one
// speed: on the 2-core VM this testbed is measured on, one core ran the same
// 1-thread run 25 % slower than the other for seconds at a time, and an even
// split then left the faster thread waiting at every barrier (perf: 13 % of
// its samples). Each loop records how long each thread took for its share, and
// the next call gives each thread a share in proportion to its speed. The
// shares stay contiguous and move by little from step to step, so a thread
// keeps most of its particles in its caches (a dynamic schedule, which
// balances too, measured 0.86x for losing them). Which thread does which items
// never changes a result: the loops that use a split compute each item alone
// (G2P) or, in P2G, each block alone within a colour.
#pragma once

#include <omp.h>
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace mpmtb {

class ThreadSplit {
 public:
  // Serially, before the parallel region: room for every thread it may have.
  void open(int max_threads = omp_get_max_threads()) {
    const auto threads = static_cast<std::size_t>(max_threads);
    if (seconds_.size() < threads) seconds_.assign(threads, 0), items_.assign(threads, 0);
  }
  // Where thread k's share of n items starts (k = threads: n), even until
  // speeds were measured with this thread count.
  long cut(int k, int threads, long n) const {
    if (k <= 0) return 0;
    if (k >= threads) return n;
    if (static_cast<int>(start_.size()) != threads + 1) return n * k / threads;
    return std::clamp(std::lround(start_[k] * static_cast<double>(n)), 0L, n);
  }
  std::pair<long, long> range(int t, int threads, long n) const {
    return {cut(t, threads, n), cut(t + 1, threads, n)};
  }
  // By thread t, inside the region: it took `seconds` for `items` items.
  void record(int t, long items, double seconds) {
    items_[t] = items;
    seconds_[t] = seconds;
  }
  // Serially, after the region: the next shares, each thread's in proportion
  // to its measured items per second, averaged with the current shares (one
  // slow step, an interrupt, moves them by half of its effect). In place: no
  // allocation in the steps, but where the thread count changed.
  void close(int threads) {
    double total = 0;
    for (int t = 0; t < threads; ++t) {
      if (!(seconds_[t] > 0) || items_[t] <= 0) return;  // nothing measured: keep
      total += speed(t);
    }
    if (static_cast<int>(start_.size()) != threads + 1) {  // even shares to start from
      start_.resize(threads + 1);
      for (int k = 0; k <= threads; ++k) start_[k] = static_cast<double>(k) / threads;
    }
    double old_start = start_[0];
    for (int t = 0; t < threads; ++t) {
      const double share = start_[t + 1] - old_start;
      old_start = start_[t + 1];
      // No thread below a quarter of the even share: a stalled measurement
      // must not starve a thread.
      const double next = std::max(0.5 * (share + speed(t) / total), 0.25 / threads);
      start_[t + 1] = start_[t] + next;
    }
    for (int t = 1; t <= threads; ++t) start_[t] /= start_[threads];
  }

 private:
  std::vector<double> start_;  // cumulative shares, threads + 1 of them (empty: even)
  std::vector<double> seconds_;
  std::vector<long> items_;

  double speed(int t) const { return static_cast<double>(items_[t]) / seconds_[t]; }
};

}  // namespace mpmtb
