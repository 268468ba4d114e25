// TPIC: Taylor particle-in-cell. Nakamura, Matsumura & Mizutani 2023, "Taylor
// particle-in-cell transfer and kernel correction for material point method",
// CMAME 403, 115720.
//   P2G momentum  m_p (v_p + L_p (x_i - x_p)) w_ip   (first-order Taylor expansion of v_p)
//   force, F      as PIC/APIC (kernel gradient)
//   G2P           v_p = sum w v_i,  L_p = sum v_i grad w_ip^T  (the velocity gradient)
// So TPIC is APIC with C_p := L_p; the linear hat already uses this C_p in APIC
// (transfers/affine.hpp), so there the two are the same scheme.
// Angular momentum is not claimed: P2G hands the grid m_p eps : (L_p D_p), but
// with a B-spline G2P returns L_p D_p != B_p = sum w v_i (x_i - x_p)^T, so the
// affine part is not exactly what the grid held (tests/unit/tpic_test.cpp
// measures the drift against PIC's).
#pragma once

#include <string_view>

#include "transfers/apic.hpp"

namespace mpmtb {

template <int Dim, class Kernel>
class TpicPolicy : public ApicPolicy<Dim, Kernel> {
  using Base = ApicPolicy<Dim, Kernel>;
  using typename Base::M;
  using typename Base::V;

 public:
  using Base::Base;
  using typename Base::Gather;

  // P2G is APIC's (scatter, scatter_form); G2P keeps the gradient sum as C_p.
  using TensorPath = TpicPolicy;
  static constexpr TensorTerms gather_terms{.gradient = true};
  Gather gather_from(const GatherSums<Dim>& sums) const { return {sums.v, sums.G, sums.G}; }
  void gather(Gather& g, Real w, const V& grad, const V&, const V& v_i, const V&) const {
    g.v += w * v_i;
    g.C += v_i * grad.transpose();
    g.grad_v += v_i * grad.transpose();
  }
};

struct TpicTransfer {
  static constexpr std::string_view name = "tpic";
  static constexpr std::string_view description =
      "TPIC: Taylor PIC, P2G with the velocity gradient C_p = sum v_i grad w^T "
      "(Nakamura et al. 2023); APIC with the linear hat";
  // The paper behind it, BibTeX for `mpmtb list --bibtex`.
  static constexpr std::string_view bibtex = R"bib(@article{nakamura2023,
  author = {Nakamura, Keita and Matsumura and Mizutani},
  title = {Taylor particle-in-cell transfer and kernel correction for material point method},
  journal = {Computer Methods in Applied Mechanics and Engineering},
  volume = {403},
  pages = {115720},
  year = {2023},
  doi = {10.1016/j.cma.2022.115720}
})bib";
  static constexpr bool affine_momentum = true;
  // Not claimed: the G2P gradient is not B_p D_p^-1 for B-splines (see above).
  static constexpr bool conserves_angular_momentum = false;
  static constexpr bool needs_old_velocity = false;
  template <class Kernel>
  static constexpr bool supports = true;
  static constexpr std::string_view unsupported_reason = "";
  template <int Dim, class Kernel>
  using Policy = TpicPolicy<Dim, Kernel>;
};

}  // namespace mpmtb
