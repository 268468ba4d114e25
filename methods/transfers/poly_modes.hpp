// PolyPIC's modes of one particle (Fu, Guo, Gast, Jiang & Teran 2017, "A
// Polynomial Particle-In-Cell Method", ACM TOG 36(6) 222, sec. 4-5): the 1D
// polynomials per axis, orthogonal under the kernel weights (Gram-Schmidt), the
// records the pass before P2G keeps of them, and the weighted transforms between
// mode coefficients and nodal values (transfers/polypic.hpp uses them).
#pragma once

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>
#include <utility>

#include "core/pack.hpp"
#include "core/stencil.hpp"
#include "core/types.hpp"

namespace mpmtb {

// The 1D polynomials e_n of one particle along each axis, orthogonal under the
// kernel weights: sum_k w_a(k) e_n(u_k) e_m(u_k) = 0 for n != m, with
// u_k = (x_i - x_p)_a / dx the node offsets in cell units. The tensor products
// s_r(i) = prod_a e_{r_a}(u_{i_a}) are then orthogonal under w_ip = prod_a w_a,
// and their norms factor: sum_i w_ip s_r(i)^2 = prod_a norm(a, r_a).
// Lanes: one register with a lane per axis (AxisPack), or one twice as wide
// holding the axes of two particles (keep_group in 3D).
template <int Dim, int S, class Lanes = AxisPack>
struct PolyModes {
  static constexpr int count = ipow(S, Dim);  // modes = stencil nodes

  // Per mode n and node k, one register with axis a in lane a, as the stencil's
  // factors (the build runs all axes at once and stores whole registers):
  Lanes e_[S][S];      // e_n at node k
  Lanes norm_[S];      // sum_k w_a(k) e_n(u_k)^2; 0 for a dropped mode
  Lanes unit_[S][S];   // e_n / sqrt(norm) for n >= 1 (0 if dropped), e_0 = 1 (norm 1)
  Lanes wunit_[S][S];  // w_a(k) unit_n(k): the weight folded in (the transforms)
  Lanes root_norm_;    // sqrt(norm_1): e_1 = root_norm unit_1
  Lanes d0_;           // offset of node 0 per axis
  Real inv_dx;
  bool kept_only_ = false;  // restore(): only wunit_ and root_norm_ are set

  Real e(int a, int n, int k) const { return e_[n][k][a]; }
  Real norm(int a, int n) const { return norm_[n][a]; }
  Real unit(int a, int n, int k) const { return unit_[n][k][a]; }
  Real wunit(int a, int n, int k) const { return wunit_[n][k][a]; }
  Real root_norm(int a) const { return root_norm_[a]; }

