// ln x for a batch of values, a vector register of lanes at a time: std::log is
// one library call per value, which the stress pass of the logarithmic models
// (neo-Hookean) spent a third of its time in.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "core/pack.hpp"

// Vector arguments of inlined functions only (-Wpsabi: see core/pack.hpp).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

namespace mpmtb {

namespace detail {

// The bit layout of an IEEE binary floating-point type.
template <class T>
struct FloatBits;
template <>
struct FloatBits<double> {
  using Int = std::int64_t;
  static constexpr int mantissa = 52, bias = 1023;
  static constexpr int terms = 9;  // z^10 / 21 < 2^-55 for |s| <= 3 - 2 sqrt(2)
};
template <>
struct FloatBits<float> {
  using Int = std::int32_t;
  static constexpr int mantissa = 23, bias = 127;
  static constexpr int terms = 4;  // z^5 / 11 < 2^-28
};

// One register of reals and of integers of the same width (GCC/Clang vector
// extension, as core/pack.hpp): the code below is vector code whatever the
// auto-vectoriser decides.
using LogPack = typename PackOf<kSimdBytes>::type;
using LogInts = typename FloatBits<Real>::Int __attribute__((vector_size(kSimdBytes)));
inline constexpr int kLogLanes = kSimdBytes / sizeof(Real);

// ln x per lane, for positive normal finite x, within 2 ulp (measured).
//   x = 2^e m, m in [sqrt(1/2), sqrt(2)), and with s = (m - 1) / (m + 1),
//   ln m = 2 atanh s = 2 s (1 + z/3 + z^2/5 + ...), z = s^2
// (Abramowitz & Stegun 1964, eq. 4.1.27), |s| <= 3 - 2 sqrt(2), so the series
// is cut where the next term is below the last bit. ln 2 is split into a head
// with trailing zero bits, so that e times it is exact, and a tail (Cody & Waite
// 1980, ch. 5). m - 1 is exact (Sterbenz), so ln x near 1 keeps its relative
// accuracy.
[[gnu::always_inline]] inline LogPack log_of_normal(LogPack x) {
  using B = FloatBits<Real>;
  using Int = typename B::Int;
  const LogInts bits = std::bit_cast<LogInts>(x);
  const LogInts mantissa_mask = LogInts{} + ((Int{1} << B::mantissa) - 1);
  const LogInts one_bits = LogInts{} + (Int{B::bias} << B::mantissa);
  LogInts biased = bits >> B::mantissa;  // the sign bit is clear
  LogInts m_bits = (bits & mantissa_mask) | one_bits;
  LogPack m = std::bit_cast<LogPack>(m_bits);
  const LogInts high = m > Real(1.4142135623730950488);
  m = high ? m * Real(0.5) : m;
  biased = biased - high;  // high is -1 where true
  // The exponent as a real, exactly: its bits below those of 2^mantissa.
  LogInts magic_bits = biased | (Int{B::bias + B::mantissa} << B::mantissa);
  const Real magic = Real(Int{1} << B::mantissa);
  const LogPack E = (std::bit_cast<LogPack>(magic_bits) - magic) - Real(B::bias);
  const LogPack s = (m - Real(1)) / (m + Real(1));
  const LogPack z = s * s;
  LogPack series = LogPack{} + Real(1) / Real(2 * B::terms + 1);
  for (int k = B::terms - 1; k >= 1; --k) series = series * z + Real(1) / Real(2 * k + 1);
  series = series * z;
  const LogPack two_s = s + s;
  const LogPack ln_m = two_s + two_s * series;
  // ln 2 = ln2_head + ln2_tail; ln2_head has 21 trailing zero bits (|e| < 2^11).
  constexpr Real ln2_head = Real(0.693147180369123816490);
  constexpr Real ln2_tail = Real(1.90821492927058770002e-10);
  return E * ln2_head + (ln_m + E * ln2_tail);
}

// y[k] = vector(x[k]) for k < n, a register of lanes at a time, for the lanes
// where valid holds (the others go through vector as `safe`), and scalar(x[k])
// for the others: the batch loop of batch_log and batch_exp (core/batch_exp.hpp).
template <class Valid, class Vector, class Scalar>
inline void batch_apply(const Real* x, Real* y, int n, Valid&& valid, Real safe, Vector&& vector,
                        Scalar&& scalar) {
  for (int k0 = 0; k0 < n; k0 += kLogLanes) {
    const int lanes = std::min(kLogLanes, n - k0);
    LogPack v = LogPack{} + safe;
    if (lanes == kLogLanes) {
      std::memcpy(&v, x + k0, sizeof v);
    } else {
      for (int l = 0; l < lanes; ++l) v[l] = x[k0 + l];
    }
    const auto ok = valid(v);
    const LogPack r = vector(ok ? v : LogPack{} + safe);
    if (lanes == kLogLanes) {
      std::memcpy(y + k0, &r, sizeof r);
    } else {
      for (int l = 0; l < lanes; ++l) y[k0 + l] = r[l];
    }
    for (int l = 0; l < lanes; ++l) {
      if (!ok[l]) y[k0 + l] = scalar(x[k0 + l]);
    }
  }
}

}  // namespace detail

// y[k] = ln x[k] for k < n, a register of lanes at a time. Values that are not
// positive, normal and finite (x <= 0 of an inverted particle, infinities, NaN,
// subnormals) get std::log's result, so the unstable-run checks see what they
// saw before.
inline void batch_log(const Real* x, Real* y, int n) {
  const Real lowest_normal = std::numeric_limits<Real>::min();
  const Real largest = std::numeric_limits<Real>::max();
  detail::batch_apply(
      x, y, n, [&](detail::LogPack v) { return (v >= lowest_normal) & (v <= largest); }, Real(1),
      [](detail::LogPack v) { return detail::log_of_normal(v); },
      [](Real a) { return std::log(a); });
}

}  // namespace mpmtb

#pragma GCC diagnostic pop
