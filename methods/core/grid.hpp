// Uniform background grid: geometry and the nodal arrays of one step.
#pragma once

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "huge_pages.hpp"
#include "types.hpp"

namespace mpmtb {

// Geometry of a uniform grid over the box [lo, hi] with `cells` cells per axis
// and `pad` ghost nodes beyond each face, so that every kernel stencil of a
// particle inside the box lies on the grid.
template <int Dim>
struct GridGeometry {
  static constexpr int pad = 2;  // enough for the cubic B-spline (4 nodes per axis)

  Vec<Dim> lo = Vec<Dim>::Zero();
  Real dx = 1;
  Real inv_dx = 1;  // 1 / dx, divided once (every stencil scales by it)
  std::array<int, Dim> cells{};
  // Particle half-width in cell units, l = 1/(2 ppc), for kernels that average over
  // the particle domain (uGIMP, kernels/gimp.hpp); set from the scene's ppc. The
  // default is two particles per cell per axis.
  Real l = Real(0.25);

  GridGeometry() = default;
  GridGeometry(const Vec<Dim>& lower, Real spacing, const std::array<int, Dim>& n)
      : lo(lower), dx(spacing), inv_dx(1 / spacing), cells(n) {
    long stride = 1;
    for (int a = Dim - 1; a >= 0; --a) {
      strides_[a] = stride;
      stride *= nodes(a);
    }
    node_count_ = stride;
  }

  Vec<Dim> hi() const {
    Vec<Dim> h;
    for (int a = 0; a < Dim; ++a) h[a] = lo[a] + cells[a] * dx;
    return h;
  }
  int nodes(int axis) const { return cells[axis] + 1 + 2 * pad; }
  long node_count() const { return node_count_; }
  const std::array<long, Dim>& strides() const { return strides_; }

  // Node coordinate along one axis for a padded node index.
  Real coordinate(int axis, int i) const { return lo[axis] + (i - pad) * dx; }

  std::array<int, Dim> multi_index(long node) const {
    std::array<int, Dim> idx{};
    for (int a = 0; a < Dim; ++a) {
      idx[a] = static_cast<int>(node / strides_[a]);
      node %= strides_[a];
    }
    return idx;
  }
  Vec<Dim> position(long node) const {
    const auto idx = multi_index(node);
    Vec<Dim> x;
    for (int a = 0; a < Dim; ++a) x[a] = coordinate(a, idx[a]);
    return x;
  }
  // True when the point lies inside the box [lo, hi] (closed).
  bool contains(const Vec<Dim>& x) const {
    for (int a = 0; a < Dim; ++a) {
      if (!(x[a] >= lo[a] && x[a] <= lo[a] + cells[a] * dx)) return false;
    }
    return true;
  }

 private:
  std::array<long, Dim> strides_{};
  long node_count_ = 0;
};

// A box of node indices [lo, hi] (inclusive per axis; empty when lo > hi),
// swept as rows: runs of consecutive nodes along the last axis.
template <int Dim>
struct NodeBox {
  std::array<int, Dim> lo{}, hi{};
  NodeBox() { lo.fill(0), hi.fill(-1); }

