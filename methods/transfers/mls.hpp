// MLS-MPM: Hu, Fang, Ge, Qu, Zhu, Pradhana & Jiang 2018, "A Moving Least Squares
// Material Point Method with Displacement Discontinuity and Two-Way Rigid Body
// Coupling", ACM TOG 37(4).
//   P2G momentum  m_p (v_p + C_p (x_i - x_p)) w_ip                 (APIC part, eq. 13)
//   force         f_i += -D_p^-1 V0_p tau_p (x_i - x_p) w_ip       (eq. 16-18)
//   G2P           v_p = sum w v_i,  C_p = D_p^-1 sum w v_i (x_i - x_p)^T
//   F update      F_p <- (I + dt C_p) F_p                           (eq. 17)
// D_p = dx^2/4 I (quadratic) or dx^2/3 I (cubic). With the linear hat D_p is
// singular at nodes, so that combination is refused.
#pragma once

#include <string_view>

#include "core/parameters.hpp"
#include "core/particles.hpp"

namespace mpmtb {

template <int Dim, class Kernel>
class MlsPolicy {
  using V = Vec<Dim>;
  using M = Mat<Dim>;

 public:
  MlsPolicy(Parameters&, Real dx) : D_inv_(1 / (Kernel::inertia * dx * dx)) {}

  struct Source {
    Real m;
    V mv;
    M mC;
    M force;  // -D^-1 V0 tau: the stress part of the affine field
  };
  Source prepare(const Particles<Dim>& P, int p, const M& tauV) const {
    return {P.m[p], P.m[p] * P.v[p], P.m[p] * P.C[p], -D_inv_ * tauV};
  }
  void scatter(const Source& s, Real w, const V& /*grad*/, const V& d, Real& m_i, V& p_i,
               V& f_i) const {
    m_i += w * s.m;
    p_i += w * (s.mv + s.mC * d);
    f_i += w * (s.force * d);
  }

  struct Gather {
    V v = V::Zero();
    M B = M::Zero();  // sum w v_i (x_i - x_p)^T
  };
  void gather(Gather& g, Real w, const V& /*grad*/, const V& d, const V& v_i, const V&) const {
    g.v += w * v_i;
    g.B += w * v_i * d.transpose();
  }
  void finish(const Gather& g, Particles<Dim>& P, int p, Real dt) const {
    P.v[p] = g.v;
    P.C[p] = D_inv_ * g.B;
    P.F[p] = (M::Identity() + dt * P.C[p]) * P.F[p];
    P.x[p] += dt * P.v[p];
  }

 private:
  Real D_inv_;
};

struct MlsTransfer {
  static constexpr std::string_view name = "mls";
  static constexpr std::string_view description =
      "MLS-MPM: affine momentum, MLS force, F from C (Hu et al. 2018)";
  static constexpr bool affine_momentum = true;
  static constexpr bool needs_old_velocity = false;
  template <class Kernel>
  static constexpr bool supports = Kernel::constant_inertia;
  static constexpr std::string_view unsupported_reason =
      "MLS-MPM needs the constant D_p of a B-spline kernel; the linear hat's D_p is singular "
      "at grid nodes";
  template <int Dim, class Kernel>
  using Policy = MlsPolicy<Dim, Kernel>;
};

}  // namespace mpmtb
