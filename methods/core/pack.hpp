// SIMD values from the GCC/Clang vector extension. A Pack is one register of
// the target (SSE2, AVX or AVX-512: the widest the build enables); a Row<N> is N
// reals as a few Packs. Arithmetic on them compiles to vector instructions,
// where the compiler's own vectorizer gives up on the fully unrolled per-node
// loops of the transfers. (Vectors wider than the target's registers compile
// to poor code, hence Rows of native Packs rather than one wide vector.)
#pragma once

#include <algorithm>
#include <cstring>
#include <utility>

#include "core/types.hpp"

// Every function here is inlined, so the ABI of vector arguments and returns
// (-Wpsabi: it differs between instruction sets) never applies.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

// The transfers' per-node code is inlined whole.
#define MPMTB_INLINE [[gnu::always_inline]]

namespace mpmtb {

#if defined(__AVX512F__)
inline constexpr int kSimdBytes = 64;
#elif defined(__AVX__)
inline constexpr int kSimdBytes = 32;
#else
inline constexpr int kSimdBytes = 16;
#endif

template <int Bytes>
struct PackOf;
template <>
struct PackOf<16> {
  typedef Real type __attribute__((vector_size(16)));
};
template <>
struct PackOf<32> {
  typedef Real type __attribute__((vector_size(32)));
};
template <>
struct PackOf<64> {
  typedef Real type __attribute__((vector_size(64)));
};

// N reals (N * sizeof(Real) a multiple of 16 bytes) as K registers.
template <int N>
struct Row {
  static constexpr int bytes = std::min<int>(kSimdBytes, N * sizeof(Real));
  static constexpr int lanes = bytes / sizeof(Real);
  static constexpr int K = N / lanes;
  static_assert(K * lanes == N, "a Row is a whole number of registers");
  using Pack = typename PackOf<bytes>::type;
  Pack v[K];

  MPMTB_INLINE static Row zero() {
    Row r;
    for (int k = 0; k < K; ++k) r.v[k] = Pack{};
    return r;
  }
  // From and to any Real array (unaligned moves: no cost on aligned data).
  MPMTB_INLINE static Row load(const Real* from) {
    Row r;
    for (int k = 0; k < K; ++k) std::memcpy(&r.v[k], from + k * lanes, bytes);
    return r;
  }
  MPMTB_INLINE void store(Real* to) const {
    for (int k = 0; k < K; ++k) std::memcpy(to + k * lanes, &v[k], bytes);
  }
  // From N scalars, in registers: values that were just stored one by one are
  // not read back by a wider load (which would wait for the stores to retire).
  MPMTB_INLINE static Row gather(const Real* from) {
    Row r;
    for (int k = 0; k < K; ++k) {
      r.v[k] = [&]<int... i>(std::integer_sequence<int, i...>) {
        return Pack{from[k * lanes + i]...};
      }
      (std::make_integer_sequence<int, lanes>{});
    }
    return r;
  }
  MPMTB_INLINE friend Row operator*(Real s, const Row& a) {
    Row r;
    for (int k = 0; k < K; ++k) r.v[k] = s * a.v[k];
    return r;
  }
  MPMTB_INLINE Row& operator+=(const Row& a) {
    for (int k = 0; k < K; ++k) v[k] += a.v[k];
    return *this;
  }
  // *this += s a
  MPMTB_INLINE void add_scaled(Real s, const Row& a) {
    for (int k = 0; k < K; ++k) v[k] += s * a.v[k];
  }
};

}  // namespace mpmtb

#pragma GCC diagnostic pop
