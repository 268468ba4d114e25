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

#include <immintrin.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>
#include <limits>
#include <string_view>
#include <type_traits>
#include <utility>

#include "core/deformation.hpp"
#include "core/parameters.hpp"
#include "core/particles.hpp"
#include "core/policy_hooks.hpp"
#include "core/stencil.hpp"
#include "core/tensor_transfer.hpp"
#include "transfers/affine.hpp"
#include "transfers/poly_modes.hpp"

namespace mpmtb {

template <int Dim, class Kernel>
class PolypicPolicy {
  using V = Vec<Dim>;
  using M = Mat<Dim>;
  static constexpr int S = Kernel::support;
  using Modes = PolyModes<Dim, S>;
  static constexpr int kModes = Modes::count;
  // Mode coefficients and nodal momenta in P2G as the rows of the folded sums,
  // (m, p) padded, with the momentum in the p slots (ScatterForm::nodal); nodal
  // velocities and mode coefficients in G2P as the packed velocity rows (v, 0).
  static constexpr int kScatterWidth = kNodalWidth<Dim>;
  static constexpr int kGatherWidth = VelocityRows<Dim, false>::N;
  using ScatterRow = Row<kScatterWidth>;
  using GatherRow = Row<kGatherWidth>;
  static constexpr int kP = ScatterForm<Dim>::p;

 public:
  // The higher-mode coefficients per particle: Dim values per mode.
  static constexpr int transfer_state_size = (kModes - 1 - Dim) * Dim;

  PolypicPolicy(Parameters&, Real dx) : dx_(dx) {}

  struct Source {
    Real m;
    M tauV;
    Modes modes;
    ScatterRow c[kModes];      // m_p times the unit modes' coefficients, in the p slots
    ScatterRow nodes[kModes];  // w_ip m_p v_p(x_i): ScatterForm::nodal
  };
  // Kept per particle from P2G to the G2P of the same step (core/policy_hooks.hpp):
  // the modes G2P reads, and the position they were built at. In 2D: cubic
  // 1.19-1.25x, quadratic 1.23-1.27x. In 3D the record (S^2 Dim values) cost
  // about what the one build it spared did (block at 1 thread: cubic 0.94-1.01x,
  // quadratic 0.99-1.02x), so it is kept only with the pass below.
  static constexpr bool kKeepsModes = Dim <= 2 || S >= 4;
  // With 4 nodes per axis (cubic B-spline, cpGIMP) a pass before P2G builds the
  // modes of two particles at once (keep_modes) and P2G restores them too: 2D
  // cubic 1.07-1.33x, cpGIMP 1.17-1.26x (5 rounds at 1 thread); 3D cubic, with
  // P2G fetching the records ahead (core/solver_impl.hpp), 1.19x at 1 thread and
  // 1.15x at 2 (5 rounds). With 3 the build of two was cheaper than the pass's
  // stencils and records (2D quadratic 0.82-0.93x); the build of four in one
  // register (2D, Modes::kGroup) pays for every kernel: against pairs, 2D cubic
  // 1.09-1.16x and cpGIMP 1.24x, and against no pass, quadratic 1.14x and uGIMP
  // 1.30x (5 rounds at 1 thread).
  static constexpr bool kKeepPass = kKeepsModes && (S >= 4 || Modes::kGroup == 4);
  struct KeptModes {
    typename Modes::Kept modes;
    V x;
  };
  using Kept = std::conditional_t<kKeepsModes, KeptModes, NothingKept>;

