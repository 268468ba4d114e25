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

#include "core/pack.hpp"
#include "core/stencil.hpp"
#include "core/types.hpp"

namespace mpmtb {

// Column j of a small matrix in the first Dim lanes of an AxisPack, zero beyond.
template <int Dim>
MPMTB_INLINE inline AxisPack column_pack(const Mat<Dim>& A, int j) {
  AxisPack c{};
  for (int i = 0; i < Dim; ++i) c[i] = A(i, j);
  return c;
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
  for (int j = 0; j < Dim; ++j)
    for (int i = 0; i < Dim; ++i) F(i, j) = out[j][i];
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