  // Gram-Schmidt of the monomials 1, u, u^2, ... under the weights, twice over
  // ("twice is enough"): orthogonal to round-off relative to each e_n's own size,
  // so the higher modes add no momentum beyond round-off. (Stieltjes' three-term
  // recurrence, cheaper, left the cubic B-spline's e_3 visibly non-orthogonal to
  // 1 where an end weight is tiny: a rigid translation then made strain.) A mode
  // whose norm falls below a relative tolerance of its monomial's is degenerate
  // (fewer weighted nodes than modes, e.g. the linear hat at a node, or the
  // quadratic B-spline half-way between nodes): it and every higher one are dropped.
  // The axes are independent: each runs in one lane of the stencil's AxisPacks
  // (padding lanes have zero weights, so their modes are dropped and never read).
  template <class Kernel>
  MPMTB_INLINE void build(const Stencil<Dim, Kernel>& st, Real dx) {
    static_assert(Kernel::support == S);
    build_lanes(st.wk, st.dk, dx);
  }
  // The same from the weights w_a(k) and offsets (x_i - x_p)_a of node k, lane
  // by lane: lanes hold axes, of one particle or of several (keep_group).
  MPMTB_INLINE void build_lanes(const Lanes (&w)[S], const Lanes (&d)[S], Real dx) {
    if constexpr (S == 3) {
      build_three(w, d, dx);
    } else {
      build_by_gram_schmidt(w, d, dx);
    }
  }
  MPMTB_INLINE void build_by_gram_schmidt(const Lanes (&w)[S], const Lanes (&d)[S], Real dx) {
    inv_dx = 1 / dx;
    root_norm_ = Lanes{};  // set at n = 1 below (GCC cannot always tell)
    const Lanes tol = 1000 * std::numeric_limits<Real>::epsilon() - Lanes{}, zero{};
    Lanes u[S], power[S], q[S][S], inv_norm[S];
    for (int k = 0; k < S; ++k) {
      u[k] = d[k] * inv_dx;
      power[k] = 1 - Lanes{};
    }
    auto dropped = zero < zero;  // all lanes false
    // Unrolled whole (perf: as loops, the triangular m < n branched and kept the
    // values in memory), so that every index is a constant.
#pragma GCC unroll 8
    for (int n = 0; n < S; ++n) {
      for (int k = 0; k < S; ++k) q[n][k] = power[k];
#pragma GCC unroll 2
      for (int pass = 0; pass < 2; ++pass) {
#pragma GCC unroll 8
        for (int m = 0; m < n; ++m) {
          Lanes dot{};
          for (int k = 0; k < S; ++k) dot += w[k] * q[n][k] * q[m][k];
          const Lanes c = dot * inv_norm[m];
          for (int k = 0; k < S; ++k) q[n][k] -= c * q[m][k];
        }
      }
      Lanes nn{}, monomial{};
      for (int k = 0; k < S; ++k) {
        nn += w[k] * q[n][k] * q[n][k];
        monomial += w[k] * power[k] * power[k];
        power[k] *= u[k];
      }
      dropped = dropped | ~(nn > tol * monomial);  // lane masks: NaN is dropped too
      norm_[n] = dropped ? zero : nn;
      inv_norm[n] = dropped ? zero : 1 / nn;
    }
    for (int n = 0; n < S; ++n) {
      // The partition of unity makes e_0 = 1 a unit mode (sum_k w_a(k) = 1).
      Lanes inv_root = 1 - zero;
      if (n > 0) inv_root = inv_norm[n], axis_sqrt_in_place(inv_root);
      for (int k = 0; k < S; ++k) {
        e_[n][k] = q[n][k];
        unit_[n][k] = q[n][k] * inv_root;
        wunit_[n][k] = w[k] * unit_[n][k];
      }
      if (n == 1) root_norm_ = norm_[1] * inv_root;  // sqrt(norm), 0 if dropped
    }
    d0_ = d[0];
  }

  // Three nodes (quadratic B-spline, uGIMP): the same modes in closed form, a
  // few short chains instead of Gram-Schmidt's long one (the 3D quadratic step
  // builds every particle's modes twice). On three equally spaced nodes the
  // quadratic mode is the one vector orthogonal under the weights to 1 and u:
  // e_2(u_k) = (2 / N) c_k / w_k with c = (1, -2, 1), the second difference,
  // which annihilates every affine function of the u_k, and N = sum_k c_k^2 /
  // w_k (2 = the second difference of u^2, so e_2 is u^2 less its projections
  // on 1 and u). Its norm is 4 / N and its unit mode's weighted values are
  // w_k unit_2(k) = c_k / sqrt(N), which sum to 0 exactly. e_1 = u - mu with mu
  // = sum_k w_k u_k / sum_k w_k (one Gram-Schmidt pass: the weights sum to 1,
  // the first moment is small). A zero weight makes N infinite and e_2 dropped;
  // the tolerances are Gram-Schmidt's, on these norms.
  MPMTB_INLINE void build_three(const Lanes (&w)[3], const Lanes (&d)[3], Real dx) {
    inv_dx = 1 / dx;
    const Lanes tol = 1000 * std::numeric_limits<Real>::epsilon() - Lanes{}, zero{};
    const Lanes one = 1 - zero;
    Lanes u[3], u2[3];
    for (int k = 0; k < 3; ++k) u[k] = d[k] * inv_dx, u2[k] = u[k] * u[k];
    const Lanes sum_w = (w[0] + w[1]) + w[2];
    const auto dropped0 = ~(sum_w > tol * sum_w);         // lane masks: NaN is dropped too
    const Lanes inv_sum = dropped0 ? zero : one / sum_w;  // padding lanes: 0, e_1 = u
    const Lanes mu = ((w[0] * u[0] + w[1] * u[1]) + w[2] * u[2]) * inv_sum;
    Lanes e1[3];
    for (int k = 0; k < 3; ++k) e1[k] = u[k] - mu;
    const Lanes n1 = (w[0] * e1[0] * e1[0] + w[1] * e1[1] * e1[1]) + w[2] * e1[2] * e1[2];
    const Lanes m1 = (w[0] * u2[0] + w[1] * u2[1]) + w[2] * u2[2];
    const auto dropped1 = dropped0 | ~(n1 > tol * m1);
    Lanes inv_w[3];
    for (int k = 0; k < 3; ++k) inv_w[k] = one / w[k];
    const Lanes inv_N = one / ((inv_w[0] + 4 * inv_w[1]) + inv_w[2]);
    const Lanes n2 = 4 * inv_N;
    const Lanes m2 = (w[0] * u2[0] * u2[0] + w[1] * u2[1] * u2[1]) + w[2] * u2[2] * u2[2];
    const auto dropped2 = dropped1 | ~(n2 > tol * m2);
    norm_[0] = dropped0 ? zero : sum_w;
    norm_[1] = dropped1 ? zero : n1;
    norm_[2] = dropped2 ? zero : n2;
    Lanes inv_root1 = one / n1, inv_root2 = inv_N;
    axis_sqrt_in_place(inv_root1), axis_sqrt_in_place(inv_root2);
    inv_root1 = dropped1 ? zero : inv_root1;
    inv_root2 = dropped2 ? zero : inv_root2;
    constexpr Real c[3] = {1, -2, 1};
    for (int k = 0; k < 3; ++k) {
      e_[0][k] = one, unit_[0][k] = one, wunit_[0][k] = w[k];
      e_[1][k] = e1[k], unit_[1][k] = e1[k] * inv_root1, wunit_[1][k] = w[k] * unit_[1][k];
      const Lanes e2 = 2 * c[k] * inv_w[k] * inv_N;
      e_[2][k] = dropped2 ? zero : e2;
      unit_[2][k] = dropped2 ? zero : c[k] * inv_w[k] * inv_root2;
      wunit_[2][k] = c[k] * inv_root2;
    }
    root_norm_ = norm_[1] * inv_root1;  // sqrt(norm), 0 if dropped
    d0_ = d[0];
  }

