// What a policy hands the fast path (core/tensor_transfer.hpp) in P2G: which
// per-node quantities its transfers use (TensorTerms), its per-particle form
// (ScatterForm, or FoldedForm for folded sums), and P2G's accumulator of those
// forms over the grid (NodeSums). TensorTransfer adds the forms to the
// accumulator over each particle's stencil.
#pragma once

#include <algorithm>
#include <cstring>
#include <utility>
#include <vector>

#include "core/huge_pages.hpp"
#include "core/pack.hpp"
#include "core/stencil.hpp"
#include "core/types.hpp"

namespace mpmtb {

// Which of the per-node quantities a transfer uses.
struct TensorTerms {
  bool moment = false;    // w_ip (x_i - x_p)
  bool gradient = false;  // grad w_ip
  bool old = false;       // gather only: sum w_ip v_i_old (FLIP)
  // A field over the stencil's own nodes: P2G adds the policy's row for node j
  // (already weighted: w_ip m_p v_p(x_i) for PolyPIC's polynomial velocity) to
  // the node's sums, G2P copies the packed rows v_i of the stencil's nodes out.
  bool nodal = false;
};

// The P2G contribution to node i, stacked as (m_i, p_i, f_i, padding):
//   w_ip alpha + sum_a gamma[a] w_ip (x_i - x_p)_a + sum_a beta[a] grad_a w_ip
//   (+ row j of nodal with TensorTerms::nodal, j the node's index in the stencil,
//   last axis fastest).
template <int Dim>
struct ScatterForm {
  static constexpr int N = Dim == 1 ? 4 : 8;  // whole SIMD registers (core/pack.hpp)
  using Col = RowBuilder<N>;                  // set in registers (core/pack.hpp), all zero at first
  Col alpha;
  Col gamma[Dim];
  Col beta[Dim];
  // TensorTerms::nodal: Kernel::support^Dim rows of kNodalWidth values, added to
  // the first kNodalWidth values of each node's sums (the m and p slots).
  const Real* nodal = nullptr;
  // Slots of the stacked column.
  static constexpr int m = 0, p = 1, f = 1 + Dim;
};

// Width of a node's sums with the force folded into the momentum, (m_i,
// p_i + dt f_i) padded to whole registers: half the row of (m_i, p_i, f_i).
template <int Dim>
inline constexpr int kFoldedWidth = std::max<int>(Dim == 1 ? 2 : 4,
                                                  16 / static_cast<int>(sizeof(Real)));
// Width of ScatterForm::nodal's rows: the (m, p) slots, padded as a folded row.
template <int Dim>
inline constexpr int kNodalWidth = kFoldedWidth<Dim>;

// P2G's accumulator: for every grid node the stacked column (m_i, p_i, f_i,
// padding) of ScatterForm, its N values side by side. A node's update is then a
// few contiguous SIMD adds instead of scalar adds to three arrays; the solver
// unpacks the sums into the grid's fields once per step, over the active box.
// kFolded: the rows hold (m_i, p_i + dt f_i) instead (TensorTransfer::
// scatter_folded), for the transfers that never read the velocity before the
// forces (v_old): the grid update's v_i = (p_i + dt f_i) / m_i + dt g is then the
// same symplectic Euler step, with half the row to scatter and unpack.
template <int Dim, bool kFolded = false>
struct NodeSums {
  static constexpr int N = kFolded ? kFoldedWidth<Dim> : ScatterForm<Dim>::N;
  using Form = ScatterForm<Dim>;
  std::vector<Real> values;  // N per node, node-major

  // Sized for a grid of `nodes` nodes, all zero when the size changes.
  void resize(std::size_t nodes) {
    if (values.size() != nodes * N) assign_on_huge_pages(values, nodes * N, Real(0));
  }
  Real* data() { return values.data(); }
  // Zeroes `count` consecutive nodes from `first`.
  void clear(long first, long count) {
    std::fill_n(values.begin() + first * N, count * N, Real(0));
  }
  // m_i, p_i, f_i <- the sums of `count` consecutive nodes from `first` (only f_i
  // when kMomentum is false: the sums then hold forces only), and, when kDrain,
  // zero those sums, so that they are zero again for the next scatter. Folded
  // rows set m_i and p_i (the force is in p_i) and leave f_i as it is.
  template <bool kMomentum, bool kDrain>
  void unpack(long first, long count, Real* m, Vec<Dim>* p, Vec<Dim>* f) {
    static_assert(kMomentum || !kFolded, "folded sums always hold the momentum");
    for (long i = first; i < first + count; ++i) {
      Real* s = &values[i * N];
      if constexpr (kMomentum) m[i] = s[Form::m];
      for (int a = 0; a < Dim; ++a) {
        if constexpr (kMomentum) p[i][a] = s[Form::p + a];
        if constexpr (!kFolded) f[i][a] = s[Form::f + a];
      }
      if constexpr (kDrain) std::fill_n(s, N, Real(0));
    }
  }
};

// P2G's form for folded sums (NodeSums<Dim, true>), written by a policy
// straight into whole registers: each column as its (m, p) part and its force
// part, both laid out as a folded row (m, then Dim momentum or force lanes, then
// padding: AxisPack). The scatter folds each column as mp + dt f, the same
// operations lane by lane as TensorTransfer::fold of the ScatterForm column
// (m, p, f), so the sums keep their bits; the columns are built from the
// particle's matrices by whole-register loads (column_lanes) instead of lane by
// lane (perf: the form, its fold and the last axis's factors had about a third
// of the scatter's samples).
// A policy opts in with `folded_form(Source, FoldedForm&)` and `using FoldedPath
// = ThisPolicy;` (a derived policy that changes scatter_form must not inherit it).
template <int Dim>
struct FoldedForm {
  static_assert(Dim >= 2, "1D folded rows are narrower than an AxisPack");
  static_assert(kFoldedWidth<Dim> == 4, "a folded row is one AxisPack");
  AxisPack alpha_mp{}, alpha_f{};
  AxisPack gamma_mp[Dim]{}, gamma_f[Dim]{};
  AxisPack beta_f[Dim]{};  // (no transfer has a beta in the (m, p) part)
  // alpha's (m, p) part: (m_p, m_p v_p).
  MPMTB_INLINE void set_mass_momentum(Real m, const Vec<Dim>& mv) {
    alpha_mp = AxisPack{m, mv[0], mv[1], Dim == 3 ? mv[Dim - 1] : Real(0)};
  }
};

// Column a of M in lanes 1..Dim (the momentum lanes of a folded row), lane 0 and
// the padding zero: one unaligned load inside M's storage and one blend or shuffle.
template <int a, int Dim>
MPMTB_INLINE inline AxisPack column_lanes(const Mat<Dim>& M) {
  static_assert(sizeof(Mat<Dim>) == Dim * Dim * sizeof(Real), "M is stored dense, column-major");
  constexpr AxisPack zero{};
  AxisPack v;
  if constexpr (Dim == 3) {
    // Four values from (0, a) - 1 (from (0, 0) for a = 0): all inside M.
    std::memcpy(&v, M.data() + (a == 0 ? 0 : 3 * a - 1), sizeof v);
    if constexpr (a == 0)
      return __builtin_shufflevector(v, zero, 4, 0, 1, 2);
    else
      return __builtin_shufflevector(v, zero, 4, 1, 2, 3);
  } else {
    static_assert(Dim == 2);
    std::memcpy(&v, M.data(), sizeof v);  // the whole matrix
    return __builtin_shufflevector(v, zero, 4, 2 * a, 2 * a + 1, 4);
  }
}

}  // namespace mpmtb
