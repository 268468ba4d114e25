// The transfers of one particle evaluated axis by axis (sum factorization over
// the tensor-product stencil), the base solver's fast path.
//
// Every transfer in the testbed adds to node i a linear combination of three
// per-node quantities, w_ip, w_ip (x_i - x_p) and grad w_ip, with coefficients
// that depend only on the particle; and reads back sums of the same three
// quantities times v_i. With w_ip = prod_a w_a and grad_a w_ip = dw_a
// prod_{b != a} w_b, these factor axis by axis, so the work per node drops from
// a few 3x3 matrix-vector products to a few fused multiply-adds. A policy opts in
// by declaring which terms it uses (`scatter_terms`, `gather_terms`) and
// providing `scatter_form(Source, ScatterForm&)` and `gather_from(GatherSums)`;
// its per-node `scatter`/`gather` stay the reference definition (a conformance
// test checks that both paths agree to round-off). The opt-in is declared with
// `using TensorPath = ThisPolicy;`: a policy derived from one that opts in, but
// not redeclaring it, falls back to its own per-node math.
#pragma once

#include <algorithm>
#include <type_traits>
#include <vector>

#include "core/pack.hpp"
#include "core/stencil.hpp"
#include "core/types.hpp"

namespace mpmtb {

// Which of the per-node quantities a transfer uses.
struct TensorTerms {
  bool moment = false;    // w_ip (x_i - x_p)
  bool gradient = false;  // grad w_ip
  bool old = false;       // gather only: sum w_ip v_i_old (FLIP)
  // A field over the stencil's own nodes: P2G adds w_ip u_j to p_i, G2P returns
  // w_ip v_i node by node (PolyPIC's per-node polynomial velocity).
  bool nodal = false;
};

// The P2G contribution to node i, stacked as (m_i, p_i, f_i, padding):
//   w_ip alpha + sum_a gamma[a] w_ip (x_i - x_p)_a + sum_a beta[a] grad_a w_ip
//   (+ w_ip nodal[j] in p_i with TensorTerms::nodal, j the node's index in the
//   stencil, last axis fastest).
template <int Dim>
struct ScatterForm {
  static constexpr int N = Dim == 1 ? 4 : 8;  // whole SIMD registers (core/pack.hpp)
  using Col = RowBuilder<N>;                  // set in registers (core/pack.hpp), all zero at first
  Col alpha;
  Col gamma[Dim];
  Col beta[Dim];
  const Vec<Dim>* nodal = nullptr;  // Kernel::support^Dim values (TensorTerms::nodal)
  // Slots of the stacked column.
  static constexpr int m = 0, p = 1, f = 1 + Dim;
};

// Width of a node's sums with the force folded into the momentum, (m_i,
// p_i + dt f_i) padded to whole registers: half the row of (m_i, p_i, f_i).
template <int Dim>
inline constexpr int kFoldedWidth = std::max<int>(Dim == 1 ? 2 : 4,
                                                  16 / static_cast<int>(sizeof(Real)));

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
    if (values.size() != nodes * N) values.assign(nodes * N, Real(0));
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

// G2P's input: for every grid node v_i (and, for the transfers that read it,
// v_i_old) padded to whole SIMD registers (core/pack.hpp), side by side, so
// that a node's contribution to every sum is a few SIMD operations. The solver
// packs the grid's velocities once per gather, over the active box.
template <int Dim, bool kOld>
struct VelocityRows {
  static constexpr int width = Dim == 3 ? 4 : Dim;                       // v_i and its padding
  static constexpr int min_reals = 16 / static_cast<int>(sizeof(Real));  // one SSE register
  static constexpr int N = std::max((kOld ? 2 : 1) * width, min_reals);
  static constexpr int old = width;  // slot of v_old
  std::vector<Real> values;          // N per node, node-major

  void resize(std::size_t nodes) {
    if (values.size() != nodes * N) values.assign(nodes * N, Real(0));
  }
  const Real* data() const { return values.data(); }
  // Packs `count` consecutive nodes from `first` (v_old is read only when kOld).
  void pack(long first, long count, const Vec<Dim>* v, const Vec<Dim>* v_old) {
    for (long i = first; i < first + count; ++i) {
      Real* r = &values[i * N];
      for (int a = 0; a < Dim; ++a) {
        r[a] = v[i][a];
        if constexpr (kOld) r[old + a] = v_old[i][a];
      }
    }
  }
};

// G2P sums over the stencil: v = sum w v_i, B = sum w v_i (x_i - x_p)^T,
// G = sum v_i grad w^T, v_old = sum w v_i_old; and, for kernels whose D_p differs
// per particle (uGIMP), D_inv = D_p^-1 from the stencil (diagonal).
template <int Dim>
struct GatherSums {
  Vec<Dim> v = Vec<Dim>::Zero();
  Mat<Dim> B = Mat<Dim>::Zero();
  Mat<Dim> G = Mat<Dim>::Zero();
  Vec<Dim> v_old = Vec<Dim>::Zero();
  Vec<Dim> D_inv = Vec<Dim>::Zero();
};

// True when Policy itself (not only a base class) opts in to the fast path.
template <class Policy>
constexpr bool has_tensor_path() {
  if constexpr (requires { typename Policy::TensorPath; }) {
    return std::is_same_v<typename Policy::TensorPath, Policy>;
  } else {
    return false;
  }
}

template <int Dim, class Kernel>
class TensorTransfer {
  using St = Stencil<Dim, Kernel>;
  static constexpr int S = St::S;

