// The pinned particles of a state: their positions, and how far they moved.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

#include "core/particles.hpp"

namespace mpmtb::testing {

// Positions of the pinned particles, in particle order.
template <int Dim>
std::vector<Vec<Dim>> pinned_positions(const Particles<Dim>& P) {
  std::vector<Vec<Dim>> x;
  for (std::size_t p = 0; p < P.size(); ++p) {
    if (P.pinned[p]) x.push_back(P.x[p]);
  }
  return x;
}

// The largest distance of a pinned particle from its position in `recorded`
// (pinned_positions of the same particles, earlier).
template <int Dim>
Real largest_pinned_displacement(const Particles<Dim>& P, const std::vector<Vec<Dim>>& recorded) {
  std::size_t k = 0;
  Real moved = 0;
  for (std::size_t p = 0; p < P.size(); ++p) {
    if (P.pinned[p]) moved = std::max(moved, (P.x[p] - recorded[k++]).norm());
  }
  return moved;
}

}  // namespace mpmtb::testing
