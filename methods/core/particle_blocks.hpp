// P2G's block colouring: the particles binned into blocks of span - 1 or span
// cells (bin()) along the first two axes, in 2^axes colours, so that the blocks of one
// colour scatter in parallel without locks (Solver, core/solver_impl.hpp).
#pragma once

#include <omp.h>
#include <algorithm>
#include <array>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include "core/state.hpp"
#include "core/stencil.hpp"
#include "core/thread_split.hpp"

namespace mpmtb {

// The nodes a particle's stencil spans from its first node along an axis: the
// support, or the stencil's own kSpan where its nodes may start later (CPDI's box).
template <int Dim, class Kernel>
constexpr int stencil_span() {
  if constexpr (requires { Stencil<Dim, Kernel>::kSpan; }) {
    return Stencil<Dim, Kernel>::kSpan;
  } else {
    return Kernel::support;
  }
}

// The first stencil node per axis of a position (padded index, as Stencil's
// base_node), every axis at once, one per lane, clamped so that a stray particle
// cannot index out of range (the same operations lane by lane: perf showed the
// axis-by-axis loop, with its branches for the bounds, at three quarters of the
// binning).
template <int Dim, class Kernel>
class FirstNodes {
 public:
  explicit FirstNodes(const GridGeometry<Dim>& geo) : inv_dx_(geo.inv_dx) {
    for (int a = 0; a < Dim; ++a) {
      origin_[a] = geo.lo[a];
      low_[a] = Real(-pad);
      high_[a] = Real(geo.cells[a] + pad);
    }
  }
  MPMTB_INLINE AxisInts operator()(const Vec<Dim>& x) const {
    AxisPack xp{};
    for (int a = 0; a < Dim; ++a) xp[a] = x[a];
    AxisPack xi = (xp - origin_) * inv_dx_;
    xi = xi < low_ ? low_ : xi;  // std::clamp's comparisons
    xi = high_ < xi ? high_ : xi;
    return Stencil<Dim, Kernel>::first_indices(xi) + pad;
  }

 private:
  static constexpr int pad = GridGeometry<Dim>::pad;
  AxisPack origin_{}, low_{}, high_{};
  Real inv_dx_;
};

// The lowest and highest first node per axis (FirstNodes) over the particles
// p < n for which take(p) holds, x(p) their positions; each(p, f) sees the first
// nodes of every particle taken. {max int, min int} per lane when none is taken.
// Min and max are exact, so the range does not depend on the thread count.
template <int Dim, class Kernel, class Take, class Position, class Each>
std::pair<AxisInts, AxisInts> first_node_range(const GridGeometry<Dim>& geo, long n, Take&& take,
                                               Position&& x, Each&& each) {
  const FirstNodes<Dim, Kernel> first_nodes(geo);
  AxisInts lo = AxisInts{} + std::numeric_limits<int>::max();
  AxisInts hi = AxisInts{} + std::numeric_limits<int>::min();
#pragma omp parallel if (n >= kParallelMinimum)
  {
    AxisInts lo_t = lo, hi_t = hi;
#pragma omp for schedule(static) nowait
    for (long p = 0; p < n; ++p) {
      if (!take(p)) continue;
      const AxisInts f = first_nodes(x(p));
      lo_t = f < lo_t ? f : lo_t;
      hi_t = hi_t < f ? f : hi_t;
      each(p, f);
    }
#pragma omp critical(mpmtb_first_node_range)
    {
      lo = lo_t < lo ? lo_t : lo;
      hi = hi < hi_t ? hi_t : hi;
    }
  }
  return {lo, hi};
}

template <int Dim, class Kernel>
class ParticleBlocks {
  using StencilT = Stencil<Dim, Kernel>;

