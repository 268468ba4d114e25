// PIC: the original particle-in-cell transfer as used by MPM (Sulsky, Chen &
// Schreyer 1994, "A particle method for history-dependent materials", CMAME 118;
// Harlow 1964 for PIC).
//   P2G momentum  m_p v_p w_ip
//   force         f_i += -V0_p tau_p grad w_ip   (sigma_p V_p = tau_p V0_p)
//   G2P           v_p = sum w v_i                (no particle velocity survives)
//   F update      F_p <- (I + dt sum v_i grad w^T) F_p
// Dissipative: the G2P projection loses kinetic energy and angular momentum.
#pragma once

#include <string_view>

#include "core/deformation.hpp"
#include "core/papers.hpp"
#include "core/parameters.hpp"
#include "core/particles.hpp"
#include "core/tensor_transfer.hpp"

namespace mpmtb {

template <int Dim, class Kernel>
class PicPolicy {
 protected:
  using V = Vec<Dim>;
  using M = Mat<Dim>;

 public:
  PicPolicy(Parameters&, Real) {}

  struct Source {
    Real m;
    V mv;
    const M& tauV;  // read in place (as ApicPolicy's)
  };
  Source prepare(const Particles<Dim>& P, int p, const M& tauV) const {
    return {P.m[p], P.m[p] * P.v[p], tauV};
  }
  void scatter(const Source& s, Real w, const V& grad, const V&, Real& m_i, V& p_i, V& f_i) const {
    m_i += w * s.m;
    p_i += w * s.mv;
    f_i -= s.tauV * grad;
  }

  // The base solver's fast path (core/tensor_transfer.hpp): the same math as
  // scatter() and gather(), as sums over the stencil.
  using TensorPath = PicPolicy;
  static constexpr TensorTerms scatter_terms{.gradient = true};
  void scatter_form(const Source& s, ScatterForm<Dim>& form) const {
    using F = ScatterForm<Dim>;
    form.alpha[F::m] = s.m;
    form.alpha.template segment<Dim>(F::p) = s.mv;
    for (int a = 0; a < Dim; ++a) form.beta[a].template segment<Dim>(F::f) = -s.tauV.col(a);
  }
  // The same columns in whole registers, for folded sums (FoldedForm).
  using FoldedPath = PicPolicy;
  void folded_form(const Source& s, FoldedForm<Dim>& form) const requires(Dim >= 2) {
    form.set_mass_momentum(s.m, s.mv);
    [&]<int... a>(std::integer_sequence<int, a...>) MPMTB_INLINE_LAMBDA {
      ((form.beta_f[a] = -column_lanes<a>(s.tauV)), ...);
    }
    (std::make_integer_sequence<int, Dim>{});
  }

  struct Gather {
    V v = V::Zero();
    M grad_v = M::Zero();
  };
  static constexpr TensorTerms gather_terms{.gradient = true};
  Gather gather_from(const GatherSums<Dim>& sums) const { return {sums.v, sums.G}; }
  void gather(Gather& g, Real w, const V& grad, const V&, const V& v_i, const V&) const {
    g.v += w * v_i;
    g.grad_v += v_i * grad.transpose();
  }
  void finish(const Gather& g, Particles<Dim>& P, int p, Real dt) const {
    P.v[p] = g.v;
    deformation_update<Dim>(P.F[p], g.grad_v, dt);
    P.x[p] += dt * g.v;
  }
};

struct PicTransfer {
  static constexpr std::string_view name = "pic";
  static constexpr std::string_view description =
      "PIC: particle velocity replaced by the grid's (Sulsky et al. 1994); dissipative";
  static constexpr std::string_view bibtex = papers::sulsky1994;  // mpmtb list --bibtex
  static constexpr bool affine_momentum = false;
  // Whether the paper claims angular momentum conservation, affine part included, in both
  // transfers (if so, the conformance tests hold it to round-off).
  static constexpr bool conserves_angular_momentum = false;
  static constexpr bool needs_old_velocity = false;
  template <class Kernel>
  static constexpr bool supports = true;
  static constexpr std::string_view unsupported_reason = "";
  template <int Dim, class Kernel>
  using Policy = PicPolicy<Dim, Kernel>;
};

}  // namespace mpmtb
