// AFLIP and ASFLIP: Fei, Guo, Wu, Huang & Gao 2021, "Revisiting Integration in
// the Material Point Method: A Scheme for Easier Separation and Less
// Dissipation", ACM TOG 40(4) 109.
//   P2G, force       as APIC (affine momentum m_p C_p (x_i - x_p) w_ip)
//   G2P velocity     v_p <- v_PIC^{n+1} + alpha (v_p^n - v_PIC^n)
//   G2P position     x_p <- x_p + dt (v_PIC^{n+1} + beta alpha (v_p^n - v_PIC^n))
//   C_p, F update    as APIC
// with v_PIC = sum w v_i^{n+1}, v_PIC^n = sum w v_i^n (the grid velocity before
// forces, APIC's affine momentum included). AFLIP is beta = 0 (positions move
// with the grid, as APIC). ASFLIP takes beta_p = beta_max for a separating
// particle and beta_min otherwise; a particle counts as separating unless
// log det F_p^{n+1} < -1e-3 (compressed), the criterion and threshold of the
// authors' demo (nepluno/pyasflip), which also uses alpha = 0.99, beta_min = 0,
// beta_max = 1. The demo's extra rule, beta = 0 for a particle in contact with a
// collider, is kept for pinned particles only (they stay put); this testbed's
// colliders act on the grid, so particles touching them are not marked.
// alpha = 0 is APIC exactly. For alpha > 0 the FLIP increment does not keep the
// affine angular momentum, so the scheme does not claim its conservation.
// Parameters: [aflip] alpha; [asflip] alpha, beta_min, beta_max, all in [0, 1].
#pragma once

#include <fmt/format.h>

#include <cmath>
#include <string_view>

#include "core/errors.hpp"
#include "transfers/apic.hpp"

namespace mpmtb {

template <int Dim, class Kernel, bool kSeparation>
class AsflipPolicy : public ApicPolicy<Dim, Kernel> {
  using Base = ApicPolicy<Dim, Kernel>;
  using typename Base::M;
  using typename Base::V;

 public:
  AsflipPolicy(Parameters& params, Real dx)
      : Base(params, dx), alpha_(params.optional("alpha", 0.99, Range::closed(0, 1))) {
    if constexpr (kSeparation) {
      beta_min_ = params.optional("beta_min", 0, Range::closed(0, 1));
      beta_max_ = params.optional("beta_max", 1, Range::closed(0, 1));
      if (beta_min_ > beta_max_) {
        throw InputError(
            fmt::format("{}.beta_min = {} is out of range: must be <= {}.beta_max = {}",
                        params.context(), beta_min_, params.context(), beta_max_));
      }
    }
  }

  struct Gather {
    V v = V::Zero();
    V v_old = V::Zero();  // v_PIC^n
    M C = M::Zero();
    M grad_v = M::Zero();
    V D_inv = V::Zero();  // D_p^-1 for per-particle D_p (uGIMP; set by begin_gather)
  };
  using TensorPath = AsflipPolicy;
  static constexpr TensorTerms gather_terms{
      .moment = Kernel::constant_inertia || AffineMoments<Dim, Kernel>::per_particle,
      .gradient = true,
      .old = true};
  Gather gather_from(const GatherSums<Dim>& sums) const {
    return {sums.v, sums.v_old, this->moments_.from_sums(sums.B, sums.G, sums.D_inv), sums.G};
  }
  Gather begin_gather(const Stencil<Dim, Kernel>& st) const {
    Gather g;
    g.D_inv = this->moments_.particle_D_inv(st);
    return g;
  }
  void gather(Gather& g, Real w, const V& grad, const V& d, const V& v_i, const V& v_old_i) const {
    g.v += w * v_i;
    g.v_old += w * v_old_i;
    g.C += v_i * this->moments_.weight_moment(w, grad, d, g.D_inv).transpose();
    g.grad_v += v_i * grad.transpose();
  }
  void finish(const Gather& g, Particles<Dim>& P, int p, Real dt) const {
    const V flip = P.v[p] - g.v_old;  // v_p^n - v_PIC^n
    P.v[p] = g.v + alpha_ * flip;
    P.C[p] = g.C;
    deformation_update<Dim>(P.F[p], g.grad_v, dt);
    Real beta = 0;
    if constexpr (kSeparation) {
      // A pinned particle is held by its nodes: no position correction, as the
      // demo's beta = 0 for particles in contact with a collider.
      if (!P.pinned[p]) {
        beta = std::log(P.F[p].determinant()) < Real(-1e-3) ? beta_min_ : beta_max_;
      }
    }
    P.x[p] += dt * (g.v + (beta * alpha_) * flip);
  }

 private:
  Real alpha_;
  Real beta_min_ = 0, beta_max_ = 0;
};

struct AflipTransfer {
  static constexpr std::string_view name = "aflip";
  static constexpr std::string_view description =
      "AFLIP: APIC with the FLIP velocity increment blended in by aflip.alpha (default 0.99; "
      "Fei et al. 2021); alpha = 0 is APIC";
  // The paper behind it, BibTeX for `mpmtb list --bibtex`.
  static constexpr std::string_view bibtex = R"bib(@article{fei2021,
  author = {Fei, Yun (Raymond) and Guo, Qi and Wu, Rundong and Huang, Li and Gao, Ming},
  title = {Revisiting integration in the material point method: a scheme for easier separation and less dissipation},
  journal = {ACM Transactions on Graphics},
  volume = {40},
  number = {4},
  articleno = {109},
  year = {2021},
  doi = {10.1145/3450626.3459678}
})bib";
  static constexpr bool affine_momentum = true;
  // Whether the paper claims angular momentum conservation, affine part included, in both
  // transfers (if so, the conformance tests hold it to round-off).
  static constexpr bool conserves_angular_momentum = false;
  static constexpr bool needs_old_velocity = true;
  template <class Kernel>
  static constexpr bool supports = !kernel_full_inertia<Kernel>;
  static constexpr std::string_view unsupported_reason = kFullInertiaRefusal;
  template <int Dim, class Kernel>
  using Policy = AsflipPolicy<Dim, Kernel, false>;
};

struct AsflipTransfer {
  static constexpr std::string_view name = "asflip";
  static constexpr std::string_view description =
      "ASFLIP: AFLIP whose separating particles also move by beta x the FLIP increment "
      "(Fei et al. 2021); asflip.alpha 0.99, beta_min 0, beta_max 1";
  static constexpr std::string_view bibtex = AflipTransfer::bibtex;  // the same paper
  static constexpr bool affine_momentum = true;
  // Whether the paper claims angular momentum conservation, affine part included, in both
  // transfers (if so, the conformance tests hold it to round-off).
  static constexpr bool conserves_angular_momentum = false;
  static constexpr bool needs_old_velocity = true;
  // beta_p differs between particles, so sum m_p x_p does not advance by
  // dt sum m_i v_i: the centre of mass drifts from the momentum's path.
  static constexpr bool positions_follow_momentum = false;
  template <class Kernel>
  static constexpr bool supports = !kernel_full_inertia<Kernel>;
  static constexpr std::string_view unsupported_reason = kFullInertiaRefusal;
  template <int Dim, class Kernel>
  using Policy = AsflipPolicy<Dim, Kernel, true>;
};

}  // namespace mpmtb
