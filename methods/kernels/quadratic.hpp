// Quadratic B-spline kernel (Steffen, Kirby & Berzins 2008; Stomakhin et al. 2013, eq. 123).
#pragma once

#include <cmath>
#include <string_view>

#include "core/papers.hpp"
#include "core/types.hpp"

namespace mpmtb {

struct QuadraticKernel {
  static constexpr std::string_view name = "quadratic";
  static constexpr std::string_view description =
      "quadratic B-spline, 3 nodes per axis, C1 (D_p = dx^2/4 I)";
  static constexpr std::string_view bibtex = papers::steffen2008;  // mpmtb list --bibtex
  static constexpr int support = 3;
  // D_p = (n + 1) dx^2 / 12 for a B-spline of degree n: dx^2 / 4 here.
  static constexpr bool constant_inertia = true;
  static constexpr Real inertia = Real(1) / 4;

  // N(r) = 3/4 - r^2 for |r| < 1/2;  (3/2 - |r|)^2 / 2 for 1/2 <= |r| < 3/2 (squared, not cubed).
  static Real N(Real r) {
    const Real a = std::abs(r);
    if (a < Real(0.5)) return Real(0.75) - a * a;
    if (a < Real(1.5)) {
      const Real b = Real(1.5) - a;
      return Real(0.5) * b * b;
    }
    return 0;
  }
  static Real dN(Real r) {
    const Real a = std::abs(r);
    const Real s = r < 0 ? -1 : 1;
    if (a < Real(0.5)) return -2 * r;
    if (a < Real(1.5)) return -s * (Real(1.5) - a);
    return 0;
  }

  // N and dN at the support's 3 nodes, r_k = r0 - k with r0 in [1/2, 3/2) the
  // offset to the first node: the branches of N resolved once (same formulas).
  // T is Real, or a SIMD pack of the axes' r0 (Stencil computes all axes at once).
  template <class T>
  static void weights(T r0, T* w, T* dw) {
    const T b = Real(1.5) - r0, r1 = r0 - Real(1), c = r0 - Real(0.5);
    w[0] = Real(0.5) * b * b;
    dw[0] = -b;
    w[1] = Real(0.75) - r1 * r1;
    dw[1] = Real(-2) * r1;
    w[2] = Real(0.5) * c * c;
    dw[2] = c;
  }
};

}  // namespace mpmtb
