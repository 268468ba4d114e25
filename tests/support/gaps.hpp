// How far two fields are apart, for tests that compare two computations of the
// same quantity to round-off.
#pragma once

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <vector>

#include "core/types.hpp"

namespace mpmtb::testing {

// Largest |a - b| relative to the largest |a|, over a whole nodal or particle field
// (scalars, vectors or matrices); infinite when the sizes differ.
template <class T>
Real relative_gap(const std::vector<T>& a, const std::vector<T>& b) {
  if (a.size() != b.size()) return INFINITY;
  Real gap = 0, scale = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if constexpr (std::is_arithmetic_v<T>) {
      gap = std::max(gap, std::abs(a[i] - b[i]));
      scale = std::max(scale, std::abs(a[i]));
    } else {
      gap = std::max(gap, (a[i] - b[i]).cwiseAbs().maxCoeff());
      scale = std::max(scale, a[i].cwiseAbs().maxCoeff());
    }
  }
  return scale > 0 ? gap / scale : gap;
}

// The identities between schemes (FLIP with alpha = 0 is PIC, XPIC(1) is PIC,
// AFLIP with alpha = 0 is APIC) compare a transfer that keeps v_old apart with
// one whose P2G folds the force into the momentum (p_i + dt f_i, NodeSums): the
// same symplectic Euler step with its sums in another order, so the two agree
// to round-off, not bit for bit. Over the tests' 50 steps of a spinning body the
// gap stays within this bound, relative to the field's largest value.
inline constexpr Real kReorderedSumsTolerance = 1e-12;

}  // namespace mpmtb::testing