  // What G2P reads of the modes (to_modes, root_norm), kept from P2G's build at
  // the same stencil (PolypicPolicy::Kept): P2G and G2P of a step build the
  // same modes, the particles not having moved between them.
  // Only the axes' lanes: the record is memory traffic, written and read once.
  struct Kept {
    Real wunit[S][S][Dim];
    Real root_norm[Dim];
  };
  // From the lanes first .. first + Dim - 1 (a particle's axes).
  // (K: the Kept of any Lanes; keep_group's build is wider than the record's user.)
  template <class K>
  MPMTB_INLINE void keep(K& k, int first = 0) const {
    for (int n = 0; n < S; ++n)
      for (int j = 0; j < S; ++j)
        for (int a = 0; a < Dim; ++a) k.wunit[n][j][a] = wunit_[n][j][first + a];
    for (int a = 0; a < Dim; ++a) k.root_norm[a] = root_norm_[first + a];
  }
  // G2P's modes from a record keep() wrote (to_modes and root_norm only; the
  // padding lanes zero, as the build leaves them).
  MPMTB_INLINE void restore(const Kept& k) {
    const auto lanes = [](const Real* v) MPMTB_INLINE_LAMBDA {
      Lanes r{};
      for (int a = 0; a < Dim; ++a) r[a] = v[a];
      return r;
    };
    for (int n = 0; n < S; ++n)
      for (int j = 0; j < S; ++j) wunit_[n][j] = lanes(k.wunit[n][j]);
    root_norm_ = lanes(k.root_norm);
    kept_only_ = true;
  }
  // The records (keep) of G particles' modes from one build: particle g's axes
  // in lanes g L .. g L + Dim - 1 of one register (L = Dim, or 4 in 3D: an
  // AxisPack per particle, two in a register twice as wide). Every operation of
  // the build is lane by lane, so each record is the one its particle's own
  // build gives, bit for bit, in one chain of dependent operations instead of G
  // (the build is bound by that chain's latency, not by the operations).
  static constexpr int kGroupLanes = Dim == 3 ? 4 : Dim;  // L, a particle's lanes
  // Particles a build takes together: 4 in 2D where their 8 lanes fit one
  // register (AVX-512 in double, AVX in float), else 2.
  static constexpr int kGroup = Dim == 2 && 4 * Dim * sizeof(Real) <= kSimdBytes ? 4 : 2;
  template <int G, class Kernel>
  static void keep_group(const Stencil<Dim, Kernel>* const (&st)[G], Real dx,
                         Kept* const (&kept)[G]) {
    static_assert(std::is_same_v<Lanes, AxisPack>);
    constexpr int L = kGroupLanes;
    static_assert(G * L <= 8, "a group fills at most two AxisPacks");
    using Group = typename PackOf<std::max(4, G * L) * sizeof(Real)>::type;
    // The lanes of the G particles' factors side by side (x[g]: particle g's),
    // in shuffles of register pairs. (Written through a reference: a 64-byte
    // vector returned by value draws GCC's ABI warning on targets without AVX-512.)
    const auto group = [](const AxisPack(&x)[G], Group& out) MPMTB_INLINE_LAMBDA {
      if constexpr (L == 1) {
        static_assert(G == 2);
        out = __builtin_shufflevector(x[0], x[1], 0, 4, 2, 3);
      } else if constexpr (L == 2 && G == 2) {
        out = __builtin_shufflevector(x[0], x[1], 0, 1, 4, 5);
      } else if constexpr (L == 2) {
        static_assert(G == 4);
        const AxisPack x01 = __builtin_shufflevector(x[0], x[1], 0, 1, 4, 5);
        const AxisPack x23 = __builtin_shufflevector(x[2], x[3], 0, 1, 4, 5);
        out = __builtin_shufflevector(x01, x23, 0, 1, 2, 3, 4, 5, 6, 7);
      } else {
        static_assert(L == 4 && G == 2);
        out = __builtin_shufflevector(x[0], x[1], 0, 1, 2, 3, 4, 5, 6, 7);
      }
    };
    Group w[S], d[S];
    for (int k = 0; k < S; ++k) {
      AxisPack wk[G], dk[G];
      for (int g = 0; g < G; ++g) wk[g] = st[g]->wk[k], dk[g] = st[g]->dk[k];
      group(wk, w[k]), group(dk, d[k]);
    }
    PolyModes<Dim, S, Group> all;
    all.build_lanes(w, d, dx);
    for (int g = 0; g < G; ++g) all.keep(*kept[g], g * L);
  }
  // The stencil index (last axis fastest, as Stencil::for_each_node) of the node
  // at offset d = x_i - x_p.
  int node_index(const Vec<Dim>& d) const {
    assert(!kept_only_);
    int index = 0;
    for (int a = 0; a < Dim; ++a) {
      index = index * S + static_cast<int>(std::lround((d[a] - d0_[a]) * inv_dx));
    }
    return index;
  }
  // The unit mode r at the stencil's node j, prod_a unit(a, r_a, j_a) (the
  // reference evaluation, one product per mode and node).
  Real unit_mode(int r, int j) const {
    assert(!kept_only_);
    Real s = 1;
    for (int a = Dim - 1; a >= 0; --a, r /= S, j /= S) s *= unit(a, r % S, j % S);
    return s;
  }