 public:
  // Sets the grid's active box to the nodes the particles' stencils reach, plus
  // GridGeometry::pad layers along every axis on which a wall is within reach
  // (the mirrors of its ghosts), and sorts the particle ids
  // by colour, then block (a stable counting sort: particle order within a block).
  void bin(State<Dim>& s) { bin(s.particles.x, s.grid.geo, s.grid.active, &s.walls); }
  // Sizes (and touches) the per-particle arrays for n particles ahead of the first bin().
  void size_for(std::size_t n) { first_.resize(n), block_of_.resize(n), block_order_.resize(n); }
  // The same for positions x on a grid geo: `box` is set to their nodes, with
  // the pad along every axis when no walls are given.
  void bin(const std::vector<Vec<Dim>>& x, const GridGeometry<Dim>& geo, NodeBox<Dim>& box,
           const Walls<Dim>* walls = nullptr) {
    constexpr int S = stencil_span<Dim, Kernel>(), pad = GridGeometry<Dim>::pad;
    const long n = static_cast<long>(x.size());
    first_.resize(n);
    const auto range = first_node_range<Dim, Kernel>(
        geo, n, [](long) { return true; }, [&](long p) -> const Vec<Dim>& { return x[p]; },
        [&](long p, const AxisInts& f) {
          for (int a = 0; a < kColouredAxes; ++a) first_[p][a] = f[a];
        });
    const AxisInts lo = range.first, hi = range.second;
    for (int a = 0; a < Dim; ++a) {
      // The pad only along an axis with a wall within reach: there the grid
      // update must sweep the mirror of every ghost a stencil reaches (a
      // particle on the face reaches ghosts two nodes out with the cubic
      // B-spline, but mirrors only one node in). Elsewhere the pad's nodes have
      // no mass and no stencil reads them: the pinned block's box (4 cells
      // thick) had 10 nodes per row with it, 6 without, and twice the nodes.
      const int margin = !walls || walls->near(geo, a, lo[a], hi[a] + S - 1, pad) ? pad : 0;
      box.lo[a] = n ? std::max(0, lo[a] - margin) : 0;
      box.hi[a] = n ? std::min(geo.nodes(a) - 1, hi[a] + S - 1 + margin) : -1;
    }
    // Blocks of W cells from the lowest first node, half of them per colour and
    // axis. A thread's share of a colour is whole blocks, so more blocks balance
    // the threads better, but narrower blocks sweep more of the sums per
    // particle. Measured on the 3D block at 2 threads (4-5 interleaved rounds), the
    // narrowest width that colours (span - 1) against the span: quadratic 1.05x,
    // uGIMP 1.08x, linear 1.03x, but cubic 0.95x and cpGIMP 0.93x. So spans of up
    // to 3 nodes take span - 1 where that gives each colour more blocks, wider
    // ones keep the span. W depends on the positions alone, never on the threads.
    const auto blocks_per_colour = [&](int width, std::array<int, kColouredAxes>& half) {
      int count = 1;
      for (int a = 0; a < kColouredAxes; ++a) {
        half[a] = n ? ((hi[a] - lo[a]) / width + 2) / 2 : 1;
        count *= half[a];
      }
      return count;
    };
    std::array<int, kColouredAxes> half{}, narrow_half{};
    int W = span();
    int per_colour = blocks_per_colour(W, half);
    if (const int narrow = blocks_per_colour(kNarrowestWidth, narrow_half);
        span() <= 3 && narrow > per_colour) {
      W = kNarrowestWidth, per_colour = narrow, half = narrow_half;
    }
    block_of_.resize(n);
    block_start_.assign(kColours * per_colour + 1, 0);
    // The width as a constant: a division by a variable per particle and axis
    // would cost more than the binning's other work.
    const auto assign = [&]<int kWidth>() {
#pragma omp parallel for schedule(static) if (n >= kParallelMinimum)
      for (long p = 0; p < n; ++p) {
        int colour = 0, index = 0;
        for (int a = 0; a < kColouredAxes; ++a) {
          const int b = (first_[p][a] - lo[a]) / kWidth;
          colour |= (b & 1) << a;
          index = index * half[a] + b / 2;
        }
        block_of_[p] = colour * per_colour + index;
      }
    };
    if (W == span()) {
      assign.template operator()<span()>();
    } else {
      assign.template operator()<kNarrowestWidth>();
    }
    sort_into_blocks(n);
  }

  // block_order_: the particle ids by block_of_, stable (index order within a
  // block), and block_start_: where each block starts in it. A counting sort in
  // parallel: each thread counts, then places, its own run of ids, and the runs
  // of the threads follow each other in every block, so the order is the serial one.
  void sort_into_blocks(long n) {
    const std::size_t blocks = block_start_.size() - 1;
    block_order_.resize(n);
#pragma omp parallel if (n >= kParallelMinimum)
    {
      const long threads = omp_get_num_threads(), t = omp_get_thread_num();
#pragma omp single
      fill_.assign(threads * blocks, 0);  // then the implicit barrier
      int* mine = &fill_[t * blocks];
      const long from = n * t / threads, to = n * (t + 1) / threads;
      // Consecutive particles mostly share a block (the setup's lattice order runs
      // along the last axis, which the blocks do not split): the counts and the
      // places go by runs of one block, kept in a register, instead of a load of
      // the count that the previous particle has just stored.
      for (long p = from; p < to;) {
        const int b = block_of_[p];
        long end = p + 1;
        while (end < to && block_of_[end] == b) ++end;
        mine[b] += static_cast<int>(end - p);
        p = end;
      }
#pragma omp barrier
#pragma omp single
      {
        int start = 0;
        for (std::size_t b = 0; b < blocks; ++b) {
          block_start_[b] = start;
          for (long u = 0; u < threads; ++u) {
            const int c = fill_[u * blocks + b];
            fill_[u * blocks + b] = start;
            start += c;
          }
        }
        block_start_[blocks] = start;
      }
      for (long p = from; p < to;) {
        const int b = block_of_[p];
        int place = mine[b];
        for (; p < to && block_of_[p] == b; ++p) block_order_[place++] = static_cast<int>(p);
        mine[b] = place;
      }
    }
  }

