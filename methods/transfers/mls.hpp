// MLS-MPM: Hu, Fang, Ge, Qu, Zhu, Pradhana & Jiang 2018, "A Moving Least Squares
// Material Point Method with Displacement Discontinuity and Two-Way Rigid Body
// Coupling", ACM TOG 37(4).
//   P2G momentum  m_p (v_p + C_p (x_i - x_p)) w_ip                 (APIC part, eq. 13)
//   force         f_i += -V0_p tau_p D_p^-1 (x_i - x_p) w_ip       (eq. 16-18)
//   G2P           v_p = sum w v_i,  C_p = sum v_i q_ip^T (affine.hpp)
//   F update      F_p <- (I + dt C_p) F_p                           (eq. 17)
// The MLS force direction D_p^-1 (x_i - x_p) w_ip is q_ip, the same vector as
// in C_p: with the linear hat it becomes grad w_ip (affine.hpp).
#pragma once

#include <string_view>

#include "transfers/apic.hpp"

namespace mpmtb {

// MLS-MPM is APIC with the MLS force direction and F updated from C_p.
template <int Dim, class Kernel>
class MlsPolicy : public ApicPolicy<Dim, Kernel> {
  using Base = ApicPolicy<Dim, Kernel>;
  using typename Base::M;
  using typename Base::Source;
  using typename Base::V;

 public:
  using Base::Base;

  void scatter(const Source& s, Real w, const V& grad, const V& d, Real& m_i, V& p_i,
               V& f_i) const {
    this->scatter_momentum(s, w, d, m_i, p_i);
    f_i -= s.tauV * this->moments_.weight_moment(w, grad, d, s.D_inv);
  }

  // The base solver's fast path (core/tensor_transfer.hpp): the same math as
  // scatter() and gather(), as sums over the stencil.
  using TensorPath = MlsPolicy;
  // Kernels with a hat-like D_p use the gradient form (affine.hpp).
  static constexpr bool kGradientForm =
      !Kernel::constant_inertia && !AffineMoments<Dim, Kernel>::per_particle;
  static constexpr TensorTerms scatter_terms{.moment = true, .gradient = kGradientForm};
  void scatter_form(const Source& s, ScatterForm<Dim>& form) const {
    using F = ScatterForm<Dim>;
    this->momentum_form(s, form);
    for (int a = 0; a < Dim; ++a) {
      if constexpr (Kernel::constant_inertia) {
        form.gamma[a].template segment<Dim>(F::f) = -this->moments_.D_inv() * s.tauV.col(a);
      } else if constexpr (AffineMoments<Dim, Kernel>::per_particle) {
        form.gamma[a].template segment<Dim>(F::f) = -s.D_inv[a] * s.tauV.col(a);
      } else {
        form.beta[a].template segment<Dim>(F::f) = -s.tauV.col(a);
      }
    }
  }

  // The same columns in whole registers, for folded sums (FoldedForm).
  using FoldedPath = MlsPolicy;
  void folded_form(const Source& s, FoldedForm<Dim>& form) const requires(Dim >= 2) {
    this->folded_momentum_form(s, form);
    [&]<int... a>(std::integer_sequence<int, a...>) MPMTB_INLINE_LAMBDA {
      if constexpr (Kernel::constant_inertia) {
        ((form.gamma_f[a] = -this->moments_.D_inv() * column_lanes<a>(s.tauV)), ...);
      } else if constexpr (AffineMoments<Dim, Kernel>::per_particle) {
        ((form.gamma_f[a] = -s.D_inv[a] * column_lanes<a>(s.tauV)), ...);
      } else {
        ((form.beta_f[a] = -column_lanes<a>(s.tauV)), ...);
      }
    }
    (std::make_integer_sequence<int, Dim>{});
  }

  struct Gather {
    V v = V::Zero();
    M C = M::Zero();
    V D_inv = V::Zero();  // D_p^-1 for per-particle D_p (set by begin_gather)
  };
  static constexpr TensorTerms gather_terms{.moment = !kGradientForm, .gradient = kGradientForm};
  Gather gather_from(const GatherSums<Dim>& sums) const {
    return {sums.v, this->moments_.from_sums(sums.B, sums.G, sums.D_inv)};
  }
  Gather begin_gather(const Stencil<Dim, Kernel>& st) const {
    Gather g;
    if constexpr (AffineMoments<Dim, Kernel>::per_particle) {
      g.D_inv = AffineMoments<Dim, Kernel>::particle_D_inv(st);
    }
    return g;
  }
  void gather(Gather& g, Real w, const V& grad, const V& d, const V& v_i, const V&) const {
    g.v += w * v_i;
    g.C += v_i * this->moments_.weight_moment(w, grad, d, g.D_inv).transpose();
  }
  void finish(const Gather& g, Particles<Dim>& P, int p, Real dt) const {
    P.v[p] = g.v;
    P.C[p] = g.C;
    deformation_update<Dim>(P.F[p], g.C, dt);
    P.x[p] += dt * g.v;
  }
  // The fast path's finish from the stencil sums in registers (core/
  // policy_hooks.hpp): gather_from and finish in one, the same operations.
  using FinishRows = MlsPolicy;
  template <class Rows>
  MPMTB_INLINE void finish_rows(const Rows& r, const Stencil<Dim, Kernel>& st, Particles<Dim>& P,
                                int p, Real dt) const {
    this->template finish_affine_rows<true>(r, st, P, p, dt);
  }
};

struct MlsTransfer {
  static constexpr std::string_view name = "mls";
  static constexpr std::string_view description =
      "MLS-MPM: APIC with the MLS force and F from C (Hu et al. 2018); linear: gradient form; "
      "gimp: the particle's own D_p";
  // The paper behind it, BibTeX for `mpmtb list --bibtex`.
  static constexpr std::string_view bibtex = R"bib(@article{hu2018,
  author = {Hu, Yuanming and Fang, Yu and Ge, Ziheng and Qu, Ziyin and Zhu, Yixin and Pradhana, Andre and Jiang, Chenfanfu},
  title = {A moving least squares material point method with displacement discontinuity and two-way rigid body coupling},
  journal = {ACM Transactions on Graphics},
  volume = {37},
  number = {4},
  articleno = {150},
  year = {2018},
  doi = {10.1145/3197517.3201293}
})bib";
  static constexpr bool affine_momentum = true;
  // Whether the paper claims angular momentum conservation, affine part included, in both
  // transfers (if so, the conformance tests hold it to round-off).
  static constexpr bool conserves_angular_momentum = true;
  static constexpr bool needs_old_velocity = false;
  // F is updated from C_p and the MLS force is fused with the affine momentum,
  // so P2G and G2P cannot be split: only update_order = "usl" (core/stepper.hpp).
  static constexpr bool gradient_based = false;
  template <class Kernel>
  static constexpr bool supports = !kernel_full_inertia<Kernel>;
  static constexpr std::string_view unsupported_reason = kFullInertiaRefusal;
  template <int Dim, class Kernel>
  using Policy = MlsPolicy<Dim, Kernel>;
};

}  // namespace mpmtb
