// PolyPIC: Fu, Guo, Gast, Jiang & Teran 2017, "A Polynomial Particle-In-Cell
// Method", ACM TOG 36(6) 222.
// Each particle carries a polynomial velocity field over its stencil,
//   v_p(x_i) = sum_r c_p^r s_r(x_i - x_p),
// in modes s_r that are orthogonal on the stencil's nodes under the weights w_ip
// (sec. 4-5). The modes are tensor products of 1D polynomials e_0 = 1, e_1, ...,
// e_{S-1} (S = Kernel::support), built per particle and axis by Gram-Schmidt
// under the 1D weights, so all S^Dim modes of the stencil are kept.
//   P2G momentum  m_p w_ip sum_r c_r s_r(i)
//   force, F      as APIC (kernel gradient)
//   G2P           c_r = sum_i w_ip s_r(i) v_i / sum_i w_ip s_r(i)^2   (a weighted projection)
// The constant mode is v_p (= PIC's), the linear modes are APIC's C_p = B_p D_p^-1;
// they stay in P.v and P.C, the higher modes go to Particles::transfer_state
// (normalized: see finish()). With the modes orthonormal at each position, G2P
// (Bessel's inequality) and P2G (Jensen's) cannot create kinetic energy.
// Every higher mode is orthogonal to 1 and to x_i - x_p, so it carries no linear
// or angular momentum: both are conserved as in APIC (the conformance tests hold
// it to round-off).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string_view>
#include <utility>

#include "core/parameters.hpp"
#include "core/particles.hpp"
#include "core/stencil.hpp"
#include "core/tensor_transfer.hpp"

namespace mpmtb {

// The 1D polynomials e_n of one particle along each axis, orthogonal under the
// kernel weights: sum_k w_a(k) e_n(u_k) e_m(u_k) = 0 for n != m, with
// u_k = (x_i - x_p)_a / dx the node offsets in cell units. The tensor products
// s_r(i) = prod_a e_{r_a}(u_{i_a}) are then orthogonal under w_ip = prod_a w_a,
// and their norms factor: sum_i w_ip s_r(i)^2 = prod_a norm[a][r_a].
template <int Dim, int S>
struct PolyModes {
  static constexpr int count = ipow(S, Dim);  // modes = stencil nodes
  // Dim Reals padded to a whole SIMD row (core/pack.hpp): one lane per axis in
  // build(), one row per node in the transform.
  static constexpr int kPad = [] {
    constexpr int lanes = 16 / int(sizeof(Real));  // the narrowest Row
    return (Dim + lanes - 1) / lanes * lanes;
  }();
  using Node = Row<kPad>;

  Real e[Dim][S][S];     // e[a][n][k]: e_n at node k of axis a
  Real norm[Dim][S];     // sum_k w_a(k) e_n(u_k)^2; 0 for a dropped mode
  Real unit[Dim][S][S];  // e_n / sqrt(norm) for n >= 1 (0 if dropped), e_0 = 1 (norm 1)
  Real root_norm[Dim];   // sqrt(norm[a][1]): e_1 = root_norm unit_1
  Real d0[Dim];          // offset of node 0 per axis
  Real inv_dx;

