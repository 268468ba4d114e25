// A per-particle formula over a vector register of particles, one particle per
// lane (ModelBase's stress batches, G2P's failure check): F_p's entries in, one
// pack per entry, and V0_p tau_p out. A formula written once as a template on
// its number type T runs with T = Lanes in the batches and with T = Real for
// one particle, the same operations in each lane, so the two give the same bits.
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

// out[e] lane l = in[l] lane e: an 8 x 8 block of Reals transposed in three
// rounds of two-register shuffles (24 in all), for packs of 8 lanes.
template <class Pack>
MPMTB_INLINE inline void transpose8(const Pack (&in)[8], Pack (&out)[8]) {
  Pack t[8], u[8];
  for (int i = 0; i < 8; i += 2) {  // lanes (even, odd entries) of rows i, i + 1
    t[i] = __builtin_shufflevector(in[i], in[i + 1], 0, 8, 2, 10, 4, 12, 6, 14);
    t[i + 1] = __builtin_shufflevector(in[i], in[i + 1], 1, 9, 3, 11, 5, 13, 7, 15);
  }
  for (int i = 0; i < 8; i += 4) {  // entries (e, e + 4) of rows i .. i + 3
    for (int odd = 0; odd < 2; ++odd) {
      const Pack& a = t[i + odd];
      const Pack& b = t[i + 2 + odd];
      u[i + odd] = __builtin_shufflevector(a, b, 0, 1, 8, 9, 4, 5, 12, 13);
      u[i + 2 + odd] = __builtin_shufflevector(a, b, 2, 3, 10, 11, 6, 7, 14, 15);
    }
  }
  for (int e = 0; e < 4; ++e) {  // rows 0 .. 3 and 4 .. 7 of entries e and e + 4
    out[e] = __builtin_shufflevector(u[e], u[4 + e], 0, 1, 2, 3, 8, 9, 10, 11);
    out[e + 4] = __builtin_shufflevector(u[e], u[4 + e], 4, 5, 6, 7, 12, 13, 14, 15);
  }
}

// Whole registers of 3x3 matrices move by rows of 8 Reals and transpose8, 8
// lanes at a time (perf: lane by lane, the stress batches' loads and stores
// were most of their instructions). F(i, j) is entry i + 3 j of the
// column-major storage; the ninth, (2, 2), goes lane by lane.
template <int Dim>
inline constexpr bool kTransposes = Dim == 3 && kLanes % 8 == 0 && kLanes <= 16;
using Eight = typename PackOf<8 * sizeof(Real)>::type;        // 8 lanes
inline constexpr int kEights = kLanes >= 8 ? kLanes / 8 : 1;  // in a register of Lanes

// Lanes 8 b .. 8 b + 7 of x, and the register of the kEights blocks e[b].
// (Templates: instantiated only where kTransposes.)
template <class L = Lanes>
MPMTB_INLINE inline Eight eight_of(const L& x, int b) {
  if constexpr (kEights == 1) {
    return x;
  } else {
    return b == 0 ? __builtin_shufflevector(x, x, 0, 1, 2, 3, 4, 5, 6, 7)
                  : __builtin_shufflevector(x, x, 8, 9, 10, 11, 12, 13, 14, 15);
  }
}
template <class E = Eight>
MPMTB_INLINE inline Lanes whole_of(const E (&e)[kEights]) {
  if constexpr (kEights == 1) {
    return e[0];
  } else {
    return __builtin_shufflevector(e[0], e[1], 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14,
                                   15);
  }
}

// out[i][j] = M[ids[l]](i, j) in lane l < lanes; the identity in the others.
template <int Dim>
MPMTB_INLINE inline void load_lanes(const std::vector<Mat<Dim>>& M, const int* ids, int lanes,
                                    Lanes (&out)[Dim][Dim]) {
  if constexpr (kTransposes<Dim>) {
    if (lanes == kLanes) {
      Eight entries[8][kEights];
      for (int b = 0; b < kEights; ++b) {
        Eight rows[8], block[8];
        for (int l = 0; l < 8; ++l) std::memcpy(&rows[l], M[ids[8 * b + l]].data(), sizeof(Eight));
        transpose8(rows, block);
        for (int e = 0; e < 8; ++e) entries[e][b] = block[e];
      }
      for (int e = 0; e < 8; ++e) out[e % 3][e / 3] = whole_of(entries[e]);
      out[2][2] =
          lanes_from(kLanes, Real(0), [&](int l) MPMTB_INLINE_LAMBDA { return M[ids[l]](2, 2); });
      return;
    }
  }
  for (int i = 0; i < Dim; ++i) {
    for (int j = 0; j < Dim; ++j) {
      out[i][j] = lanes_from(lanes, i == j ? Real(1) : Real(0),
                             [&](int l) MPMTB_INLINE_LAMBDA { return M[ids[l]](i, j); });
    }
  }
}

// Lane l = Real 3 l + k of the 3 N Reals in a, b, c (N lanes each): from a and
// b below 2 N, else from c.
template <int k, class Pack>
MPMTB_INLINE inline Pack every_third(const Pack& a, const Pack& b, const Pack& c) {
  constexpr int N = sizeof(Pack) / sizeof(Real);
  return [&]<int... l>(std::integer_sequence<int, l...>) MPMTB_INLINE_LAMBDA {
    const Pack ab = __builtin_shufflevector(a, b, (3 * l + k < 2 * N ? 3 * l + k : 0)...);
    return __builtin_shufflevector(ab, c, (3 * l + k < 2 * N ? l : 3 * l + k - N)...);
  }
  (std::make_integer_sequence<int, N>{});
}

