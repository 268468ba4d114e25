// Moments shared by the affine transfers (APIC, MLS-MPM).
//
// B_p = sum_i w_ip v_i (x_i - x_p)^T and C_p = B_p D_p^-1 (Jiang et al. 2015,
// eq. 8-10), with D_p = inertia dx^2 I for a B-spline. For the linear hat D_p is
// singular at nodes, but per axis grad w_ip D_p = w_ip (x_i - x_p) holds exactly,
// so C_p = sum_i v_i grad w^T is the same matrix wherever D_p is invertible
// and extends it continuously to the nodes. The same identity turns MLS-MPM's
// force direction D_p^-1 (x_i - x_p) w_ip into grad w_ip for the hat.
// For uGIMP (kernels/gimp.hpp) D_p is neither constant nor singular and neither
// shortcut holds: C_p = B_p D_p^-1 with the particle's own diagonal D_p from its
// stencil (Stencil::inertia_diagonal), passed in as D_p^-1 (`Dp_inv`).
#pragma once

#include <string_view>

#include "core/stencil.hpp"
#include "core/types.hpp"

namespace mpmtb {

// Kernels whose D_p is a full matrix (CPDI: J J^T under shear, kernels/cpdi.hpp)
// declare full_inertia = true; the transfers below take D_p diagonal (a constant,
// the hat's gradient form, or the particle's own diagonal), so they refuse them.
template <class Kernel>
constexpr bool kernel_full_inertia = [] {
  if constexpr (requires { Kernel::full_inertia; }) {
    return Kernel::full_inertia;
  } else {
    return false;
  }
}();
inline constexpr std::string_view kFullInertiaRefusal =
    "the kernel's D_p is a full matrix (CPDI: J J^T plus the corners' hat variances) and this "
    "transfer takes D_p diagonal (transfers/affine.hpp); use pic, flip, xpic or tpic";

template <int Dim, class Kernel>
class AffineMoments {
  using V = Vec<Dim>;
  using M = Mat<Dim>;

 public:
  // D_p differs per particle: the forms below that take Dp_inv must be used.
  static constexpr bool per_particle = kernel_particle_inertia<Kernel>;

  explicit AffineMoments(Real dx)
      : D_inv_(Kernel::constant_inertia ? 1 / (Kernel::inertia * dx * dx) : 0) {}

  // The vector q_ip with C_p = sum_i v_i q_ip^T: D^-1 w (x_i - x_p), or grad w.
  // C_p from the stencil sums B = sum w v_i (x_i - x_p)^T and G = sum v_i grad w^T.
  M from_sums(const M& B, const M& G) const {
    static_assert(!per_particle, "this kernel's D_p differs per particle: pass D_p^-1");
    if constexpr (Kernel::constant_inertia) {
      return B * D_inv_;
    } else {
      return G;
    }
  }
  // The same for any kernel, with Dp_inv = D_p^-1 (diagonal) of this particle; the
  // kernels with constant or singular D_p ignore it.
  M from_sums(const M& B, const M& G, const V& Dp_inv) const {
    if constexpr (per_particle) {
      return B * Dp_inv.asDiagonal();
    } else {
      return from_sums(B, G);
    }
  }
  Real D_inv() const { return D_inv_; }

  V weight_moment(Real w, const V& grad, const V& d) const {
    static_assert(!per_particle, "this kernel's D_p differs per particle: pass D_p^-1");
    if constexpr (Kernel::constant_inertia) {
      return (w * D_inv_) * d;
    } else {
      return grad;
    }
  }
  V weight_moment(Real w, const V& grad, const V& d, const V& Dp_inv) const {
    if constexpr (per_particle) {
      return (w * d).cwiseProduct(Dp_inv);
    } else {
      return weight_moment(w, grad, d);
    }
  }

  // D_p^-1 of the particle whose stencil this is (per-particle kernels; zero otherwise).
  static V particle_D_inv(const Stencil<Dim, Kernel>& st) {
    if constexpr (per_particle) {
      return st.inertia_diagonal().cwiseInverse();
    } else {
      return V::Zero();
    }
  }

 private:
  Real D_inv_;
};

}  // namespace mpmtb