  // Gram-Schmidt of the monomials 1, u, u^2, ... under the weights, twice over
  // ("twice is enough"): orthogonal to round-off relative to each e_n's own size,
  // so the higher modes add no momentum beyond round-off. (Stieltjes' three-term
  // recurrence, cheaper, left the cubic B-spline's e_3 visibly non-orthogonal to
  // 1 where an end weight is tiny: a rigid translation then made strain.) A mode
  // whose norm falls below a relative tolerance of its monomial's is degenerate
  // (fewer weighted nodes than modes, e.g. the linear hat at a node, or the
  // quadratic B-spline half-way between nodes): it and every higher one are dropped.
  // The axes are independent: each runs in one SIMD lane (padding lanes have
  // zero weights, so their modes are dropped and never read).
  template <class Kernel>
  void build(const Stencil<Dim, Kernel>& st, Real dx) {
    static_assert(Kernel::support == S);
    using Lanes = typename PackOf<kPad * sizeof(Real)>::type;
    inv_dx = 1 / dx;
    const Lanes tol = 1000 * std::numeric_limits<Real>::epsilon() - Lanes{}, zero{};
    Lanes u[S], w[S], power[S], q[S][S], norm_n[S], inv_norm[S];
    for (int k = 0; k < S; ++k) {
      // Set whole, from arrays: lane by lane into a zero pack, GCC reports the
      // lanes not yet set as maybe uninitialized once the gather is inlined.
      Real u_k[kPad] = {}, w_k[kPad] = {};
      for (int a = 0; a < Dim; ++a) u_k[a] = st.d(a, k) * inv_dx, w_k[a] = st.w(a, k);
      std::memcpy(&u[k], u_k, sizeof(Lanes));
      std::memcpy(&w[k], w_k, sizeof(Lanes));
      power[k] = 1 - Lanes{};
    }
    auto dropped = zero < zero;  // all lanes false
    for (int n = 0; n < S; ++n) {
      for (int k = 0; k < S; ++k) q[n][k] = power[k];
      for (int pass = 0; pass < 2; ++pass) {
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
      norm_n[n] = dropped ? zero : nn;
      inv_norm[n] = dropped ? zero : 1 / nn;
    }
    for (int a = 0; a < Dim; ++a) {
      for (int n = 0; n < S; ++n) {
        norm[a][n] = norm_n[n][a];
        // The partition of unity makes e_0 = 1 a unit mode (sum_k w_a(k) = 1).
        const Real inv_root = n == 0 ? Real(1) : std::sqrt(inv_norm[n][a]);
        for (int k = 0; k < S; ++k) e[a][n][k] = q[n][k][a], unit[a][n][k] = q[n][k][a] * inv_root;
        if (n == 1) root_norm[a] = norm_n[1][a] * inv_root;  // sqrt(norm), 0 if dropped
      }
      d0[a] = st.d(a, 0);
    }
  }

  // The stencil index (last axis fastest, as Stencil::for_each_node) of the node
  // at offset d = x_i - x_p.
  int node_index(const Vec<Dim>& d) const {
    int index = 0;
    for (int a = 0; a < Dim; ++a) {
      index = index * S + static_cast<int>(std::lround((d[a] - d0[a]) * inv_dx));
    }
    return index;
  }

  // The transform in the orthonormal modes s_r / |s_r| (= prod_a unit[a][r_a]),
  // on one SIMD row per node (Dim Reals, padded: core/pack.hpp), sum-factorised:
  // Dim passes of S x S, each out[j] = sum_k U_a[j_a][k] in[j with j_a -> k]
  // (nodal values -> mode sums) or with U_a^T (mode coefficients -> nodal
  // values), U_a = unit[a]. The index arithmetic is constant once unrolled.
  template <bool Transpose, int A>
  MPMTB_INLINE void apply_axis(const Node* __restrict in, Node* __restrict out) const {
    constexpr int stride = ipow(S, Dim - 1 - A), outer = ipow(S, A);
    for (int o = 0; o < outer; ++o) {
      const Node* x = in + o * S * stride;
      Node* y = out + o * S * stride;
      for (int n = 0; n < S; ++n) {
        for (int i = 0; i < stride; ++i) {
          Node acc = coefficient<Transpose, A>(n, 0) * x[i];
          for (int k = 1; k < S; ++k)
            acc.add_scaled(coefficient<Transpose, A>(n, k), x[k * stride + i]);
          y[n * stride + i] = acc;
        }
      }
    }
  }
  template <bool Transpose, int A>
  MPMTB_INLINE Real coefficient(int n, int k) const {
    return Transpose ? unit[A][k][n] : unit[A][n][k];
  }
  // From in to out (count values each).
  template <bool Transpose>
  void transform(const Vec<Dim>* in, Vec<Dim>* out) const {
    Node buffer[2][count];
    for (int j = 0; j < count; ++j) {
      Real padded[kPad] = {};
      for (int a = 0; a < Dim; ++a) padded[a] = in[j][a];
      buffer[0][j] = Node::gather(padded);
    }
    [&]<int... A>(std::integer_sequence<int, A...>) {
      (apply_axis<Transpose, A>(buffer[A % 2], buffer[(A + 1) % 2]), ...);
    }
    (std::make_integer_sequence<int, Dim>{});
    for (int j = 0; j < count; ++j) {
      Real padded[kPad];
      buffer[Dim % 2][j].store(padded);
      for (int a = 0; a < Dim; ++a) out[j][a] = padded[a];
    }
  }

  // Mode r = (r_0, ..., r_{Dim-1}) as a flat index: 0 is the constant, linear(a)
  // the mode e_1 along axis a; the rest are the higher modes.
  static constexpr int linear(int a) { return ipow(S, Dim - 1 - a); }
  static constexpr bool higher(int r) {
    if (r == 0) return false;
    for (int a = 0; a < Dim; ++a)
      if (r == linear(a)) return false;
    return true;
  }
};

template <int Dim, class Kernel>
class PolypicPolicy {
  using V = Vec<Dim>;
  using M = Mat<Dim>;
  static constexpr int S = Kernel::support;
  using Modes = PolyModes<Dim, S>;
  static constexpr int kModes = Modes::count;