  // The weighted transforms, on one SIMD Row per node or mode (core/pack.hpp):
  //   to_nodes: out[i] = sum_r c[r] prod_a wunit(a, r_a, i_a) = w_ip sum_r c_r s_r(i)/|s_r|,
  //             the field with unit-mode coefficients c at the nodes, times w_ip;
  //   to_modes: out[r] = sum_i prod_a wunit(a, r_a, i_a) v[i] = sum_i w_ip s_r(i) v_i / |s_r|,
  //             the projection onto the unit modes.
  // Sum-factorised: Dim passes of S x S, each y[j] = sum_k W_a[j_a][k] x[j with j_a -> k]
  // with W_a = wunit(a, ., .) or its transpose. The index arithmetic is constant once unrolled.
  template <class Node>
  MPMTB_INLINE void to_nodes(const Node* c, Node* out) const {
    transform<true>(c, out);
  }
  template <class Node>
  MPMTB_INLINE void to_modes(const Node* v, Node* out) const {
    transform<false>(v, out);
  }

  // Mode r = (r_0, ..., r_{Dim-1}) as a flat index: 0 is the constant, linear(a)
  // the mode e_1 along axis a; the rest are the higher modes.
  static constexpr int linear(int a) {
    return ipow(S, Dim - 1 - a);
  }
  static constexpr bool higher(int r) {
    if (r == 0) return false;
    for (int a = 0; a < Dim; ++a)
      if (r == linear(a)) return false;
    return true;
  }

