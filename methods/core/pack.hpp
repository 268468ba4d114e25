// SIMD values from the GCC/Clang vector extension. A Pack is one register of
// the target (SSE2, AVX or AVX-512: the widest the build enables); a Row<N> is N
// reals as a few Packs. Arithmetic on them compiles to vector instructions,
// where the compiler's own vectorizer gives up on the fully unrolled per-node
// loops of the transfers. (Vectors wider than the target's registers compile
// to poor code, hence Rows of native Packs rather than one wide vector.)
#pragma once

#include <algorithm>
#include <cmath>
#include <cstring>
#include <type_traits>
#include <utility>

#if defined(__FMA__) || defined(__AVX512F__)
#include <immintrin.h>
#endif

#include "core/types.hpp"

// Every function here is inlined, so the ABI of vector arguments and returns
// (-Wpsabi: it differs between instruction sets) never applies.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

// The transfers' per-node code is inlined whole.
#define MPMTB_INLINE [[gnu::always_inline]]
// The same for a lambda (after its parameter list).
#define MPMTB_INLINE_LAMBDA __attribute__((always_inline))

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

// x y + z per lane, rounded once. The fusion is spelled here, not left to the
// compiler (-ffp-contract=off): every target computes the same bits, with the
// FMA instruction where it has one and std::fma (correctly rounded, so equal)
// where it has not.
template <class Pack>
MPMTB_INLINE inline Pack fused(Pack x, Pack y, Pack z) {
  constexpr int bytes = sizeof(Pack);
  constexpr bool is_double = std::is_same_v<Real, double>;
#if defined(__AVX512F__)
  if constexpr (bytes == 64 && is_double) return _mm512_fmadd_pd(x, y, z);
  if constexpr (bytes == 64 && !is_double) return _mm512_fmadd_ps(x, y, z);
#endif
#if defined(__FMA__)
  if constexpr (bytes == 32 && is_double) return _mm256_fmadd_pd(x, y, z);
  if constexpr (bytes == 32 && !is_double) return _mm256_fmadd_ps(x, y, z);
  if constexpr (bytes == 16 && is_double) return _mm_fmadd_pd(x, y, z);
  if constexpr (bytes == 16 && !is_double) return _mm_fmadd_ps(x, y, z);
#endif
  Pack r;
  for (int i = 0; i < bytes / static_cast<int>(sizeof(Real)); ++i)
    r[i] = std::fma(x[i], y[i], z[i]);
  return r;
}

// Lane I of a pack in every lane of a pack of type To (of any width): one
// shuffle or broadcast in registers, where reading the lane out as a Real and
// broadcasting it back took two or three (and often a trip through the stack).
template <int I, class To, class From>
MPMTB_INLINE inline To splat(From from) {
  constexpr int lanes = sizeof(To) / sizeof(Real);
  return [&]<int... l>(std::integer_sequence<int, l...>) MPMTB_INLINE_LAMBDA {
    return __builtin_shufflevector(from, from, (l * 0 + I)...);
  }
  (std::make_integer_sequence<int, lanes>{});
}