  // Rebuilds the modes at the particle's current stencil (the orthogonality that
  // conservation needs is under these weights) and evaluates its field at the
  // nodes; with `kept`, records the modes for G2P (begin_gather).
  MPMTB_INLINE Source prepare(const Particles<Dim>& P, int p, const M& tauV,
                              const Stencil<Dim, Kernel>& st, Kept* kept = nullptr) const {
    Source s;
    s.m = P.m[p];
    s.tauV = tauV;
    // Restored where the solver's pass before P2G (keep_modes) recorded them;
    // without that pass a record is the last step's, and is written anew.
    if (!modes_at(s.modes, st, P.x[p], kKeepPass ? kept : nullptr)) {
      if constexpr (kKeepsModes) {
        if (kept) s.modes.keep(kept->modes), kept->x = P.x[p];
      }
    }
    const auto row = [&](const auto& value) MPMTB_INLINE_LAMBDA {
      RowBuilder<kScatterWidth> r;
      r.template segment<Dim>(kP) = s.m * value;
      return r.row();
    };
    const Real* stored = P.transfer_state_of(p);
#pragma GCC unroll 64
    for (int r = 0; r < kModes; ++r) {
      if (Modes::higher(r)) {
        s.c[r] = scaled_row(stored, s.m);
        stored += Dim;
      }
    }
    s.c[0] = row(P.v[p]);
    // Linear modes in cell units: e_1 = (x_i - x_p)_a / dx, so c = C_p e_a dx,
    // times |e_1| for the unit mode. The higher modes are stored for theirs.
    for (int a = 0; a < Dim; ++a)
      s.c[Modes::linear(a)] = row(P.C[p].col(a) * (dx_ * s.modes.root_norm(a)));
    s.modes.to_nodes(s.c, s.nodes);
    return s;
  }
  // m v_0 .. m v_{Dim-1} in the p slots of a row, 0 in the others. In 3D with
  // AVX-512 and three nodes per axis a masked load and a lane rotation (the same
  // products) instead of a segment's three scalar products and inserts for each
  // of the 23 higher modes: 3D block, quadratic, 1 thread, 1.029x (10 rounds).
  // With four nodes (60 higher modes) it measured 0.94x-0.97x: not taken there.
  MPMTB_INLINE static ScatterRow scaled_row(const Real* v, Real m) {
#if defined(__AVX512VL__)
    if constexpr (Dim == 3 && S == 3 && kP == 1 && ScatterRow::K == 1 && ScatterRow::lanes == 4) {
      using Pack = typename ScatterRow::Pack;
      Pack x;  // (v_0, v_1, v_2, 0): the lane past the record is not read
      if constexpr (std::is_same_v<Real, double>) {
        x = reinterpret_cast<Pack>(_mm256_maskz_loadu_pd(0x7, v));
      } else {
        x = reinterpret_cast<Pack>(_mm_maskz_loadu_ps(0x7, v));
      }
      ScatterRow r;
      r.v[0] = __builtin_shufflevector(x, x, 3, 0, 1, 2) * m;
      return r;
    }
#endif
    RowBuilder<kScatterWidth> r;
    r.template segment<Dim>(kP) = m * Eigen::Map<const V>(v);
    return r.row();
  }

  // A mode's Dim coefficients from its row of to_modes (a GatherRow) into the
  // particle's record. In 3D with AVX-512 and three or four nodes per axis (the
  // hat, unmeasured, keeps the copy) one masked store from the row as a
  // register, as P2G's scaled_row loads them: 3D block at 1 thread, quadratic
  // 1.032x and 1.037x (10 rounds each), cubic 1.021x and 1.019x (8 each),
  // cpGIMP 1.00x (6).
  MPMTB_INLINE static void store_row_coefficients(const Real* row, Real* stored) {
#if defined(__AVX512VL__)
    if constexpr (Dim == 3 && S >= 3 && GatherRow::K == 1 && GatherRow::lanes == 4) {
      typename GatherRow::Pack x;
      std::memcpy(&x, row, sizeof x);
      if constexpr (std::is_same_v<Real, double>) {
        _mm256_mask_storeu_pd(stored, 0x7, reinterpret_cast<__m256d>(x));
      } else {
        _mm_mask_storeu_ps(stored, 0x7, reinterpret_cast<__m128>(x));
      }
      return;
    }
#endif
    std::memcpy(stored, row, Dim * sizeof(Real));
  }

  // The reference: the polynomial evaluated at the node, mode by mode.
  void scatter(const Source& s, Real w, const V& grad, const V& d, Real& m_i, V& p_i,
               V& f_i) const {
    const int j = s.modes.node_index(d);
    V mv = V::Zero();
    for (int r = 0; r < kModes; ++r) {
      const Real sr = s.modes.unit_mode(r, j);
      for (int a = 0; a < Dim; ++a) mv[a] += sr * lane(s.c[r], kP + a);
    }
    m_i += w * s.m;
    p_i += w * mv;
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
    form.nodal = rows_data(s.nodes);
  }

