// G2P's packed grid velocities (VelocityRows): the rows the fast path's
// gather sums over (core/tensor_transfer.hpp).
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

#include "core/huge_pages.hpp"
#include "core/types.hpp"

namespace mpmtb {

// G2P's input: for every grid node v_i (and, for the transfers that read it,
// v_i_old) padded to whole SIMD registers (core/pack.hpp), side by side, so
// that a node's contribution to every sum is a few SIMD operations. The solver
// packs the grid's velocities once per gather, over the active box.
template <int Dim, bool kOld>
struct VelocityRows {
  static constexpr int width = Dim == 3 ? 4 : Dim;                       // v_i and its padding
  static constexpr int min_reals = 16 / static_cast<int>(sizeof(Real));  // one SSE register
  static constexpr int N = std::max((kOld ? 2 : 1) * width, min_reals);
  static constexpr int old = width;  // slot of v_old
  std::vector<Real> values;          // N per node, node-major

  void resize(std::size_t nodes) {
    if (values.size() != nodes * N) assign_on_huge_pages(values, nodes * N, Real(0));
  }
  const Real* data() const { return values.data(); }
  // Packs `count` consecutive nodes from `first` (v_old is read only when kOld).
  void pack(long first, long count, const Vec<Dim>* v, const Vec<Dim>* v_old) {
    for (long i = first; i < first + count; ++i) {
      Real* r = &values[i * N];
      for (int a = 0; a < Dim; ++a) {
        r[a] = v[i][a];
        if constexpr (kOld) r[old + a] = v_old[i][a];
      }
    }
  }
};

}  // namespace mpmtb