// N reals (N * sizeof(Real) a multiple of 16 bytes) as K registers.
template <int N>
struct Row {
  static constexpr int count = N;  // reals
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
      r.v[k] = [&]<int... i>(std::integer_sequence<int, i...>) MPMTB_INLINE_LAMBDA {
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
  // *this += s a, each lane as one fused multiply-add (rounded once, fused()),
  // so that every transfer that sums through a Row rounds the same way.
  MPMTB_INLINE void add_scaled(Real s, const Row& a) {
    const Pack sp = s - Pack{};  // s in every lane
    for (int k = 0; k < K; ++k) v[k] = fused(sp, a.v[k], v[k]);
  }
  // *this += s a with s = lane I of the pack `from` (splat: the same value).
  template <int I, class From>
  MPMTB_INLINE void add_scaled_lane(From from, const Row& a) {
    const Pack sp = splat<I, Pack>(from);
    for (int k = 0; k < K; ++k) v[k] = fused(sp, a.v[k], v[k]);
  }
};

// A stencil row: the N = S * W values of the S nodes along the grid's fastest
// axis (W per node, consecutive in memory), as the fewest registers of at most 32
// bytes: the widest packs first, then narrower ones (12 doubles: 4 + 4 + 4, 12
// floats: 8 + 4). The transfers' last axis works on whole strips, so a row of
// nodes costs a load, a fused multiply-add per term and a store per register
// instead of per node.
// (With AVX-512, 8 + 4 doubles measured 4 % slower on the 3D block than 4 + 4 + 4,
// likely because the next particle's stencil row, a node further on, loads across
// two of the previous one's stores, which a core cannot forward; G2P's strips,
// which only load, measured the same either way.)
template <int N>
struct Strip {
  static constexpr int count = N;
  static constexpr int bytes = [] {
    int b = std::min(kSimdBytes, 32);
    while (b > 16 && b > N * static_cast<int>(sizeof(Real))) b /= 2;
    return b;
  }();
  static constexpr int lanes = bytes / sizeof(Real);
  static_assert(N * sizeof(Real) % 16 == 0, "a Strip is whole 16-byte registers");
  using Pack = typename PackOf<bytes>::type;
  Pack head;
  Strip<N - lanes> tail;

  // Lane l = f(l), built in registers.
  template <int First = 0, class F>
  MPMTB_INLINE static Strip from(F&& f) {
    Strip s;
    s.head = [&]<int... i>(std::integer_sequence<int, i...>) MPMTB_INLINE_LAMBDA {
      return Pack{f(First + i)...};
    }
    (std::make_integer_sequence<int, lanes>{});
    s.tail = Strip<N - lanes>::template from<First + lanes>(f);
    return s;
  }
  // The W values of a Row repeated across the strip's S nodes (lane l = r[l % W]).
  template <int W>
  MPMTB_INLINE static Strip repeat(const Row<W>& r) {
    return from([&](int l) MPMTB_INLINE_LAMBDA {
      return r.v[(l % W) / Row<W>::lanes][(l % W) % Row<W>::lanes];
    });
  }
  MPMTB_INLINE static Strip load(const Real* from) {
    Strip s;
    std::memcpy(&s.head, from, bytes);
    s.tail = Strip<N - lanes>::load(from + lanes);
    return s;
  }
  MPMTB_INLINE void store(Real* to) const {
    std::memcpy(to, &head, bytes);
    tail.store(to + lanes);
  }
  // Per lane: a b, a + b, and a b + c rounded once (fused()).
  MPMTB_INLINE friend Strip operator*(const Strip& a, const Strip& b) {
    Strip s;
    s.head = a.head * b.head;
    s.tail = a.tail * b.tail;
    return s;
  }
  MPMTB_INLINE friend Strip operator+(const Strip& a, const Strip& b) {
    Strip s;
    s.head = a.head + b.head;
    s.tail = a.tail + b.tail;
    return s;
  }
  MPMTB_INLINE static Strip fma(const Strip& a, const Strip& b, const Strip& c) {
    Strip s;
    s.head = fused(a.head, b.head, c.head);
    s.tail = Strip<N - lanes>::fma(a.tail, b.tail, c.tail);
    return s;
  }
  // a b + c with a scalar a in every lane.
  MPMTB_INLINE static Strip fma(Real a, const Strip& b, const Strip& c) {
    Strip s;
    s.head = fused(a - Pack{}, b.head, c.head);
    s.tail = Strip<N - lanes>::fma(a, b.tail, c.tail);
    return s;
  }
  // a b + c with a = lane I of the pack `from` in every lane (splat).
  template <int I, class From>
  MPMTB_INLINE static Strip fma_lane(From from, const Strip& b, const Strip& c) {
    Strip s;
    s.head = fused(splat<I, Pack>(from), b.head, c.head);
    s.tail = Strip<N - lanes>::template fma_lane<I>(from, b.tail, c.tail);
    return s;
  }
  // Lane l of the strip.
  MPMTB_INLINE Real operator[](int l) const { return l < lanes ? head[l] : tail[l - lanes]; }
  // Lanes First .. First + W - 1 as a Row, in registers.
  template <int First, int W>
  MPMTB_INLINE Row<W> segment() const {
    Row<W> r;
    for (int k = 0; k < Row<W>::K; ++k) {
      r.v[k] = [&]<int... i>(std::integer_sequence<int, i...>) MPMTB_INLINE_LAMBDA {
        return typename Row<W>::Pack{(*this)[First + k * Row<W>::lanes + i]...};
      }
      (std::make_integer_sequence<int, Row<W>::lanes>{});
    }
    return r;
  }
};
template <>
struct Strip<0> {
  template <int First, class F>
  MPMTB_INLINE static Strip from(F&&) {
    return {};
  }
  MPMTB_INLINE static Strip load(const Real*) { return {}; }
  MPMTB_INLINE void store(Real*) const {}
  MPMTB_INLINE friend Strip operator*(const Strip&, const Strip&) { return {}; }
  MPMTB_INLINE friend Strip operator+(const Strip&, const Strip&) { return {}; }
  MPMTB_INLINE static Strip fma(const Strip&, const Strip&, const Strip&) { return {}; }
  MPMTB_INLINE static Strip fma(Real, const Strip&, const Strip&) { return {}; }
  template <int I, class From>
  MPMTB_INLINE static Strip fma_lane(From, const Strip&, const Strip&) {
    return {};
  }
  MPMTB_INLINE Real operator[](int) const { return 0; }
};

// A Row built lane by lane, with the Eigen-like setters the transfers write
// their P2G form with (col[i] = x, col.segment<K>(i) = or += vector). The lanes
// are set in registers: a column written to memory piecewise and then read as
// whole registers would stall on store forwarding (the loads span several
// narrower stores), which the profile showed as the costliest part of P2G's
// set-up.
template <int N>
class RowBuilder {
 public:
  MPMTB_INLINE RowBuilder() : row_(Row<N>::zero()) {}
  MPMTB_INLINE const Row<N>& row() const { return row_; }
  MPMTB_INLINE Real operator[](int i) const { return row_.v[i / lanes][i % lanes]; }

