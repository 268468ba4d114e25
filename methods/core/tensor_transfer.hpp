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
#include <array>
#include <cstring>
#include <type_traits>
#include <utility>

#include "core/pack.hpp"
#include "core/scatter_forms.hpp"
#include "core/stencil.hpp"
#include "core/types.hpp"
#include "core/velocity_rows.hpp"

namespace mpmtb {

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

// A policy opts in to a path by naming itself in a member type (`using
// TensorPath = ThisPolicy;`): true when Member<Policy> is Policy itself, so that a
// policy derived from one that opted in (and inherits its member) does not.
template <template <class> class Member, class Policy>
constexpr bool names_itself() {
  if constexpr (requires { typename Member<Policy>; }) {
    return std::is_same_v<Member<Policy>, Policy>;
  } else {
    return false;
  }
}
template <class Policy>
using TensorPathOf = typename Policy::TensorPath;
template <class Policy>
using FoldedPathOf = typename Policy::FoldedPath;

// True when Policy itself (not only a base class) opts in to the fast path.
template <class Policy>
constexpr bool has_tensor_path() {
  return names_itself<TensorPathOf, Policy>();
}

// True when Policy itself writes the FoldedForm (FoldedForm above).
template <class Policy>
constexpr bool has_folded_form() {
  return names_itself<FoldedPathOf, Policy>();
}

template <int Dim, class Kernel>
class TensorTransfer;

// True when Policy writes a FoldedForm that the kernel's TensorTransfer takes
// (CPDI's own TensorTransfer, kernels/cpdi.hpp, has no scatter_folded_form).
template <int Dim, class Kernel, class Policy>
constexpr bool takes_folded_form = [] {
  if constexpr (Dim >= 2 && has_folded_form<Policy>()) {
    return requires(const Stencil<Dim, Kernel>& st, const GridGeometry<Dim>& geo,
                    const FoldedForm<Dim>& form, Real* sums) {
      TensorTransfer<Dim, Kernel>::template scatter_folded_form<Policy::scatter_terms>(
          st, geo, form, Real(0), sums);
    };
  } else {
    return false;
  }
}();

template <int Dim, class Kernel>
class TensorTransfer {
  using St = Stencil<Dim, Kernel>;
  static constexpr int S = St::S;