 public:
  // The higher-mode coefficients per particle: Dim values per mode.
  static constexpr int transfer_state_size = (kModes - 1 - Dim) * Dim;

  PolypicPolicy(Parameters&, Real dx) : dx_(dx) {}

  struct Source {
    Real m;
    M tauV;
    Modes modes;
    V mv[kModes];  // m_p v_p(x_i) at each stencil node
  };
  // Rebuilds the modes at the particle's current stencil (the orthogonality that
  // conservation needs is under these weights) and evaluates its field at the nodes.
  Source prepare(const Particles<Dim>& P, int p, const M& tauV,
                 const Stencil<Dim, Kernel>& st) const {
    Source s;
    s.m = P.m[p];
    s.tauV = tauV;
    s.modes.build(st, dx_);
    V c[kModes];  // the unit modes' coefficients
    const Real* stored = P.transfer_state_of(p);
    for (int r = 0; r < kModes; ++r) {
      if (Modes::higher(r)) {
        c[r] = Eigen::Map<const V>(stored);
        stored += Dim;
      }
    }
    c[0] = P.v[p];
    // Linear modes in cell units: e_1 = (x_i - x_p)_a / dx, so c = C_p e_a dx,
    // times |e_1| for the unit mode. The higher modes are stored for theirs.
    for (int a = 0; a < Dim; ++a)
      c[Modes::linear(a)] = P.C[p].col(a) * (dx_ * s.modes.root_norm[a]);
    s.modes.template transform<true>(c, s.mv);  // coefficients -> nodal velocities
    for (int j = 0; j < kModes; ++j) s.mv[j] *= s.m;
    return s;
  }
  void scatter(const Source& s, Real w, const V& grad, const V& d, Real& m_i, V& p_i,
               V& f_i) const {
    m_i += w * s.m;
    p_i += w * s.mv[s.modes.node_index(d)];
    f_i -= s.tauV * grad;
  }

  // The base solver's fast path (core/tensor_transfer.hpp): mass and force as
  // APIC's, the momentum as a field over the stencil's nodes (TensorTerms::nodal).
  using TensorPath = PolypicPolicy;
  static constexpr TensorTerms scatter_terms{.gradient = true, .nodal = true};
  void scatter_form(const Source& s, ScatterForm<Dim>& form) const {
    using F_ = ScatterForm<Dim>;
    form.alpha[F_::m] = s.m;
    for (int a = 0; a < Dim; ++a) form.beta[a].template segment<Dim>(F_::f) = -s.tauV.col(a);
    form.nodal = s.mv;
  }

