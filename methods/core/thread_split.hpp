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
#include <atomic>
#include <cmath>
#include <cstdint>
#include <memory>
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

// The threads' shares of a loop whose items are independent (G2P), taken in
// chunks: each thread from the front of its own share, and, once that is
// empty, from the back of the share with the most left. The speeds ThreadSplit
// measured size the shares, so little is ever taken; what is balances the
// step-to-step swings of the cores' speeds that the shares cannot follow (perf,
// 3D block at 2 threads: a thread waited at G2P's end for 3.5 % of the run).
class StealingShares {
 public:
  // Serially, before the parallel region: room for every thread it may have.
  void open(int max_threads = omp_get_max_threads()) {
    if (count_ < max_threads)
      shares_ = std::make_unique<Share[]>(max_threads), count_ = max_threads;
  }
  // Thread t's share [from, to): set for every thread before the parallel
  // region, or by thread t inside it, followed by a barrier before any take.
  void set(int t, long from, long to) {
    shares_[t].bounds.store(pack(from, to), std::memory_order_relaxed);
  }
  // By thread t: the next chunk [first, last) of at most `chunk` items; false
  // when every share is empty.
  bool next(int t, int threads, long chunk, long& first, long& last) {
    if (take(shares_[t], chunk, true, first, last)) return true;
    for (;;) {
      int victim = -1;
      long most = 0;
      for (int u = 0; u < threads; ++u) {
        const long left = size(shares_[u].bounds.load(std::memory_order_relaxed));
        if (u != t && left > most) most = left, victim = u;
      }
      if (victim < 0) return false;
      if (take(shares_[victim], chunk, false, first, last)) return true;
    }
  }

 private:
  // A share's front (low 32 bits) and back (high 32 bits), changed together.
  struct alignas(64) Share {
    std::atomic<std::uint64_t> bounds{0};
  };
  std::unique_ptr<Share[]> shares_;
  int count_ = 0;

  static std::uint64_t pack(long front, long back) {
    return static_cast<std::uint32_t>(front) | std::uint64_t{static_cast<std::uint32_t>(back)}
                                                   << 32;
  }
  static long front_of(std::uint64_t b) { return static_cast<long>(b & 0xffffffffu); }
  static long back_of(std::uint64_t b) { return static_cast<long>(b >> 32); }
  static long size(std::uint64_t b) { return std::max(0L, back_of(b) - front_of(b)); }
  // A chunk off the front (the owner) or the back (a thief); false if empty.
  static bool take(Share& s, long chunk, bool front, long& first, long& last) {
    std::uint64_t b = s.bounds.load(std::memory_order_relaxed);
    for (;;) {
      const long lo = front_of(b), hi = back_of(b), c = std::min(chunk, hi - lo);
      if (c <= 0) return false;
      const std::uint64_t taken = front ? pack(lo + c, hi) : pack(lo, hi - c);
      if (s.bounds.compare_exchange_weak(b, taken, std::memory_order_relaxed)) {
        first = front ? lo : hi - c;
        last = first + c;
        return true;
      }
    }
  }
};

// f(first, last) over [0, n) in chunks of `chunk`, in parallel if `parallel`:
// each thread starts on an even share, then takes from the others' backs
// (StealingShares). For loops whose items are independent and cheap enough
// that no speeds are kept for them (the stress pass: on the 3D block at 2
// threads, an even static split left a thread waiting there for 5 % of the
// run). The shares are set before the region, for the team it is planned to
// have: no barrier is needed before the first take. A team of another size
// (nested regions) splits evenly, without stealing.
template <class F>
void for_each_chunk_balanced(long n, long chunk, bool parallel, F&& f) {
  const int planned = parallel ? omp_get_max_threads() : 1;
  StealingShares shares;
  shares.open(planned);
  for (int t = 0; t < planned; ++t) shares.set(t, n * t / planned, n * (t + 1) / planned);
#pragma omp parallel if (parallel)
  {
    const int threads = omp_get_num_threads(), t = omp_get_thread_num();
    long first = 0, last = 0;
    if (threads == planned) {
      while (shares.next(t, threads, chunk, first, last)) f(first, last);
    } else if (n * t / threads < n * (t + 1) / threads) {
      f(n * t / threads, n * (t + 1) / threads);
    }
  }
}

}  // namespace mpmtb
