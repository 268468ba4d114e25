// Uniform GIMP kernel (uGIMP): Bardenhagen & Kober 2004, "The generalized
// interpolation material point method", CMES 5(6), eq. 40: the weight S_ip is the
// hat averaged over the particle's (undeformed) domain; uGIMP as analysed by Steffen,
// Kirby & Berzins 2008. With r = (x_p - x_i)/dx and l the particle half-width in
// cell units (l = 1/(2 ppc), GridGeometry::l):
//   S = 1 - (r^2 + l^2)/(2l)       for |r| < l
//   S = 1 - |r|                    for l <= |r| < 1 - l
//   S = (1 + l - |r|)^2 / (4l)     for 1 - l <= |r| < 1 + l,   0 beyond.
// C1 in r; 3 nodes per axis for l <= 1/2. D_p = sum w (x_i - x_p)^2 per axis is
// the hat's f (1 - f) dx^2 averaged over the domain plus l^2 dx^2 / 3: neither
// constant nor singular, so the affine transfers use the particle's own D_p
// (transfers/affine.hpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <string_view>

#include "core/types.hpp"

namespace mpmtb {

struct GimpKernel {
  static constexpr std::string_view name = "gimp";
  static constexpr std::string_view description =
      "uniform GIMP (Bardenhagen & Kober 2004), particle half-width l = 1/(2 ppc), 3 nodes per "
      "axis, C1 (D_p per particle)";
  // The paper behind it, BibTeX for `mpmtb list --bibtex`.
  static constexpr std::string_view bibtex = R"bib(@article{bardenhagen2004,
  author = {Bardenhagen, Scott G. and Kober, Edward M.},
  title = {The generalized interpolation material point method},
  journal = {Computer Modeling in Engineering and Sciences},
  volume = {5},
  number = {6},
  pages = {477--495},
  year = {2004}
})bib";
  static constexpr int support = 3;
  static constexpr bool constant_inertia = false;
  static constexpr Real inertia = 0;
  // D_p depends on the particle's position: the affine transfers take it from the stencil.
  static constexpr bool particle_inertia = true;
  // The half-width of the default grid (two particles per cell per axis).
  static constexpr Real default_half_width = Real(0.25);
  // Largest half-width the 3-node support covers (one particle per cell).
  static constexpr Real max_half_width = Real(0.5);

  // The piecewise definition (reference form; tests compare weights() against it).
  static Real N(Real r, Real l = default_half_width) {
    const Real a = std::abs(r);
    if (a < l) return 1 - (r * r + l * l) / (2 * l);
    if (a < 1 - l) return 1 - a;
    if (a < 1 + l) {
      const Real b = 1 + l - a;
      return b * b / (4 * l);
    }
    return 0;
  }
  // dS/dr, derived from the branches above.
  static Real dN(Real r, Real l = default_half_width) {
    const Real a = std::abs(r);
    const Real s = r < 0 ? -1 : 1;
    if (a < l) return -r / l;
    if (a < 1 - l) return -s;
    if (a < 1 + l) return -s * (1 + l - a) / (2 * l);
    return 0;
  }

  // N and dN at the support's 3 nodes, r_k = r0 - k with r0 in [1/2, 3/2), without
  // branches. S is the hat averaged over [r - l, r + l]:
  //   S(r) = (Phi(r + l) - Phi(r - l)) / (2l),  dS/dr = (hat(r + l) - hat(r - l)) / (2l),
  // with Phi the hat's antiderivative, Phi(c) = 1/2 + c - c|c|/2 for c = clamp(x, -1, 1),
  // and hat(x) = 1 - |c|. Equal to N(r, l) and dN(r, l) up to round-off.
  static void weights(Real r0, Real* w, Real* dw, Real l = default_half_width) {
    const Real inv_2l = 1 / (2 * l);
    for (int k = 0; k < support; ++k) averaged_hat(r0 - k, l, inv_2l, w[k], dw[k]);
  }
  // S and dS/dr at one node, r = (x_p - x_i)/dx, inv_2l = 1 / (2l) (shared with cpGIMP,
  // kernels/cpgimp.hpp).
  static void averaged_hat(Real r, Real l, Real inv_2l, Real& w, Real& dw) {
    const Real cp = std::clamp(r + l, Real(-1), Real(1));
    const Real cm = std::clamp(r - l, Real(-1), Real(1));
    const Real phi_p = cp - Real(0.5) * cp * std::abs(cp);
    const Real phi_m = cm - Real(0.5) * cm * std::abs(cm);
    w = (phi_p - phi_m) * inv_2l;
    dw = (std::abs(cm) - std::abs(cp)) * inv_2l;
  }
};

}  // namespace mpmtb