  struct Gather {
    Modes modes;
    V v = V::Zero();
    M grad_v = M::Zero();
    bool from_rows = false;    // the fast path filled v_rows
    GatherRow v_rows[kModes];  // v_i at each stencil node (the fast path's, as Reals: v_data)
    V wv[kModes];              // w_ip v_i at each stencil node (the reference's)
    Real* v_data() { return rows_data(v_rows); }
  };
  Gather begin_gather(const Stencil<Dim, Kernel>& st) const {
    Gather g;
    g.modes.build(st, dx_);
    return g;
  }
  // The records of kKeptTogether particles at once (PolyModes::keep_group), for
  // the pass over the particles before P2G (core/policy_hooks.hpp): the build
  // is a long chain of dependent operations, and they share one.
  static constexpr int kKeptTogether = Modes::kGroup;
  void keep_modes(const Stencil<Dim, Kernel>* const (&st)[kKeptTogether],
                  const V* const (&x)[kKeptTogether], Kept* const (&kept)[kKeptTogether]) const
      requires(kKeepPass) {
    typename Modes::Kept* modes[kKeptTogether];
    for (int g = 0; g < kKeptTogether; ++g) modes[g] = &kept[g]->modes;
    Modes::template keep_group<kKeptTogether, Kernel>(st, dx_, modes);
    for (int g = 0; g < kKeptTogether; ++g) kept[g]->x = *x[g];
  }
  // The same from P2G's record where it was made at this position (the same
  // stencil, so the same modes, bit for bit): the build, a long chain of
  // dependent operations, was a quarter of a 2D cubic step.
  Gather begin_gather(const Stencil<Dim, Kernel>& st, const V& x, const Kept* kept) const {
    Gather g;
    modes_at(g.modes, st, x, kept);
    return g;
  }
  // The modes at the stencil st of a particle at x: restored from `kept` where it
  // was recorded at x (the caller passes only a record of this step), else built.
  // True where restored.
  MPMTB_INLINE bool modes_at(Modes& modes, const Stencil<Dim, Kernel>& st, const V& x,
                             const Kept* kept) const {
    if constexpr (kKeepsModes) {
      if (kept && kept->x == x) {
        modes.restore(kept->modes);
        return true;
      }
    }
    modes.build(st, dx_);
    return false;
  }
  static constexpr TensorTerms gather_terms{.gradient = true, .nodal = true};
  // The sums have filled g.v_rows (core/policy_hooks.hpp: tensor_gather).
  void gather_from(const GatherSums<Dim>& sums, Gather& g) const {
    g.v = sums.v;
    g.grad_v = sums.G;
    g.from_rows = true;
  }
  void gather(Gather& g, Real w, const V& grad, const V& d, const V& v_i, const V&) const {
    g.wv[g.modes.node_index(d)] = w * v_i;
    g.v += w * v_i;
    g.grad_v += v_i * grad.transpose();
  }
  void finish(Gather& g, Particles<Dim>& P, int p, Real dt) const {
    // sum_i w_ip s_r(i) v_i / |s_r| per mode: the coefficient of the unit mode
    // s_r / |s_r| (the projection, as the unit modes are orthonormal), 0 for a
    // dropped one; mode r's Dim values at coefficients + r * stride.
    const auto keep = [&]<int stride>(const Real* coefficients) MPMTB_INLINE_LAMBDA {
      Real* stored = P.transfer_state_of(p);
      // Unrolled whole, so that each mode's values are copied as one piece (as a
      // loop, with the test of higher() in it, it was half of finish's time).
#pragma GCC unroll 64
      for (int r = 0; r < kModes; ++r) {
        if (Modes::higher(r)) {
          // Stored as the coefficient of the unit mode: a particle's stencil energy
          // sum_r |c_r|^2 then survives the rebuild of its modes at the moved
          // position in P2G. Storing the coefficient of s_r itself let a nearly
          // degenerate mode (tiny |s_r|, large coefficient) gain norm one step
          // later and inject energy (the disks gained 2.1x).
          if constexpr (stride == kGatherWidth) {
            store_row_coefficients(coefficients + r * stride, stored);
          } else {
            std::memcpy(stored, coefficients + r * stride, Dim * sizeof(Real));
          }
          stored += Dim;
        }
      }
      for (int a = 0; a < Dim; ++a) {
        const Real root = g.modes.root_norm(a);
        const Eigen::Map<const V> c(coefficients + Modes::linear(a) * stride);
        P.C[p].col(a) = root > 0 ? V(c / (root * dx_)) : V::Zero();
      }
    };
    if (g.from_rows) {
      GatherRow modes[kModes];
      g.modes.to_modes(g.v_rows, modes);
      keep.template operator()<kGatherWidth>(rows_data(modes));
    } else {  // the reference: mode by mode over the nodes
      V c[kModes];
      for (int r = 0; r < kModes; ++r) {
        c[r].setZero();
        for (int j = 0; j < kModes; ++j) c[r] += g.modes.unit_mode(r, j) * g.wv[j];
      }
      static_assert(sizeof(V) == Dim * sizeof(Real));
      keep.template operator()<Dim>(c[0].data());
    }
    // The constant mode is sum_i w_ip v_i (sum_i w_ip = 1): PIC's velocity.
    P.v[p] = g.v;
    deformation_update<Dim>(P.F[p], g.grad_v, dt);
    P.x[p] += dt * g.v;
  }

 private:
  // Rows side by side are the Reals of the tensor transfer's rows (Row is its
  // registers, whole: no padding between rows); written and read with memcpy.
  template <int N>
  static Real* rows_data(Row<N>* rows) {
    static_assert(sizeof(Row<N>) == N * sizeof(Real));
    return reinterpret_cast<Real*>(rows);
  }
  template <int N>
  static const Real* rows_data(const Row<N>* rows) {
    return rows_data(const_cast<Row<N>*>(rows));
  }
  template <int N>
  static Real lane(const Row<N>& r, int i) {
    return r.v[i / Row<N>::lanes][i % Row<N>::lanes];
  }
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
  static constexpr bool supports = !kernel_full_inertia<Kernel>;
  static constexpr std::string_view unsupported_reason = kFullInertiaRefusal;
  template <int Dim, class Kernel>
  using Policy = PolypicPolicy<Dim, Kernel>;
};

}  // namespace mpmtb