  long rows() const {
    long r = 1;
    for (int a = 0; a + 1 < Dim; ++a) r *= std::max(0, hi[a] - lo[a] + 1);
    return hi[Dim - 1] < lo[Dim - 1] ? 0 : r;
  }
  long nodes() const {
    const long r = rows();
    return r ? r * (hi[Dim - 1] - lo[Dim - 1] + 1) : 0;
  }
  // First node and length of row r (0 <= r < rows()) on a grid of these strides.
  std::pair<long, int> row(long r, const std::array<long, Dim>& strides) const {
    long node = lo[Dim - 1];
    for (int a = Dim - 2; a >= 0; --a) {
      const long extent = hi[a] - lo[a] + 1;
      node += (lo[a] + r % extent) * strides[a];
      r /= extent;
    }
    return {node, hi[Dim - 1] - lo[Dim - 1] + 1};
  }
  // f(first, count) for every row, in parallel when the box is large.
  template <class F>
  void for_each_row(const std::array<long, Dim>& strides, F&& f) const {
    const long n = rows();
#pragma omp parallel for schedule(static) if (nodes() >= kParallelMinimum)
    for (long r = 0; r < n; ++r) {
      const auto [first, count] = row(r, strides);
      f(first, static_cast<long>(count));
    }
  }
  // f(first, count) for every run of nodes along the last axis that lies in
  // this box but not in `inner`, one after the other.
  template <class F>
  void for_each_row_outside(const NodeBox& inner, const std::array<long, Dim>& strides,
                            F&& f) const {
    const long n = rows();
    const int lo_last = lo[Dim - 1], hi_last = hi[Dim - 1];
    for (long r = 0; r < n; ++r) {
      const auto [first, count] = row(r, strides);
      bool leading_inside = true;  // the row's indices on the leading axes lie in inner
      long rest = r;
      for (int a = Dim - 2; a >= 0; --a) {
        const long extent = hi[a] - lo[a] + 1;
        const int index = lo[a] + static_cast<int>(rest % extent);
        rest /= extent;
        leading_inside = leading_inside && index >= inner.lo[a] && index <= inner.hi[a];
      }
      const int in_lo = std::max(lo_last, inner.lo[Dim - 1]);
      const int in_hi = std::min(hi_last, inner.hi[Dim - 1]);
      if (!leading_inside || in_lo > in_hi) {
        f(first, static_cast<long>(count));
        continue;
      }
      if (in_lo > lo_last) f(first, static_cast<long>(in_lo - lo_last));
      if (in_hi < hi_last) f(first + (in_hi + 1 - lo_last), static_cast<long>(hi_last - in_hi));
    }
  }
  // f(node) for every node, in parallel over the rows.
  template <class F>
  void for_each_node(const std::array<long, Dim>& strides, F&& f) const {
    for_each_row(strides, [&](long first, long count) {
      for (long i = first; i < first + count; ++i) f(i);
    });
  }
};

// Nodal fields. p_i is the momentum transferred from the particles, f_i the
// internal force; the grid update turns them into v_i.
template <int Dim>
struct Grid {
  GridGeometry<Dim> geo;
  std::vector<Real> m;               // m_i
  std::vector<Vec<Dim>> p;           // p_i  momentum (before forces)
  std::vector<Vec<Dim>> f;           // f_i  internal force
  std::vector<Vec<Dim>> v;           // v_i  velocity after the grid update
  std::vector<Vec<Dim>> v_old;       // v_i before forces (kept for FLIP-like transfers)
  std::vector<std::uint8_t> pinned;  // nodes held at rest by pinned particles
  // The box of nodes outside which every nodal field is zero: the solver
  // clears, updates and sweeps only this box, so the grid's cost follows the
  // region the particles occupy, not the domain. Empty on a fresh grid.
  NodeBox<Dim> active;

  explicit Grid(const GridGeometry<Dim>& g = {}) : geo(g) {
    const auto n = static_cast<std::size_t>(g.node_count());
    assign_on_huge_pages(m, n, Real(0));
    assign_on_huge_pages(p, n, Vec<Dim>(Vec<Dim>::Zero()));
    assign_on_huge_pages(f, n, Vec<Dim>(Vec<Dim>::Zero()));
    assign_on_huge_pages(v, n, Vec<Dim>(Vec<Dim>::Zero()));
    assign_on_huge_pages(v_old, n, Vec<Dim>(Vec<Dim>::Zero()));
    assign_on_huge_pages(pinned, n, std::uint8_t{0});
  }
  std::size_t size() const { return m.size(); }

  // The active box's rows (runs of consecutive nodes along the last axis).
  long active_rows() const { return active.rows(); }
  long active_nodes() const { return active.nodes(); }
  std::pair<long, int> active_row(long r) const { return active.row(r, geo.strides()); }
};

}  // namespace mpmtb
