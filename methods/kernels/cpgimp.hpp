// Contiguous-particle GIMP (cpGIMP): Bardenhagen & Kober 2004, CMES 5(6)
// (the particle domain follows the deformation), in the axis-aligned form of
// Wallstedt & Guilkey 2008, JCP 227: the domain stays a box whose
// half-width along axis a is l_a = l0 F_aa (l0 = 1/(2 ppc), GridGeometry::l), so
// the weight is uGIMP's (kernels/gimp.hpp, eq. 40 of Bardenhagen & Kober) with a
// per-particle, per-axis half-width, and stays a tensor product. The shear terms
// of F are ignored (the usual cpGIMP approximation).
//
// Support. A box of half-width l reaches nodes within 1 + l cells: 3 nodes per
// axis cover l <= 1/2, 4 nodes (the cubic B-spline's first node, floor(xi) - 1)
// cover l <= 1, a stretch up to 1 / l0 = 2 ppc times (4x at ppc 2). The stencil
// is 4 nodes per axis, so that a bar stretched 2-3x stays inside it; l_a is
// clamped to [kMinHalfWidth, kMaxHalfWidth] (clamped() says when; the
// bar_stretch scene reports the largest l_a). At F = I the weights are uGIMP's
// bit for bit (the same operations on the same r); the fourth node's weight is
// then zero.
#pragma once

#include <algorithm>
#include <string_view>

#include "core/types.hpp"
#include "kernels/gimp.hpp"

namespace mpmtb {

struct CpGimpKernel {
  static constexpr std::string_view name = "cpgimp";
  static constexpr std::string_view description =
      "contiguous-particle GIMP (Wallstedt & Guilkey 2008): uGIMP with half-widths l_a = l0 F_aa "
      "clamped to [0.01, 1], 4 nodes per axis, C1 (D_p per particle)";
  static constexpr std::string_view bibtex = R"bib(@article{wallstedt2008,
  author = {Wallstedt, Philip C. and Guilkey, James E.},
  title = {An evaluation of explicit time integration schemes for use with the generalized interpolation material point method},
  journal = {Journal of Computational Physics},
  volume = {227},
  number = {22},
  pages = {9628--9642},
  year = {2008},
  doi = {10.1016/j.jcp.2008.07.019}
})bib";
  static constexpr int support = 4;
  static constexpr bool constant_inertia = false;
  static constexpr Real inertia = 0;
  // D_p depends on the particle (position and half-widths): taken from the stencil.
  static constexpr bool particle_inertia = true;
  // The stencil takes the particle's F (Stencil(x_p, F_p, geo), core/stencil.hpp).
  static constexpr bool deformed_domain = true;
  static constexpr Real default_half_width = GimpKernel::default_half_width;
  // The half-widths the 4-node support covers (above), and a floor that keeps
  // 1 / (2l) finite under compression (or an inverted F_aa).
  static constexpr Real kMaxHalfWidth = Real(1);
  static constexpr Real kMinHalfWidth = Real(0.01);

  // l_a = l0 F_aa (Wallstedt & Guilkey 2008), clamped to what the support covers.
  static Real half_width(Real l0, Real F_aa) {
    return std::clamp(l0 * F_aa, kMinHalfWidth, kMaxHalfWidth);
  }
  static bool clamped(Real l0, Real F_aa) {
    const Real l = l0 * F_aa;
    return !(l >= kMinHalfWidth && l <= kMaxHalfWidth);
  }
  // Whether any of the particle's half-widths is clamped (reported by the runs:
  // summary `domains_clamped_max`, core/registry.hpp).
  template <int Dim>
  static bool domain_clamped(Real l0, const Mat<Dim>& F) {
    for (int a = 0; a < Dim; ++a)
      if (clamped(l0, F(a, a))) return true;
    return false;
  }

  // S(r) and dS/dr for one half-width l <= 1, the hat averaged over [r - l, r + l]
  // (uGIMP's piecewise branches assume l <= 1/2; this form does not).
  static Real N(Real r, Real l = default_half_width) {
    Real w, dw;
    GimpKernel::averaged_hat(r, l, 1 / (2 * l), w, dw);
    return w;
  }
  static Real dN(Real r, Real l = default_half_width) {
    Real w, dw;
    GimpKernel::averaged_hat(r, l, 1 / (2 * l), w, dw);
    return dw;
  }

  // N and dN at the support's 4 nodes, r_k = r0 - k with r0 in [1, 2).
  static void weights(Real r0, Real* w, Real* dw, Real l = default_half_width) {
    const Real inv_2l = 1 / (2 * l);
    for (int k = 0; k < support; ++k) GimpKernel::averaged_hat(r0 - k, l, inv_2l, w[k], dw[k]);
  }
};

}  // namespace mpmtb