  // Blocks of span - 1 or span cells along the first two axes: the stencils of
  // blocks two apart never overlap, so the blocks of one colour (the parity of
  // their block coordinates) scatter in parallel, one colour after the other.
  // No locks, and the summation order (and so the result) does not depend on
  // the thread count. Each thread takes a run of consecutive blocks holding its
  // share of the colour's particles: balanced, and the same region of space in
  // every colour and step, so that the particles a thread scatters are mostly
  // those it gathers (G2P splits the particles in index order, which follows
  // space: the lattice order of the setup) and stay in its core's caches.
  // f(colour, ids) for every block of the last bin(), colour by colour: the
  // particle ids of the block, in the order the scatter takes them (tests).
  template <class F>
  void for_each_block(F&& f) const {
    const int per_colour = static_cast<int>(block_start_.size() - 1) / kColours;
    for (int colour = 0; colour < kColours; ++colour) {
      for (int k = colour * per_colour; k < (colour + 1) * per_colour; ++k) {
        f(colour, std::span<const int>(block_order_.data() + block_start_[k],
                                       block_order_.data() + block_start_[k + 1]));
      }
    }
  }

  // The scatter above: scatter(p) for every particle of the last bin(); before
  // each, ahead(q) with the particle q the thread takes next (to fetch its records).
  struct NothingAhead {
    void operator()(int) const {}
  };
  template <class Scatter, class Ahead = NothingAhead>
  void for_each_coloured(const State<Dim>& s, Scatter&& scatter, Ahead&& ahead = {}) const {
    for_each_share(s, [&](int from, int to) MPMTB_INLINE_LAMBDA {
      for (int k = from; k < to; ++k) {
        if (k + 1 < to) ahead(block_order_[k + 1]);
        scatter(block_order_[k]);
      }
    });
  }
  // The same a run of up to `run` particles at a time, in the same order:
  // f(ids, count, next, next_count) with the run's particles ids[0] .. ids[count - 1]
  // and the next run the thread takes, next[0] .. next[next_count - 1].
  template <class Run>
  void for_each_coloured_run(const State<Dim>& s, int run, Run&& f) const {
    for_each_share(s, [&](int from, int to) MPMTB_INLINE_LAMBDA {
      for (int k = from; k < to; k += run) {
        const int count = std::min(run, to - k);
        const int next_count = std::min(run, to - k - count);
        f(block_order_.data() + k, count, block_order_.data() + k + count, next_count);
      }
    });
  }

 private:
  // share(from, to) with each thread's share of each colour, the indices into
  // block_order_ [from, to), the colours one after the other.
  template <class Share>
  void for_each_share(const State<Dim>& s, Share&& share_of) const {
    const bool parallel = static_cast<long>(s.particles.size()) >= kParallelMinimum;
    const int per_colour = static_cast<int>(block_start_.size() - 1) / kColours;
    split_.open();
    int threads_used = 1;
#pragma omp parallel if (parallel)
    {
      const int threads = omp_get_num_threads(), t = omp_get_thread_num();
      if (t == 0) threads_used = threads;
      double busy = 0;  // this thread's time in its blocks, without the barriers
      long scattered = 0;
      for (int colour = 0; colour < kColours; ++colour) {
        const auto first = block_start_.begin() + colour * per_colour;
        const auto last = first + per_colour;
        const long count = *last - *first;
        // The block boundary nearest to the thread's share of the particles (the
        // first block at or after it left up to a whole block's imbalance); the
        // shares follow the threads' speeds in the last call (ThreadSplit).
        const auto share = [&](int k) {
          if (k == threads) return last;
          const int target = static_cast<int>(*first + split_.cut(k, threads, count));
          const auto after = std::lower_bound(first, last, target);
          if (after == first) return after;
          return target - *(after - 1) < *after - target ? after - 1 : after;
        };
        const auto from = share(t), to = share(t + 1);
        const double start = omp_get_wtime();
        share_of(*from, *to);
        busy += omp_get_wtime() - start;
        scattered += *to - *from;
#pragma omp barrier
      }
      split_.record(t, scattered, busy);
    }
    split_.close(threads_used);
  }

  // Blocks over the first two axes (one in 1D), 2^axes colours. (Blocks over
  // all three axes in 3D, 8 colours, measured 23 % slower on the 3D block at one
  // thread: each colour's scatter sweeps most of the grid's sums, twice as often.)
  static constexpr int kColouredAxes = Dim >= 2 ? 2 : 1;
  static constexpr int span() {
    return stencil_span<Dim, Kernel>();
  }
  // A particle of block b (first nodes b W .. b W + W - 1) reaches nodes up to
  // b W + W + span - 2, short of block b + 2's first node (b + 2) W when
  // W >= span - 1: the narrowest blocks that colour.
  static constexpr int kNarrowestWidth = span() - 1 > 0 ? span() - 1 : 1;
  static constexpr int kColours = 1 << kColouredAxes;
  std::vector<std::array<int, kColouredAxes>> first_;  // first stencil node per coloured axis
  std::vector<int> block_of_, block_start_, block_order_, fill_;
  mutable ThreadSplit split_;  // the threads' shares of each colour's particles
};

}  // namespace mpmtb