// out[a] lane l = v[l][a] for the kLanes vectors v[0] .. v[kLanes - 1] side by
// side in memory: whole-register loads and shuffles where kTransposes<Dim>.
template <int Dim>
MPMTB_INLINE inline void load_vector_lanes(const Vec<Dim>* v, Lanes (&out)[Dim]) {
  static_assert(sizeof(Vec<Dim>) == Dim * sizeof(Real), "vectors side by side");
  if constexpr (kTransposes<Dim>) {
    Lanes a, b, c;  // the 3 kLanes Reals
    std::memcpy(&a, v[0].data(), sizeof a);
    std::memcpy(&b, v[0].data() + kLanes, sizeof b);
    std::memcpy(&c, v[0].data() + 2 * kLanes, sizeof c);
    out[0] = every_third<0>(a, b, c);
    out[1] = every_third<1>(a, b, c);
    out[2] = every_third<2>(a, b, c);
  } else {
    for (int a = 0; a < Dim; ++a)
      out[a] = lanes_from(kLanes, Real(0), [&](int l) MPMTB_INLINE_LAMBDA { return v[l][a]; });
  }
}

// out[e] lane l = record_l[e], e < 4, for the records record_l = base + ids[l]
// stride of a whole register of particles (each record at least 4 Reals: a
// model's state, Particles::state_of): rows of 4 Reals paired into registers of
// 8 and transposed in 8 shuffles per 8 lanes. (Lane by lane, three values a
// particle, the loads and inserts were a third of the damage screen's
// instructions.)
// (A template: instantiated only where kRecordTransposes.)
inline constexpr bool kRecordTransposes = kLanes % 8 == 0 && kLanes <= 16;
template <class L = Lanes>
MPMTB_INLINE inline void load_record_lanes(const Real* base, long stride, const int* ids,
                                           L (&out)[4]) {
  static_assert(kRecordTransposes);
  using Four = typename PackOf<4 * sizeof(Real)>::type;
  Eight entries[4][kEights];
  for (int b = 0; b < kEights; ++b) {
    const int* at = ids + 8 * b;
    Eight pair[4];  // records i and i + 4 side by side
    for (int i = 0; i < 4; ++i) {
      Four lo, hi;
      std::memcpy(&lo, base + at[i] * stride, sizeof lo);
      std::memcpy(&hi, base + at[i + 4] * stride, sizeof hi);
      pair[i] = __builtin_shufflevector(lo, hi, 0, 1, 2, 3, 4, 5, 6, 7);
    }
    // Entries (0, 2) and (1, 3) of records (0, 1 | 4, 5) and (2, 3 | 6, 7).
    const Eight t0 = __builtin_shufflevector(pair[0], pair[1], 0, 8, 2, 10, 4, 12, 6, 14);
    const Eight t1 = __builtin_shufflevector(pair[0], pair[1], 1, 9, 3, 11, 5, 13, 7, 15);
    const Eight t2 = __builtin_shufflevector(pair[2], pair[3], 0, 8, 2, 10, 4, 12, 6, 14);
    const Eight t3 = __builtin_shufflevector(pair[2], pair[3], 1, 9, 3, 11, 5, 13, 7, 15);
    entries[0][b] = __builtin_shufflevector(t0, t2, 0, 1, 8, 9, 4, 5, 12, 13);
    entries[2][b] = __builtin_shufflevector(t0, t2, 2, 3, 10, 11, 6, 7, 14, 15);
    entries[1][b] = __builtin_shufflevector(t1, t3, 0, 1, 8, 9, 4, 5, 12, 13);
    entries[3][b] = __builtin_shufflevector(t1, t3, 2, 3, 10, 11, 6, 7, 14, 15);
  }
  for (int e = 0; e < 4; ++e) out[e] = whole_of(entries[e]);
}

// Whether every lane of a comparison's mask is true: halves and-ed together
// (lane by lane, the lanes' extractions were most of G2P's check).
template <class Mask>
MPMTB_INLINE inline bool all_lanes(const Mask& m) {
  constexpr int N = sizeof(Mask) / sizeof(m[0]);
  if constexpr (N == 1) {
    return m[0] != 0;
  } else {
    return [&]<int... l>(std::integer_sequence<int, l...>) MPMTB_INLINE_LAMBDA {
      return all_lanes(__builtin_shufflevector(m, m, l...) &
                       __builtin_shufflevector(m, m, (l + N / 2)...));
    }
    (std::make_integer_sequence<int, N / 2>{});
  }
}

// out(l) = the matrix of lane l, for l < lanes.
template <int Dim, class Out>
MPMTB_INLINE inline void store_lanes(const Lanes (&in)[Dim][Dim], int lanes, Out&& out) {
  if constexpr (kTransposes<Dim>) {
    if (lanes == kLanes) {
      alignas(sizeof(Lanes)) Real last[kLanes];
      std::memcpy(last, &in[2][2], sizeof last);
      for (int b = 0; b < kEights; ++b) {
        Eight entries[8], rows[8];
        for (int e = 0; e < 8; ++e) entries[e] = eight_of(in[e % 3][e / 3], b);
        transpose8(entries, rows);
        for (int l = 0; l < 8; ++l) {
          Mat<Dim>& m = out(8 * b + l);
          std::memcpy(m.data(), &rows[l], sizeof(Eight));
          m(2, 2) = last[8 * b + l];
        }
      }
      return;
    }
  }
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
