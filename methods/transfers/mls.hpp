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

#include "core/parameters.hpp"
#include "core/particles.hpp"
#include "transfers/affine.hpp"

namespace mpmtb {

template <int Dim, class Kernel>
class MlsPolicy {
  using V = Vec<Dim>;
  using M = Mat<Dim>;

 public:
  MlsPolicy(Parameters&, Real dx) : moments_(dx) {}

  struct Source {
    Real m;
    V mv;
    M mC;
    M tauV;
  };
  Source prepare(const Particles<Dim>& P, int p, const M& tauV) const {
    return {P.m[p], P.m[p] * P.v[p], P.m[p] * P.C[p], tauV};
  }
  void scatter(const Source& s, Real w, const V& grad, const V& d, Real& m_i, V& p_i,
               V& f_i) const {
    m_i += w * s.m;
    p_i += w * s.mv + s.mC * (w * d);
    f_i -= s.tauV * moments_.weight_moment(w, grad, d);
  }

  struct Gather {
    V v = V::Zero();
    M C = M::Zero();
  };
  void gather(Gather& g, Real w, const V& grad, const V& d, const V& v_i, const V&) const {
    g.v += w * v_i;
    g.C += v_i * moments_.weight_moment(w, grad, d).transpose();
  }
  void finish(const Gather& g, Particles<Dim>& P, int p, Real dt) const {
    P.v[p] = g.v;
    P.C[p] = g.C;
    P.F[p] = (M::Identity() + dt * g.C) * P.F[p];
    P.x[p] += dt * g.v;
  }

 private:
  AffineMoments<Dim, Kernel> moments_;
};

struct MlsTransfer {
  static constexpr std::string_view name = "mls";
  static constexpr std::string_view description =
      "MLS-MPM: affine momentum, MLS force, F from C (Hu et al. 2018)";
  static constexpr bool affine_momentum = true;
  static constexpr bool needs_old_velocity = false;
  template <class Kernel>
  static constexpr bool supports = true;
  static constexpr std::string_view unsupported_reason = "";
  template <int Dim, class Kernel>
  using Policy = MlsPolicy<Dim, Kernel>;
};

}  // namespace mpmtb
