// Linear hat kernel: the original MPM shape function (Sulsky, Chen & Schreyer 1994).
#pragma once

#include <cmath>
#include <string_view>

#include "core/papers.hpp"
#include "core/types.hpp"

namespace mpmtb {

struct LinearKernel {
  static constexpr std::string_view name = "linear";
  static constexpr std::string_view description =
      "linear hat, 2 nodes per axis, C0 gradients (cell-crossing noise)";
  static constexpr std::string_view bibtex = papers::sulsky1994;  // mpmtb list --bibtex
  static constexpr int support = 2;
  // D_p = sum_i w_ip (x_i - x_p)(x_i - x_p)^T is diag(f (1 - f)) dx^2 for the hat,
  // f the position inside the cell: singular at nodes, so no constant inertia.
  static constexpr bool constant_inertia = false;
  static constexpr Real inertia = 0;

  static Real N(Real r) {
    const Real a = std::abs(r);
    return a < 1 ? 1 - a : 0;
  }
  // One-sided at the kink, matching the stencil's choice of cell by floor():
  // a particle on a node sees slopes -1 (r = 0) and +1 (r = -1), summing to 0.
  static Real dN(Real r) {
    if (r >= 0 && r < 1) return -1;
    if (r >= -1 && r < 0) return 1;
    return 0;
  }
};

}  // namespace mpmtb