 public:
  // Adds the form to the stencil's nodes of `sums` (NodeSums: N values per node).
  template <TensorTerms T>
  static void scatter(const St& st, const GridGeometry<Dim>& g, const ScatterForm<Dim>& form,
                      Real* __restrict sums) {
    P gamma[Dim], beta[Dim];
    for (int a = 0; a < Dim; ++a) {
      if constexpr (T.moment) gamma[a] = form.gamma[a].row();
      if constexpr (T.gradient) beta[a] = form.beta[a].row();
    }
    scatter_rows<T>(st, g, form.alpha.row(), gamma, beta, form.nodal, sums);
  }
  // The same into folded sums (NodeSums<Dim, true>): each column of the form
  // becomes (m, p + dt f) before the stencil loop, so every node adds half a row.
  template <TensorTerms T>
  static void scatter_folded(const St& st, const GridGeometry<Dim>& g, const ScatterForm<Dim>& form,
                             Real dt, Real* __restrict sums) {
    using PF = Row<kFoldedWidth<Dim>>;
    PF gamma[Dim], beta[Dim];
    for (int a = 0; a < Dim; ++a) {
      if constexpr (T.moment) gamma[a] = fold(form.gamma[a], dt);
      if constexpr (T.gradient) beta[a] = fold(form.beta[a], dt);
    }
    scatter_rows<T>(st, g, fold(form.alpha, dt), gamma, beta, form.nodal, sums);
  }

  // The sums from the packed velocities (VelocityRows<Dim, T.old>::data()); with
  // T.nodal also nodal[j] = w_ip v_i for the stencil's nodes j (St::count values).
  template <TensorTerms T>
  static GatherSums<Dim> gather(const St& st, const GridGeometry<Dim>& g,
                                const Real* __restrict rows, Vec<Dim>* nodal = nullptr) {
    Real wd[Dim][S];
    for (int a = 0; a < Dim; ++a)
      for (int k = 0; k < S; ++k) wd[a][k] = st.w[a][k] * st.d[a][k];
    Partial<T> part;
    gather_axis<0, T>(st, wd, g.strides(), st.base_node, rows, nodal, 0, Real(1), part);
    GatherSums<Dim> out;
    Real sum[VR<T>::N];
    part.W.store(sum);
    for (int a = 0; a < Dim; ++a) {
      out.v[a] = sum[a];
      if constexpr (T.old) out.v_old[a] = sum[VR<T>::old + a];
    }
    for (int a = 0; a < Dim; ++a) {
      if constexpr (T.moment) {
        part.Dm[a].store(sum);
        for (int b = 0; b < Dim; ++b) out.B(b, a) = sum[b];
      }
      if constexpr (T.gradient) {
        part.Gr[a].store(sum);
        for (int b = 0; b < Dim; ++b) out.G(b, a) = sum[b];
      }
    }
    if constexpr (kernel_particle_inertia<Kernel>) out.D_inv = st.inertia_diagonal().cwiseInverse();
    return out;
  }

 private:
  using V = Vec<Dim>;
  using Form = ScatterForm<Dim>;

  static constexpr int N = Form::N;

  using P = Row<N>;

  // (m, p + dt f) of a form column, in registers.
  MPMTB_INLINE static Row<kFoldedWidth<Dim>> fold(const typename Form::Col& c, Real dt) {
    RowBuilder<kFoldedWidth<Dim>> r;
    r[Form::m] = c[Form::m];
    for (int a = 0; a < Dim; ++a) r[Form::p + a] = c[Form::p + a] + dt * c[Form::f + a];
    return r.row();
  }