 private:
  template <bool Transpose, class Node>
  MPMTB_INLINE void transform(const Node* in, Node* out) const {
    Node buffer[2][count];
    [&]<int... A>(std::integer_sequence<int, A...>) MPMTB_INLINE_LAMBDA {
      (apply_axis<Transpose, A>(A == 0 ? in : buffer[(A + 1) % 2],
                                A == Dim - 1 ? out : buffer[A % 2]),
       ...);
    }
    (std::make_integer_sequence<int, Dim>{});
  }
  template <bool Transpose, int A, class Node>
  MPMTB_INLINE void apply_axis(const Node* __restrict x, Node* __restrict y) const {
    constexpr int stride = ipow(S, Dim - 1 - A), outer = ipow(S, A);
    if constexpr (kPaired<Node>) {
      apply_axis_paired<Transpose, A>(x, y);
    } else {
      for (int o = 0; o < outer; ++o)
        for (int n = 0; n < S; ++n)
          for (int i = 0; i < stride; ++i) one_output<Transpose, A>(x, y, o, n, i);
    }
  }
  // y[first + n stride] = sum_k W(n, k) x[first + k stride], first = o S stride + i.
  template <bool Transpose, int A, class Node>
  MPMTB_INLINE void one_output(const Node* __restrict x, Node* __restrict y, int o, int n,
                               int i) const {
    constexpr int stride = ipow(S, Dim - 1 - A);
    const int first = o * S * stride + i;
    Node acc = coefficient<Transpose, A>(n, 0) * x[first];
    for (int k = 1; k < S; ++k)
      acc.add_scaled(coefficient<Transpose, A>(n, k), x[first + k * stride]);
    y[first + n * stride] = acc;
  }

  // Two outputs per register where two nodes' rows fill one (AVX-512 with 3D
  // double rows, AVX with 2D ones): half the multiply-adds. Along the last axis
  // (stride 1) the pair is outputs n and n + 1 of one line, the same inputs with
  // two coefficients; along the others it is nodes i and i + 1, side by side in
  // memory, with one coefficient. Every lane takes the same operations in the same
  // order as one_output, so the results are the same bits.
  // (Odd supports keep one output per register: with a node left over in every
  // line, the quadratic B-spline's pairs measured 2 % slower.)
  template <class Node>
  static constexpr bool kPaired = S % 2 == 0 && Node::K == 1 && 2 * sizeof(Node) <= kSimdBytes;

  template <bool Transpose, int A, class Node>
  MPMTB_INLINE void apply_axis_paired(const Node* __restrict x, Node* __restrict y) const {
    constexpr int stride = ipow(S, Dim - 1 - A), outer = ipow(S, A);
    constexpr int L = Node::lanes;
    using Pair = typename PackOf<2 * sizeof(Node)>::type;
    const auto load = [](const Node* at) MPMTB_INLINE_LAMBDA {
      Pair p;
      std::memcpy(&p, at, sizeof p);
      return p;
    };
    const auto twice = [](const Node& r) MPMTB_INLINE_LAMBDA {  // (r, r)
      return [&]<int... l>(std::integer_sequence<int, l...>) MPMTB_INLINE_LAMBDA {
        return __builtin_shufflevector(r.v[0], r.v[0], (l % L)...);
      }
      (std::make_integer_sequence<int, 2 * L>{});
    };
    const auto halves = [](Real lo, Real hi) MPMTB_INLINE_LAMBDA {  // (lo..., hi...)
      return [&]<int... l>(std::integer_sequence<int, l...>) MPMTB_INLINE_LAMBDA {
        return Pair{(l < L ? lo : hi)...};
      }
      (std::make_integer_sequence<int, 2 * L>{});
    };
    for (int o = 0; o < outer; ++o) {
      if constexpr (stride == 1) {
        const Node* line = x + o * S;
        for (int n = 0; n + 1 < S; n += 2) {
          const auto w = [&](int k) MPMTB_INLINE_LAMBDA {
            return halves(coefficient<Transpose, A>(n, k), coefficient<Transpose, A>(n + 1, k));
          };
          Pair acc = w(0) * twice(line[0]);
          for (int k = 1; k < S; ++k) acc = fused(w(k), twice(line[k]), acc);
          std::memcpy(y + o * S + n, &acc, sizeof acc);
        }
        if constexpr (S % 2 == 1) one_output<Transpose, A>(x, y, o, S - 1, 0);
      } else {
        for (int n = 0; n < S; ++n) {
          for (int i = 0; i + 1 < stride; i += 2) {
            const int first = o * S * stride + i;
            Pair acc = coefficient<Transpose, A>(n, 0) * load(x + first);
            for (int k = 1; k < S; ++k)
              acc = fused(coefficient<Transpose, A>(n, k) - Pair{}, load(x + first + k * stride),
                          acc);
            std::memcpy(y + first + n * stride, &acc, sizeof acc);
          }
          if constexpr (stride % 2 == 1) one_output<Transpose, A>(x, y, o, n, stride - 1);
        }
      }
    }
  }
  template <bool Transpose, int A>
  MPMTB_INLINE Real coefficient(int n, int k) const {
    return Transpose ? wunit_[k][n][A] : wunit_[n][k][A];
  }
};

}  // namespace mpmtb
