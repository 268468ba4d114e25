// A model's per-particle formula over a vector register of particles, one
// particle per lane (ModelBase's stress batches): F_p's entries in, one pack per
// entry, and V0_p tau_p out. A formula written once as a template on its number
// type T runs with T = Lanes in the batches and with T = Real for one particle,
// the same operations in each lane, so the two give the same bits.
#pragma once

#include <cstring>
#include <utility>
#include <vector>

#include "core/batch_log.hpp"
#include "core/types.hpp"

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

namespace mpmtb {

using Lanes = detail::LogPack;  // the batch logarithm's register (core/batch_log.hpp)
inline constexpr int kLanes = detail::kLogLanes;

// det F lane by lane: the cofactor expansion along the first row in Eigen's
// order (Eigen/src/LU/Determinant.h), so that each lane is F_p.determinant().
template <int Dim, class T>
MPMTB_INLINE inline T determinant_of(const T (&F)[Dim][Dim]) {
  if constexpr (Dim == 1) {
    return F[0][0];
  } else if constexpr (Dim == 2) {
    return F[0][0] * F[1][1] - F[1][0] * F[0][1];
  } else {
    const auto term = [&](int a, int b, int c) MPMTB_INLINE_LAMBDA {
      return F[0][a] * (F[1][b] * F[2][c] - F[1][c] * F[2][b]);
    };
    return term(0, 1, 2) - term(1, 0, 2) + term(2, 0, 1);
  }
}

// Lane l of each pack from f(l) for l < lanes, `rest` beyond. Built in
// registers: lanes stored one by one and loaded as a pack would stall the
// load on store forwarding.
template <class F>
MPMTB_INLINE inline Lanes lanes_from(int lanes, Real rest, F&& f) {
  return [&]<int... l>(std::integer_sequence<int, l...>) MPMTB_INLINE_LAMBDA {
    return Lanes{(l < lanes ? f(l) : rest)...};
  }
  (std::make_integer_sequence<int, kLanes>{});
}

// out[i][j] = M[ids[l]](i, j) in lane l < lanes; the identity in the others.
template <int Dim>
MPMTB_INLINE inline void load_lanes(const std::vector<Mat<Dim>>& M, const int* ids, int lanes,
                                    Lanes (&out)[Dim][Dim]) {
  for (int i = 0; i < Dim; ++i) {
    for (int j = 0; j < Dim; ++j) {
      out[i][j] = lanes_from(lanes, i == j ? Real(1) : Real(0),
                             [&](int l) MPMTB_INLINE_LAMBDA { return M[ids[l]](i, j); });
    }
  }
}

// out(l) = the matrix of lane l, for l < lanes.
template <int Dim, class Out>
MPMTB_INLINE inline void store_lanes(const Lanes (&in)[Dim][Dim], int lanes, Out&& out) {
  alignas(sizeof(Lanes)) Real e[Dim][Dim][kLanes];
  std::memcpy(e, in, sizeof e);
  for (int l = 0; l < lanes; ++l) {
    Mat<Dim>& m = out(l);
    for (int i = 0; i < Dim; ++i) {
      for (int j = 0; j < Dim; ++j) m(i, j) = e[i][j][l];
    }
  }
}

}  // namespace mpmtb

#pragma GCC diagnostic pop
