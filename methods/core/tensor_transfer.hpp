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

#include <type_traits>

#include "core/stencil.hpp"
#include "core/types.hpp"

namespace mpmtb {

// Which of the per-node quantities a transfer uses.
struct TensorTerms {
  bool moment = false;    // w_ip (x_i - x_p)
  bool gradient = false;  // grad w_ip
  bool old = false;       // gather only: sum w_ip v_i_old (FLIP)
};

// The P2G contribution to node i, stacked as (m_i, p_i, f_i, padding):
//   w_ip alpha + sum_a gamma[a] w_ip (x_i - x_p)_a + sum_a beta[a] grad_a w_ip.
template <int Dim>
struct ScatterForm {
  static constexpr int N = 2 * Dim + 2;  // even, so that it packs into SIMD registers
  using Col = Eigen::Matrix<Real, N, 1>;
  Col alpha = Col::Zero();
  Col gamma[Dim];
  Col beta[Dim];
  ScatterForm() {
    for (int a = 0; a < Dim; ++a) gamma[a].setZero(), beta[a].setZero();
  }
  // Slots of the stacked column.
  static constexpr int m = 0, p = 1, f = 1 + Dim;
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
  // Adds the form to the stencil's nodes: m[i], p[i], f[i].
  template <TensorTerms T>
  static void scatter(const St& st, const GridGeometry<Dim>& g, const ScatterForm<Dim>& form,
                      Real* m, Vec<Dim>* p, Vec<Dim>* f) {
    Real wd[Dim][S];
    for (int a = 0; a < Dim; ++a)
      for (int k = 0; k < S; ++k) wd[a][k] = st.w[a][k] * st.d[a][k];
    scatter_axis<0, T>(st, wd, g.strides(), st.base_node, form.alpha, form.gamma, form.beta, m, p,
                       f);
  }

  template <TensorTerms T>
  static GatherSums<Dim> gather(const St& st, const GridGeometry<Dim>& g, const Vec<Dim>* v,
                                const Vec<Dim>* v_old) {
    Real wd[Dim][S];
    for (int a = 0; a < Dim; ++a)
      for (int k = 0; k < S; ++k) wd[a][k] = st.w[a][k] * st.d[a][k];
    Partial part;
    gather_axis<0, T>(st, wd, g.strides(), st.base_node, v, v_old, part);
    GatherSums<Dim> out;
    out.v = part.W;
    if constexpr (T.old) out.v_old = part.W_old;
    for (int a = 0; a < Dim; ++a) {
      if constexpr (T.moment) out.B.col(a) = part.Dm[a];
      if constexpr (T.gradient) out.G.col(a) = part.Gr[a];
    }
    if constexpr (kernel_particle_inertia<Kernel>) out.D_inv = st.inertia_diagonal().cwiseInverse();
    return out;
  }

 private:
  using Col = typename ScatterForm<Dim>::Col;
  using V = Vec<Dim>;

  // Top down: on entry to axis A, the node value is
  //   alpha prod_{b>=A} w_b + sum_{a>=A} gamma[a] (prod_{b>=A} w_b) d_a
  //                         + sum_{a>=A} beta[a] dw_a prod_{b>=A, b!=a} w_b.
  template <int A, TensorTerms T>
  static void scatter_axis(const St& st, const Real (&wd)[Dim][S],
                           const std::array<long, Dim>& stride, long node, const Col& alpha,
                           const Col* gamma, const Col* beta, Real* m, V* p, V* f) {
    for (int k = 0; k < S; ++k) {
      const Real w = st.w[A][k];
      Col al = w * alpha;
      if constexpr (T.moment) al += wd[A][k] * gamma[A];
      if constexpr (T.gradient) al += st.dw[A][k] * beta[A];
      const long n = node + k * stride[A];
      if constexpr (A == Dim - 1) {
        m[n] += al[ScatterForm<Dim>::m];
        p[n] += al.template segment<Dim>(ScatterForm<Dim>::p);
        f[n] += al.template segment<Dim>(ScatterForm<Dim>::f);
      } else {
        Col g2[Dim], b2[Dim];
        for (int a = A + 1; a < Dim; ++a) {
          if constexpr (T.moment) g2[a] = w * gamma[a];
          if constexpr (T.gradient) b2[a] = w * beta[a];
        }
        scatter_axis<A + 1, T>(st, wd, stride, n, al, g2, b2, m, p, f);
      }
    }
  }

  // Bottom up: the sums over the sub-stencil of axes A..Dim-1.
  struct Partial {
    V W, W_old;
    V Dm[Dim], Gr[Dim];
  };
  template <int A, TensorTerms T>
  static void gather_axis(const St& st, const Real (&wd)[Dim][S],
                          const std::array<long, Dim>& stride, long node, const V* v,
                          const V* v_old, Partial& out) {
    out.W.setZero();
    if constexpr (T.old) out.W_old.setZero();
    for (int a = A; a < Dim; ++a) {
      if constexpr (T.moment) out.Dm[a].setZero();
      if constexpr (T.gradient) out.Gr[a].setZero();
    }
    for (int k = 0; k < S; ++k) {
      const Real w = st.w[A][k];
      const long n = node + k * stride[A];
      if constexpr (A == Dim - 1) {
        const V& u = v[n];
        out.W += w * u;
        if constexpr (T.old) out.W_old += w * v_old[n];
        if constexpr (T.moment) out.Dm[A] += wd[A][k] * u;
        if constexpr (T.gradient) out.Gr[A] += st.dw[A][k] * u;
      } else {
        Partial sub;
        gather_axis<A + 1, T>(st, wd, stride, n, v, v_old, sub);
        out.W += w * sub.W;
        if constexpr (T.old) out.W_old += w * sub.W_old;
        if constexpr (T.moment) out.Dm[A] += wd[A][k] * sub.W;
        if constexpr (T.gradient) out.Gr[A] += st.dw[A][k] * sub.W;
        for (int a = A + 1; a < Dim; ++a) {
          if constexpr (T.moment) out.Dm[a] += w * sub.Dm[a];
          if constexpr (T.gradient) out.Gr[a] += w * sub.Gr[a];
        }
      }
    }
  }
};

}  // namespace mpmtb