 public:
  // Adds the form to the stencil's nodes of `sums` (NodeSums: N values per node).
  template <TensorTerms T>
  MPMTB_INLINE static void scatter(const St& st, const GridGeometry<Dim>& g,
                                   const ScatterForm<Dim>& form, Real* __restrict sums) {
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
  MPMTB_INLINE static void scatter_folded(const St& st, const GridGeometry<Dim>& g,
                                          const ScatterForm<Dim>& form, Real dt,
                                          Real* __restrict sums) {
    using PF = Row<kFoldedWidth<Dim>>;
    PF gamma[Dim], beta[Dim];
    for (int a = 0; a < Dim; ++a) {
      if constexpr (T.moment) gamma[a] = fold(form.gamma[a], dt);
      if constexpr (T.gradient) beta[a] = fold(form.beta[a], dt);
    }
    scatter_rows<T>(st, g, fold(form.alpha, dt), gamma, beta, form.nodal, sums);
  }

  // The same from a FoldedForm (its columns folded as mp + dt f).
  template <TensorTerms T>
  MPMTB_INLINE static void scatter_folded_form(const St& st, const GridGeometry<Dim>& g,
                                               const FoldedForm<Dim>& form, Real dt,
                                               Real* __restrict sums) {
    static_assert(!T.nodal, "a FoldedForm has no nodal rows");
    const auto fold = [dt](const AxisPack& mp, const AxisPack& f) MPMTB_INLINE_LAMBDA {
      const AxisPack r = mp + dt * f;
      Row<kFoldedWidth<Dim>> row;
      static_assert(sizeof row == sizeof r);
      std::memcpy(&row, &r, sizeof r);
      return row;
    };
    using PF = Row<kFoldedWidth<Dim>>;
    PF gamma[Dim], beta[Dim];
    for (int a = 0; a < Dim; ++a) {
      if constexpr (T.moment) gamma[a] = fold(form.gamma_mp[a], form.gamma_f[a]);
      if constexpr (T.gradient) beta[a] = fold(AxisPack{}, form.beta_f[a]);
    }
    scatter_rows<T>(st, g, fold(form.alpha_mp, form.alpha_f), gamma, beta, nullptr, sums);
  }

  // The stencil sums as they leave the loop, in registers: W = sum w v_i (and
  // v_i_old in the slots after VelocityRows::old), Dm[a] = sum w v_i (x_i - x_p)_a
  // and Gr[a] = sum v_i (grad w)_a, each a row of VelocityRows<Dim, T.old>::N
  // values with v_i's components in its first lanes. A policy may finish from
  // these directly (finish_rows, core/policy_hooks.hpp): converted to GatherSums'
  // Eigen matrices they went through the stack in scalars and came back in
  // packets, which stalled G2P on store forwarding.
  template <TensorTerms T>
  struct Partial {
    static constexpr TensorTerms terms = T;
    using GR = Row<VelocityRows<Dim, T.old>::N>;
    GR W;
    GR Dm[Dim], Gr[Dim];
  };
  template <TensorTerms T>
  MPMTB_INLINE static Partial<T> gather_rows(const St& st, const GridGeometry<Dim>& g,
                                             const Real* __restrict rows,
                                             Real* __restrict nodal = nullptr) {
    AxisPack wd[S];  // w_a d_a of node k, axis a in lane a (as Stencil's factors)
    for (int k = 0; k < S; ++k) wd[k] = st.wk[k] * st.dk[k];
    Partial<T> part;
    gather_strips<T>(st, wd, g.strides(), rows, nodal, part);
    return part;
  }

  // The sums from the packed velocities (VelocityRows<Dim, T.old>::data()); with
  // T.nodal also the stencil's rows themselves, copied to nodal (St::count rows of
  // VelocityRows::N values, last axis fastest).
  template <TensorTerms T>
  MPMTB_INLINE static GatherSums<Dim> gather(const St& st, const GridGeometry<Dim>& g,
                                             const Real* __restrict rows,
                                             Real* __restrict nodal = nullptr) {
    const Partial<T> part = gather_rows<T>(st, g, rows, nodal);
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

  // (m, p + dt f) of a form column: whole registers, (m, p, 0) + dt (0, f, 0),
  // both shuffled from the column's lanes (in registers: lanes written one by
  // one and read back as a register would stall on store forwarding).
  MPMTB_INLINE static Row<kFoldedWidth<Dim>> fold(const typename Form::Col& c, Real dt) {
    using FR = Row<kFoldedWidth<Dim>>;
    const Row<N>& col = c.row();
    const auto lane = [&](int i) MPMTB_INLINE_LAMBDA -> Real {
      return col.v[i / Row<N>::lanes][i % Row<N>::lanes];
    };
    static_assert(FR::K == 1, "a folded row is one register");
    FR mp, f;
    [&]<int... i>(std::integer_sequence<int, i...>) MPMTB_INLINE_LAMBDA {
      constexpr auto in_p = [](int l) { return l >= Form::p && l < Form::p + Dim; };
      mp.v[0] = typename FR::Pack{(i <= Dim ? lane(i) : Real(0))...};
      f.v[0] =
          typename FR::Pack{(in_p(i) ? lane(in_p(i) ? Form::f + i - Form::p : 0) : Real(0))...};
    }
    (std::make_integer_sequence<int, FR::lanes>{});
    FR r = dt * f;  // lane by lane c_p + dt c_f, as (m, p + dt f) was always formed
    r.v[0] = mp.v[0] + r.v[0];
    return r;
  }

  // The scatter over rows of W values per node: alpha, gamma, beta as rows,
  // nodal (TensorTerms::nodal) the policy's rows per node (ScatterForm::nodal).
  template <TensorTerms T, class R>
  MPMTB_INLINE static void scatter_rows(const St& st, const GridGeometry<Dim>& g, const R& alpha,
                                        const R (&gamma)[Dim], const R (&beta)[Dim],
                                        const Real* __restrict nodal, Real* __restrict sums) {
    AxisPack wd[S];  // w_a d_a of node k, axis a in lane a (as Stencil's factors)
    for (int k = 0; k < S; ++k) wd[k] = st.wk[k] * st.dk[k];
    const LastAxis<R::count> last(st, wd);
    // A copy: the geometry's strides, read through a reference after each row's
    // stores, were loaded again for every row.
    const std::array<long, Dim> stride = g.strides();
    scatter_axis<0, T>(st, wd, last, stride, st.base_node, alpha, gamma, beta, nodal, 0, sums);
  }
  // Row j of the stencil (the S nodes along the last axis after the leading
  // axes' index j) of the nodal field, as a strip of S nodes of W values: the
  // nodal rows are kNodalWidth wide, zero beyond.
  template <int W>
  MPMTB_INLINE static Strip<S * W> nodal_strip(const Real* __restrict nodal, int j) {
    constexpr int NW = kNodalWidth<Dim>;
    static_assert(NW <= W, "nodal rows fit in the sums' rows");
    const Real* row = nodal + j * S * NW;
    if constexpr (NW == W) {
      return Strip<S * W>::load(row);
    } else {
      return Strip<S * W>::from([&](int l) MPMTB_INLINE_LAMBDA {
        return l % W < NW ? row[l / W * NW + l % W] : Real(0);
      });
    }
  }

  // The last axis's factors w_k, w_k d_k and dw_k of node k repeated over its W
  // values: lane l of a stencil row (Strip) belongs to node l / W.
  template <int W>
  struct LastAxis {
    using L = Strip<S * W>;
    L w, wd, dw;
    MPMTB_INLINE LastAxis(const St& st, const AxisPack (&wd_k)[S])
        : w(L::from([&](int l) MPMTB_INLINE_LAMBDA { return st.w(Dim - 1, l / W); })),
          wd(L::from([&](int l) MPMTB_INLINE_LAMBDA { return wd_k[l / W][Dim - 1]; })),
          dw(L::from([&](int l) MPMTB_INLINE_LAMBDA { return st.dw(Dim - 1, l / W); })) {}
  };

  // Top down: on entry to axis A, the node value is
  //   alpha prod_{b>=A} w_b + sum_{a>=A} gamma[a] (prod_{b>=A} w_b) d_a
  //                         + sum_{a>=A} beta[a] dw_a prod_{b>=A, b!=a} w_b;
  // j is the stencil index of the axes before A.
  template <int A, TensorTerms T, class R>
  MPMTB_INLINE static inline void scatter_axis(const St& st, const AxisPack (&wd)[S],
                                               const LastAxis<R::count>& last,
                                               const std::array<long, Dim>& stride, long node,
                                               const R& alpha, const R (&gamma)[Dim],
                                               const R (&beta)[Dim], const Real* __restrict nodal,
                                               int j, Real* __restrict sums) {
    constexpr int W = R::count;  // values per node
    if constexpr (A == Dim - 1) {
      // The whole row of S nodes at once (the last axis is the grid's fastest,
      // stride 1: GridGeometry): w alpha + w d gamma + dw beta, lane by lane the
      // same operations as node by node, each term a fused multiply-add onto the
      // node's sums as loaded: a register costs two instructions and its store,
      // where forming the row first and then adding it to the sums took four
      // (3D block, 1 thread: 1.01x-1.07x, medians of 40 interleaved rounds;
      // the sums round differently, at the level of one operation).
      using L = Strip<S * W>;
      Real* out = sums + node * W;
      L acc = L::load(out);
      if constexpr (T.nodal) acc = acc + nodal_strip<W>(nodal, j);
      if constexpr (T.gradient) acc = L::fma(last.dw, L::repeat(beta[A]), acc);
      if constexpr (T.moment) acc = L::fma(last.wd, L::repeat(gamma[A]), acc);
      L::fma(last.w, L::repeat(alpha), acc).store(out);
    } else {
      for (int k = 0; k < S; ++k) {
        const Real w = st.w(A, k);
        R al = w * alpha;
        if constexpr (T.moment) al.add_scaled(wd[k][A], gamma[A]);
        if constexpr (T.gradient) al.add_scaled(st.dw(A, k), beta[A]);
        R g2[Dim], b2[Dim];
        for (int a = A + 1; a < Dim; ++a) {
          if constexpr (T.moment) g2[a] = w * gamma[a];
          if constexpr (T.gradient) b2[a] = w * beta[a];
        }
        scatter_axis<A + 1, T>(st, wd, last, stride, node + k * stride[A], al, g2, b2, nodal,
                               j * S + k, sums);
      }
    }
  }

  // Bottom up: the sums over the sub-stencil of axes A..Dim-1, of whole rows
  // (v_i and v_i_old together).
  template <TensorTerms T>
  using VR = VelocityRows<Dim, T.old>;
  // The gather by stencil rows (Strip): first the sums over the leading axes of
  // whole rows, each row weighted by the product of the leading axes' factors
  // (w_a, or w_a d_a / dw_a for the moment / gradient along axis a; in 3D by
  // slabs, the second axis's factors first and then the first's), then each
  // sum reduced along the last axis with its factors. The same sums as node by
  // node, added in another order; a row costs a load and one fused multiply-add
  // per sum and register.
  template <TensorTerms T>
  struct RowSums {
    using L = Strip<S * VR<T>::N>;
    L W;        // sum_q P(q) R_q
    L Dm[Dim];  // sum_q P(q) with w_a -> w_a d_a, a < Dim - 1
    L Gr[Dim];  // the same with w_a -> dw_a
  };
  // With T.nodal each row is also copied to nodal (row j at nodal + j S N).
  template <TensorTerms T>
  MPMTB_INLINE static void gather_strips(const St& st, const AxisPack (&wd)[S],
                                         const std::array<long, Dim>& stride,
                                         const Real* __restrict rows, Real* __restrict nodal,
                                         Partial<T>& out) {
    using GR = typename Partial<T>::GR;
    using L = typename RowSums<T>::L;
    constexpr int B = Dim - 1;  // the last axis
    RowSums<T> acc;
    acc.W = L::from([](int) MPMTB_INLINE_LAMBDA { return Real(0); });
    for (int a = 0; a < B; ++a) {
      if constexpr (T.moment) acc.Dm[a] = acc.W;
      if constexpr (T.gradient) acc.Gr[a] = acc.W;
    }
    row_sums<T>(st, wd, stride, rows, nodal, acc);
    out.W = reduce_last<GR>(acc.W, st.wk);
    for (int a = 0; a < B; ++a) {
      if constexpr (T.moment) out.Dm[a] = reduce_last<GR>(acc.Dm[a], st.wk);
      if constexpr (T.gradient) out.Gr[a] = reduce_last<GR>(acc.Gr[a], st.wk);
    }
    if constexpr (T.moment) out.Dm[B] = reduce_last<GR>(acc.W, wd);
    if constexpr (T.gradient) out.Gr[B] = reduce_last<GR>(acc.W, st.dwk);
  }
  // Along the last axis: sum_k c_k (row k of the strip), c_k the last axis's
  // factor of node k (lane Dim - 1 of f[k], the stencil's node-major factors).
  template <class GR, class L>
  MPMTB_INLINE static GR reduce_last(const L& strip, const AxisPack (&f)[S]) {
    constexpr int N = GR::count, B = Dim - 1;
    GR r = GR::zero();
    r.template add_scaled_lane<B>(f[0], strip.template segment<0, N>());
    if constexpr (S > 1) r.template add_scaled_lane<B>(f[1], strip.template segment<N, N>());
    if constexpr (S > 2) r.template add_scaled_lane<B>(f[2], strip.template segment<2 * N, N>());
    if constexpr (S > 3) r.template add_scaled_lane<B>(f[3], strip.template segment<3 * N, N>());
    static_assert(S <= 4, "kernels of up to 4 nodes per axis");
    return r;
  }
  // Axis A's factors of the S nodes, node k in lane k, from f node-major (axis
  // a in lane a: the stencil's layout), in two or three shuffles; lanes S and
  // above hold copies (never read).
  template <int A>
  MPMTB_INLINE static AxisPack axis_factors(const AxisPack (&f)[S]) {
    static_assert(S >= 2 && S <= 4, "an AxisPack holds 2 to 4 nodes");
    const AxisPack f01 = __builtin_shufflevector(f[0], f[1], A, 4 + A, A, 4 + A);
    if constexpr (S == 2) {
      return f01;
    } else if constexpr (S == 3) {
      return __builtin_shufflevector(f01, f[2], 0, 1, 4 + A, 4 + A);
    } else {
      const AxisPack f23 = __builtin_shufflevector(f[2], f[3], A, 4 + A, A, 4 + A);
      return __builtin_shufflevector(f01, f23, 0, 1, 4, 5);
    }
  }
  // Row K of the first axis in 2D (row_sums): its factors in lane K of w, md
  // and gd.
  template <int K, TensorTerms T>
  MPMTB_INLINE static void last_row(long node, int j, const Real* __restrict rows,
                                    Real* __restrict nodal, const AxisPack& w,
                                    const AxisPack (&md)[Dim], const AxisPack (&gd)[Dim],
                                    RowSums<T>& acc) {
    using L = typename RowSums<T>::L;
    constexpr int N = VR<T>::N, A = Dim - 1;
    const L row = L::load(rows + node * N);
    if constexpr (T.nodal) row.store(nodal + j * S * N);
    acc.W = L::template fma_lane<K>(w, row, acc.W);
    for (int a = 0; a < A; ++a) {
      if constexpr (T.moment) acc.Dm[a] = L::template fma_lane<K>(md[a], row, acc.Dm[a]);
      if constexpr (T.gradient) acc.Gr[a] = L::template fma_lane<K>(gd[a], row, acc.Gr[a]);
    }
  }
  // The sums over the stencil's rows (RowSums), each row copied to nodal with
  // T.nodal (row j at nodal + j S N): in 1D the one row; in 2D the S rows of
  // the first axis (last_row); in 3D by slabs of the first axis.
  template <TensorTerms T>
  MPMTB_INLINE static void row_sums(const St& st, const AxisPack (&wd)[S],
                                    const std::array<long, Dim>& stride,
                                    const Real* __restrict rows, Real* __restrict nodal,
                                    RowSums<T>& acc) {
    using L = typename RowSums<T>::L;
    constexpr int N = VR<T>::N;
    const long node = st.base_node;
    if constexpr (Dim == 1) {
      const L row = L::load(rows + node * N);
      if constexpr (T.nodal) row.store(nodal);
      acc.W = L::fma(Real(1), row, acc.W);
    } else if constexpr (Dim == 2) {
      // The factors of the S rows at once, row k in lane k, then splat into
      // each row's sums: the per-row scalars had gone through the stack.
      const AxisPack wv = axis_factors<0>(st.wk);
      AxisPack mdv[Dim], gdv[Dim];
      if constexpr (T.moment) mdv[0] = axis_factors<0>(wd);
      if constexpr (T.gradient) gdv[0] = axis_factors<0>(st.dwk);
      [&]<int... k>(std::integer_sequence<int, k...>) MPMTB_INLINE_LAMBDA {
        (last_row<k, T>(node + k * stride[0], k, rows, nodal, wv, mdv, gdv, acc), ...);
      }
      (std::make_integer_sequence<int, S>{});
    } else {
      static_assert(Dim == 3);
      // Each slab k of the first axis summed over the second with that axis's
      // own factors, then the slabs' sums added with the first axis's: per row a
      // fused multiply-add per sum of the second axis and register, its factor
      // splat from the stencil, where the products of the two axes' factors had
      // to be formed and splat for every row (the same sums associated
      // otherwise; 3D block, 1 thread: see CHANGELOG).
      const L zero = L::from([](int) MPMTB_INLINE_LAMBDA { return Real(0); });
      for (int k = 0; k < S; ++k) {
        L sW = zero, sM = zero, sG = zero;  // the slab's sums over the second axis
        for (int k1 = 0; k1 < S; ++k1) {
          const long n = node + k * stride[0] + k1 * stride[1];
          const L row = L::load(rows + n * N);
          if constexpr (T.nodal) row.store(nodal + (k * S + k1) * S * N);
          sW = L::fma(st.w(1, k1), row, sW);
          if constexpr (T.moment) sM = L::fma(wd[k1][1], row, sM);
          if constexpr (T.gradient) sG = L::fma(st.dw(1, k1), row, sG);
        }
        acc.W = L::fma(st.w(0, k), sW, acc.W);
        if constexpr (T.moment) {
          acc.Dm[0] = L::fma(wd[k][0], sW, acc.Dm[0]);
          acc.Dm[1] = L::fma(st.w(0, k), sM, acc.Dm[1]);
        }
        if constexpr (T.gradient) {
          acc.Gr[0] = L::fma(st.dw(0, k), sW, acc.Gr[0]);
          acc.Gr[1] = L::fma(st.w(0, k), sG, acc.Gr[1]);
        }
      }
    }
  }
};

}  // namespace mpmtb
