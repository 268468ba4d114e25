// APIC: Jiang, Schroeder, Selle, Teran & Stomakhin 2015, "The Affine Particle-
// In-Cell Method", ACM TOG 34(4); for solids Jiang et al. 2016 (SIGGRAPH course,
// sec. 10.2).
//   P2G momentum  m_p (v_p + C_p (x_i - x_p)) w_ip          (eq. 14, C_p = B_p D_p^-1)
//   force         f_i += -V0_p tau_p grad w_ip               (as PIC)
//   G2P           v_p = sum w v_i,  B_p = sum w v_i (x_i - x_p)^T  (eq. 10)
//   F update      F_p <- (I + dt sum v_i grad w^T) F_p       (as PIC)
// Angular momentum, including the affine part m_p (C_p D_p)^T : eps, is
// conserved by both transfers (sec. 5.3).
#pragma once

#include <string_view>

#include "core/deformation.hpp"
#include "core/parameters.hpp"
#include "core/particles.hpp"
#include "core/tensor_transfer.hpp"
#include "transfers/affine.hpp"

namespace mpmtb {

template <int Dim, class Kernel>
class ApicPolicy {
 protected:
  using V = Vec<Dim>;
  using M = Mat<Dim>;

 public:
  ApicPolicy(Parameters&, Real dx) : moments_(dx) {}

  // C_p and tau_p V_p are read in place: copies on the stack, read back by
  // columns, stalled P2G's set-up on store forwarding (perf).
  struct Source {
    Real m;
    V mv;
    const M& C;
    const M& tauV;
    V D_inv = V::Zero();  // D_p^-1, for kernels whose D_p differs per particle (uGIMP)
  };
  Source prepare(const Particles<Dim>& P, int p, const M& tauV) const {
    return {P.m[p], P.m[p] * P.v[p], P.C[p], tauV};
  }
  // The base solver calls this form when it exists: it adds the particle's D_p^-1.
  Source prepare(const Particles<Dim>& P, int p, const M& tauV,
                 const Stencil<Dim, Kernel>& st) const {
    Source s = prepare(P, p, tauV);
    if constexpr (AffineMoments<Dim, Kernel>::per_particle) s.D_inv = moments_.particle_D_inv(st);
    return s;
  }
  void scatter(const Source& s, Real w, const V& grad, const V& d, Real& m_i, V& p_i,
               V& f_i) const {
    scatter_momentum(s, w, d, m_i, p_i);
    f_i -= s.tauV * grad;
  }

  // The base solver's fast path (core/tensor_transfer.hpp): the same math as
  // scatter() and gather(), as sums over the stencil.
  using TensorPath = ApicPolicy;
  static constexpr TensorTerms scatter_terms{.moment = true, .gradient = true};
  void scatter_form(const Source& s, ScatterForm<Dim>& form) const {
    momentum_form(s, form);
    for (int a = 0; a < Dim; ++a) form.beta[a].template segment<Dim>(F_::f) = -s.tauV.col(a);
  }
  // The same columns in whole registers, for folded sums (FoldedForm).
  using FoldedPath = ApicPolicy;
  void folded_form(const Source& s, FoldedForm<Dim>& form) const requires(Dim >= 2) {
    folded_momentum_form(s, form);
    [&]<int... a>(std::integer_sequence<int, a...>) MPMTB_INLINE_LAMBDA {
      ((form.beta_f[a] = -column_lanes<a>(s.tauV)), ...);
    }
    (std::make_integer_sequence<int, Dim>{});
  }

  struct Gather {
    V v = V::Zero();
    M C = M::Zero();
    M grad_v = M::Zero();
    V D_inv = V::Zero();  // D_p^-1 for per-particle D_p (set by begin_gather)
  };
  static constexpr TensorTerms gather_terms{
      .moment = Kernel::constant_inertia || AffineMoments<Dim, Kernel>::per_particle,
      .gradient = true};
  Gather gather_from(const GatherSums<Dim>& sums) const {
    return {sums.v, moments_.from_sums(sums.B, sums.G, sums.D_inv), sums.G};
  }
  // The per-node path starts from this (the base solver calls it when it exists).
  Gather begin_gather(const Stencil<Dim, Kernel>& st) const {
    Gather g;
    if constexpr (AffineMoments<Dim, Kernel>::per_particle) g.D_inv = moments_.particle_D_inv(st);
    return g;
  }
  void gather(Gather& g, Real w, const V& grad, const V& d, const V& v_i, const V&) const {
    g.v += w * v_i;
    g.C += v_i * moments_.weight_moment(w, grad, d, g.D_inv).transpose();
    g.grad_v += v_i * grad.transpose();
  }
  void finish(const Gather& g, Particles<Dim>& P, int p, Real dt) const {
    P.v[p] = g.v;
    P.C[p] = g.C;
    deformation_update<Dim>(P.F[p], g.grad_v, dt);
    P.x[p] += dt * g.v;
  }
  // The fast path's finish from the stencil sums in registers (core/
  // policy_hooks.hpp): gather_from and finish in one, the same operations.
  using FinishRows = ApicPolicy;
  template <class Rows>
  MPMTB_INLINE void finish_rows(const Rows& r, const Stencil<Dim, Kernel>& st, Particles<Dim>& P,
                                int p, Real dt) const {
    finish_affine_rows<false>(r, st, P, p, dt);
  }

