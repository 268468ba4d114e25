// Quadratic B-spline kernel (Steffen, Kirby & Berzins 2008; Stomakhin et al. 2013, eq. 123).
#pragma once

#include <cmath>
#include <string_view>

#include "core/types.hpp"

namespace mpmtb {

struct QuadraticKernel {
  static constexpr std::string_view name = "quadratic";
  static constexpr std::string_view description =
      "quadratic B-spline, 3 nodes per axis, C1 (D_p = dx^2/4 I)";
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
};

}  // namespace mpmtb