  class Lane {
   public:
    MPMTB_INLINE Lane(RowBuilder& c, int i) : c_(c), i_(i) {}
    MPMTB_INLINE Lane& operator=(Real x) {
      c_.set(i_, x);
      return *this;
    }

   private:
    RowBuilder& c_;
    int i_;
  };
  MPMTB_INLINE Lane operator[](int i) { return {*this, i}; }

  // Lanes first .. first + K - 1, as an Eigen K-vector.
  template <int K>
  class Segment {
   public:
    MPMTB_INLINE Segment(RowBuilder& c, int first) : c_(c), first_(first) {}
    template <class E>
    MPMTB_INLINE Segment& operator=(const Eigen::MatrixBase<E>& e) {
      const Eigen::Matrix<Real, K, 1> x = e;
      for (int k = 0; k < K; ++k) c_.set(first_ + k, x[k]);
      return *this;
    }
    template <class E>
    MPMTB_INLINE Segment& operator+=(const Eigen::MatrixBase<E>& e) {
      const Eigen::Matrix<Real, K, 1> x = e;
      for (int k = 0; k < K; ++k) c_.set(first_ + k, std::as_const(c_)[first_ + k] + x[k]);
      return *this;
    }

   private:
    RowBuilder& c_;
    int first_;
  };
  template <int K>
  MPMTB_INLINE Segment<K> segment(int first) {
    return {*this, first};
  }

 private:
  static constexpr int lanes = Row<N>::lanes;
  MPMTB_INLINE void set(int i, Real x) { row_.v[i / lanes][i % lanes] = x; }
  Row<N> row_;
};

}  // namespace mpmtb

#pragma GCC diagnostic pop
