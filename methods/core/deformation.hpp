// The deformation-gradient update of G2P, shared by every transfer:
//   F_p^{n+1} = (I + dt L_p) F_p^n,
// L_p the particle's velocity gradient (sum_i v_i grad w_ip^T, or MLS-MPM's C_p,
// Hu et al. 2018, eq. 17): the update of Sulsky, Chen & Schreyer 1994, "A
// particle method for history-dependent materials", CMAME 118.
// Evaluated as F + dt L F column by column in SIMD registers, one axis per lane:
// written with Eigen's 3x3 product it went through a temporary on the stack that
// was stored in scalars and read back in packets, which stalled G2P on store
// forwarding (perf: about a fifth of MLS-MPM's G2P in 3D).
#pragma once

#include <cstring>

#include "core/pack.hpp"
#include "core/stencil.hpp"
#include "core/types.hpp"

namespace mpmtb {

// Column j of a small matrix in the first Dim lanes of an AxisPack, zero beyond.
// In 2D and 3D one whole-register load inside A's storage (dense, column-major)
// and one shuffle, where lane-by-lane inserts took two or three instructions a value.
template <int Dim>
MPMTB_INLINE inline AxisPack column_pack(const Mat<Dim>& A, int j) {
  static_assert(sizeof(Mat<Dim>) == Dim * Dim * sizeof(Real), "A is stored dense");
  constexpr AxisPack zero{};
  AxisPack v;
  if constexpr (Dim == 3) {
    // The last column from (2, 1): four values inside A.
    std::memcpy(&v, A.data() + (j < 2 ? 3 * j : 5), sizeof v);
    return j < 2 ? __builtin_shufflevector(v, zero, 0, 1, 2, 4)
                 : __builtin_shufflevector(v, zero, 1, 2, 3, 4);
  } else if constexpr (Dim == 2) {
    std::memcpy(&v, A.data(), sizeof v);  // the whole matrix
    return j == 0 ? __builtin_shufflevector(v, zero, 0, 1, 4, 4)
                  : __builtin_shufflevector(v, zero, 2, 3, 4, 4);
  } else {
    AxisPack c{};
    c[0] = A(0, 0);
    return c;
  }
}

// A's columns from the first Dim lanes of `columns` (the lanes beyond ignored):
// in 2D and 3D whole-register stores inside A's storage, in an order that leaves
// every value right (in 3D the first two stores also write the next column's
// first value, which the next store writes again).
template <int Dim>
MPMTB_INLINE inline void store_columns(Mat<Dim>& A, const AxisPack (&columns)[Dim]) {
  static_assert(sizeof(Mat<Dim>) == Dim * Dim * sizeof(Real), "A is stored dense");
  if constexpr (Dim == 3) {
    std::memcpy(A.data(), &columns[0], sizeof(AxisPack));
    std::memcpy(A.data() + 3, &columns[1], sizeof(AxisPack));
    const AxisPack last = __builtin_shufflevector(columns[1], columns[2], 2, 4, 5, 6);
    std::memcpy(A.data() + 5, &last, sizeof(AxisPack));  // (2, 1) and the last column
  } else if constexpr (Dim == 2) {
    const AxisPack both = __builtin_shufflevector(columns[0], columns[1], 0, 1, 4, 5);
    std::memcpy(A.data(), &both, sizeof(AxisPack));
  } else {
    A(0, 0) = columns[0][0];
  }
}

// F <- (I + dt L) F with L given by its columns: column j becomes
// F_j + sum_k (dt L_k) F_kj, each term one fused multiply-add (fused(): the same
// bits with and without FMA hardware).
template <int Dim>
MPMTB_INLINE inline void deformation_update(Mat<Dim>& F, const AxisPack (&L)[Dim], Real dt) {
  AxisPack dtL[Dim];
  for (int k = 0; k < Dim; ++k) dtL[k] = dt * L[k];
  AxisPack out[Dim];
  for (int j = 0; j < Dim; ++j) {
    AxisPack c = column_pack<Dim>(F, j);
    for (int k = 0; k < Dim; ++k) c = fused(dtL[k], F(k, j) - AxisPack{}, c);
    out[j] = c;
  }
  store_columns<Dim>(F, out);
}
template <int Dim>
MPMTB_INLINE inline void deformation_update(Mat<Dim>& F, const Mat<Dim>& L, Real dt) {
  AxisPack columns[Dim];
  for (int k = 0; k < Dim; ++k) columns[k] = column_pack<Dim>(L, k);
  deformation_update<Dim>(F, columns, dt);
}

// The first Dim lanes of a Row (core/pack.hpp) as an AxisPack, zero beyond: a
// vector of the stencil sums (TensorTransfer::Partial) in registers.
template <int Dim, class R>
MPMTB_INLINE inline AxisPack axis_lanes(const R& row) {
  AxisPack a{};
  for (int b = 0; b < Dim; ++b) a[b] = row.v[b / R::lanes][b % R::lanes];
  return a;
}

}  // namespace mpmtb