  struct Gather {
    Modes modes;
    V v = V::Zero();
    M grad_v = M::Zero();
    V wv[kModes];  // w_ip v_i at each stencil node
  };
  Gather begin_gather(const Stencil<Dim, Kernel>& st) const {
    Gather g;
    g.modes.build(st, dx_);
    for (auto& x : g.wv) x.setZero();
    return g;
  }
  static constexpr TensorTerms gather_terms{.gradient = true, .nodal = true};
  // The sums have filled g.wv (core/policy_hooks.hpp: tensor_gather).
  void gather_from(const GatherSums<Dim>& sums, Gather& g) const {
    g.v = sums.v;
    g.grad_v = sums.G;
  }
  void gather(Gather& g, Real w, const V& grad, const V& d, const V& v_i, const V&) const {
    g.wv[g.modes.node_index(d)] = w * v_i;
    g.v += w * v_i;
    g.grad_v += v_i * grad.transpose();
  }
  void finish(Gather& g, Particles<Dim>& P, int p, Real dt) const {
    V c[kModes];
    // sum_i w_ip s_r(i) v_i / |s_r| per mode: the coefficient of the unit mode
    // s_r / |s_r| (the projection, as the unit modes are orthonormal), 0 for a
    // dropped one.
    g.modes.template transform<false>(g.wv, c);
    Real* stored = P.transfer_state_of(p);
    for (int r = 0; r < kModes; ++r) {
      if (Modes::higher(r)) {
        // Stored as the coefficient of the unit mode: a particle's stencil energy
        // sum_r |c_r|^2 then survives the rebuild of its modes at the moved
        // position in P2G. Storing the coefficient of s_r itself let a nearly
        // degenerate mode (tiny |s_r|, large coefficient) gain norm one step
        // later and inject energy (the disks gained 2.1x).
        Eigen::Map<V>{stored} = c[r];
        stored += Dim;
      }
    }
    // The constant mode is sum_i w_ip v_i (sum_i w_ip = 1): PIC's velocity.
    P.v[p] = g.v;
    for (int a = 0; a < Dim; ++a) {
      const Real root = g.modes.root_norm[a];
      P.C[p].col(a) = root > 0 ? V(c[Modes::linear(a)] / (root * dx_)) : V::Zero();
    }
    P.F[p] = (M::Identity() + dt * g.grad_v) * P.F[p];
    P.x[p] += dt * g.v;
  }

 private:
  Real dx_;
};

struct PolypicTransfer {
  static constexpr std::string_view name = "polypic";
  static constexpr std::string_view description =
      "PolyPIC: per-particle polynomial velocity in all S^Dim stencil modes, orthogonal "
      "under the weights (Fu et al. 2017); kernel-gradient force and F";
  // The paper behind it, BibTeX for `mpmtb list --bibtex`.
  static constexpr std::string_view bibtex = R"bib(@article{fu2017,
  author = {Fu, Chuyuan and Guo, Qi and Gast, Theodore and Jiang, Chenfanfu and Teran, Joseph},
  title = {A polynomial particle-in-cell method},
  journal = {ACM Transactions on Graphics},
  volume = {36},
  number = {6},
  articleno = {222},
  year = {2017},
  doi = {10.1145/3130800.3130878}
})bib";
  // P.C holds the linear modes (APIC's C_p), so the diagnostics count the affine
  // angular momentum; the higher modes carry none.
  static constexpr bool affine_momentum = true;
  static constexpr bool conserves_angular_momentum = true;
  static constexpr bool needs_old_velocity = false;
  template <class Kernel>
  static constexpr bool supports = true;
  static constexpr std::string_view unsupported_reason = "";
  template <int Dim, class Kernel>
  using Policy = PolypicPolicy<Dim, Kernel>;
};

}  // namespace mpmtb
