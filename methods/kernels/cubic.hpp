// Cubic B-spline kernel (Steffen, Kirby & Berzins 2008; Stomakhin et al. 2013, eq. 122).
#pragma once

#include <cmath>
#include <string_view>

#include "core/papers.hpp"
#include "core/types.hpp"

namespace mpmtb {

struct CubicKernel {
  static constexpr std::string_view name = "cubic";
  static constexpr std::string_view description =
      "cubic B-spline, 4 nodes per axis, C2 (D_p = dx^2/3 I)";
  static constexpr std::string_view bibtex = papers::steffen2008;  // mpmtb list --bibtex
  static constexpr int support = 4;
  // D_p = (n + 1) dx^2 / 12 for a B-spline of degree n: dx^2 / 3 here.
  static constexpr bool constant_inertia = true;
  static constexpr Real inertia = Real(1) / 3;

  // N(r) = |r|^3 / 2 - r^2 + 2/3 for |r| < 1;  (2 - |r|)^3 / 6 for 1 <= |r| < 2.
  static Real N(Real r) {
    const Real a = std::abs(r);
    if (a < 1) return Real(0.5) * a * a * a - a * a + Real(2) / 3;
    if (a < 2) {
      const Real b = 2 - a;
      return b * b * b / 6;
    }
    return 0;
  }
  static Real dN(Real r) {
    const Real a = std::abs(r);
    const Real s = r < 0 ? -1 : 1;
    if (a < 1) return s * (Real(1.5) * a * a - 2 * a);
    if (a < 2) {
      const Real b = 2 - a;
      return -s * b * b / 2;
    }
    return 0;
  }

  // N and dN at the support's 4 nodes, r_k = r0 - k with r0 in [1, 2) the
  // offset to the first node: the branches of N resolved once (same formulas).
  // T is Real, or a SIMD pack of the axes' r0 (Stencil computes all axes at once).
  template <class T>
  static void weights(T r0, T* w, T* dw) {
    const T b0 = Real(2) - r0, a1 = r0 - Real(1), a2 = Real(2) - r0, b3 = r0 - Real(1);
    w[0] = b0 * b0 * b0 / Real(6);
    dw[0] = -b0 * b0 / Real(2);
    w[1] = Real(0.5) * a1 * a1 * a1 - a1 * a1 + Real(2) / 3;
    dw[1] = Real(1.5) * a1 * a1 - Real(2) * a1;
    w[2] = Real(0.5) * a2 * a2 * a2 - a2 * a2 + Real(2) / 3;
    dw[2] = -(Real(1.5) * a2 * a2 - Real(2) * a2);
    w[3] = b3 * b3 * b3 / Real(6);
    dw[3] = b3 * b3 / Real(2);
  }
};

}  // namespace mpmtb