  // The scatter over rows of W values per node: alpha, gamma, beta as rows,
  // nodal (TensorTerms::nodal) the per-node momenta that go to the p slots.
  template <TensorTerms T, class R>
  MPMTB_INLINE static void scatter_rows(const St& st, const GridGeometry<Dim>& g, const R& alpha,
                                        const R (&gamma)[Dim], const R (&beta)[Dim],
                                        const Vec<Dim>* nodal_values, Real* __restrict sums) {
    Real wd[Dim][S];
    for (int a = 0; a < Dim; ++a)
      for (int k = 0; k < S; ++k) wd[a][k] = st.w[a][k] * st.d[a][k];
    R nodal[T.nodal ? St::count : 1];
    if constexpr (T.nodal) {
      for (int j = 0; j < St::count; ++j) {
        RowBuilder<R::count> row;
        row.template segment<Dim>(Form::p) = nodal_values[j];
        nodal[j] = row.row();
      }
    }
    scatter_axis<0, T>(st, wd, g.strides(), st.base_node, alpha, gamma, beta, nodal, 0, Real(1),
                       sums);
  }

  // Top down: on entry to axis A, the node value is
  //   alpha prod_{b>=A} w_b + sum_{a>=A} gamma[a] (prod_{b>=A} w_b) d_a
  //                         + sum_{a>=A} beta[a] dw_a prod_{b>=A, b!=a} w_b;
  // j is the stencil index of the axes before A, w_before = prod_{b<A} w_b.
  template <int A, TensorTerms T, class R, int K>
  MPMTB_INLINE static inline void scatter_axis(const St& st, const Real (&wd)[Dim][S],
                                               const std::array<long, Dim>& stride, long node,
                                               const R& alpha, const R (&gamma)[Dim],
                                               const R (&beta)[Dim], const R (&nodal)[K], int j,
                                               Real w_before, Real* __restrict sums) {
    constexpr int W = R::count;  // values per node
    for (int k = 0; k < S; ++k) {
      const Real w = st.w[A][k];
      R al = w * alpha;
      if constexpr (T.moment) al.add_scaled(wd[A][k], gamma[A]);
      if constexpr (T.gradient) al.add_scaled(st.dw[A][k], beta[A]);
      const long n = node + k * stride[A];
      if constexpr (A == Dim - 1) {
        if constexpr (T.nodal) al.add_scaled(w_before * w, nodal[j * S + k]);
        Real* out = sums + n * W;
        R sum = R::load(out);
        sum += al;
        sum.store(out);
      } else {
        R g2[Dim], b2[Dim];
        for (int a = A + 1; a < Dim; ++a) {
          if constexpr (T.moment) g2[a] = w * gamma[a];
          if constexpr (T.gradient) b2[a] = w * beta[a];
        }
        scatter_axis<A + 1, T>(st, wd, stride, n, al, g2, b2, nodal, j * S + k, w_before * w, sums);
      }
    }
  }

  // Bottom up: the sums over the sub-stencil of axes A..Dim-1, of whole rows
  // (v_i and v_i_old together).
  template <TensorTerms T>
  using VR = VelocityRows<Dim, T.old>;
  template <TensorTerms T>
  struct Partial {
    using GR = Row<VR<T>::N>;
    GR W;
    GR Dm[Dim], Gr[Dim];
  };
  template <int A, TensorTerms T>
  MPMTB_INLINE static inline void gather_axis(const St& st, const Real (&wd)[Dim][S],
                                              const std::array<long, Dim>& stride, long node,
                                              const Real* __restrict rows, Vec<Dim>* nodal, int j,
                                              Real w_before, Partial<T>& out) {
    using GR = typename Partial<T>::GR;
    constexpr int N = VR<T>::N;
    out.W = GR::zero();
    for (int a = A; a < Dim; ++a) {
      if constexpr (T.moment) out.Dm[a] = GR::zero();
      if constexpr (T.gradient) out.Gr[a] = GR::zero();
    }
    for (int k = 0; k < S; ++k) {
      const Real w = st.w[A][k];
      const long n = node + k * stride[A];
      if constexpr (A == Dim - 1) {
        const GR u = GR::load(rows + n * N);
        if constexpr (T.nodal) {
          const Real w_ip = w_before * w;
          for (int a = 0; a < Dim; ++a) nodal[j * S + k][a] = w_ip * rows[n * N + a];
        }
        out.W.add_scaled(w, u);
        if constexpr (T.moment) out.Dm[A].add_scaled(wd[A][k], u);
        if constexpr (T.gradient) out.Gr[A].add_scaled(st.dw[A][k], u);
      } else {
        Partial<T> sub;
        gather_axis<A + 1, T>(st, wd, stride, n, rows, nodal, j * S + k, w_before * w, sub);
        out.W.add_scaled(w, sub.W);
        if constexpr (T.moment) out.Dm[A].add_scaled(wd[A][k], sub.W);
        if constexpr (T.gradient) out.Gr[A].add_scaled(st.dw[A][k], sub.W);
        for (int a = A + 1; a < Dim; ++a) {
          if constexpr (T.moment) out.Dm[a].add_scaled(w, sub.Dm[a]);
          if constexpr (T.gradient) out.Gr[a].add_scaled(w, sub.Gr[a]);
        }
      }
    }
  }
};

}  // namespace mpmtb