 protected:
  using F_ = ScatterForm<Dim>;
  // finish_rows of APIC and MLS-MPM: v, C (from_sums, by columns) and x, and F
  // updated from C (kFfromC, MLS-MPM) or from grad v.
  template <bool kFfromC, class Rows>
  MPMTB_INLINE void finish_affine_rows(const Rows& r, const Stencil<Dim, Kernel>& st,
                                       Particles<Dim>& P, int p, Real dt) const {
    const AxisPack v = axis_lanes<Dim>(r.W);
    AxisPack C[Dim], G[Dim]{};  // the columns of C_p and of grad v
    [[maybe_unused]] const V D_inv = moments_.particle_D_inv(st);
    for (int a = 0; a < Dim; ++a) {
      if constexpr (Rows::terms.gradient) G[a] = axis_lanes<Dim>(r.Gr[a]);
      if constexpr (Kernel::constant_inertia) {
        C[a] = axis_lanes<Dim>(r.Dm[a]) * moments_.D_inv();
      } else if constexpr (AffineMoments<Dim, Kernel>::per_particle) {
        C[a] = axis_lanes<Dim>(r.Dm[a]) * D_inv[a];
      } else {
        C[a] = G[a];
      }
    }
    for (int b = 0; b < Dim; ++b) P.v[p][b] = v[b];
    store_columns<Dim>(P.C[p], C);
    if constexpr (kFfromC) {
      deformation_update<Dim>(P.F[p], C, dt);
    } else {
      deformation_update<Dim>(P.F[p], G, dt);
    }
    for (int b = 0; b < Dim; ++b) P.x[p][b] += dt * v[b];
  }
  // The same momentum as a linear form: alpha = (m_p, m_p v_p), gamma_a = m_p C_p e_a.
  void momentum_form(const Source& s, ScatterForm<Dim>& form) const {
    form.alpha[F_::m] = s.m;
    form.alpha.template segment<Dim>(F_::p) = s.mv;
    for (int a = 0; a < Dim; ++a) form.gamma[a].template segment<Dim>(F_::p) = s.m * s.C.col(a);
  }
  void folded_momentum_form(const Source& s, FoldedForm<Dim>& form) const {
    form.set_mass_momentum(s.m, s.mv);
    [&]<int... a>(std::integer_sequence<int, a...>) MPMTB_INLINE_LAMBDA {
      ((form.gamma_mp[a] = s.m * column_lanes<a>(s.C)), ...);
    }
    (std::make_integer_sequence<int, Dim>{});
  }
  // m_i += w m_p, p_i += w m_p (v_p + C_p (x_i - x_p)): shared with MLS-MPM.
  void scatter_momentum(const Source& s, Real w, const V& d, Real& m_i, V& p_i) const {
    m_i += w * s.m;
    const M mC = s.m * s.C;
    p_i += w * s.mv + mC * (w * d);
  }
  AffineMoments<Dim, Kernel> moments_;
};

struct ApicTransfer {
  static constexpr std::string_view name = "apic";
  static constexpr std::string_view description =
      "APIC: affine momentum C_p, kernel-gradient force and F (Jiang et al. 2015); "
      "linear: C_p = sum v_i grad w^T; gimp: the particle's own D_p";
  // The paper behind it, BibTeX for `mpmtb list --bibtex`.
  static constexpr std::string_view bibtex = R"bib(@article{jiang2015,
  author = {Jiang, Chenfanfu and Schroeder, Craig and Selle, Andrew and Teran, Joseph and Stomakhin, Alexey},
  title = {The affine particle-in-cell method},
  journal = {ACM Transactions on Graphics},
  volume = {34},
  number = {4},
  articleno = {51},
  year = {2015},
  doi = {10.1145/2766996}
})bib";
  static constexpr bool affine_momentum = true;
  // Whether the paper claims angular momentum conservation, affine part included, in both
  // transfers (if so, the conformance tests hold it to round-off).
  static constexpr bool conserves_angular_momentum = true;
  static constexpr bool needs_old_velocity = false;
  template <class Kernel>
  static constexpr bool supports = !kernel_full_inertia<Kernel>;
  static constexpr std::string_view unsupported_reason = kFullInertiaRefusal;
  template <int Dim, class Kernel>
  using Policy = ApicPolicy<Dim, Kernel>;
};

}  // namespace mpmtb
