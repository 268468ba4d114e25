// e^x for a batch of values, a vector register of lanes at a time (as
// core/batch_log.hpp's logarithms): std::exp is one library call per value,
// which the damage model's stress pass spent 4 % of the pinned block's step in
// (for J^(2/3) = exp(2/3 ln J)).
#pragma once

#include <bit>
#include <cmath>

#include "core/batch_log.hpp"

// Vector arguments of inlined functions only (-Wpsabi: see core/pack.hpp).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"

namespace mpmtb {

namespace detail {

// The reduction's constants per precision: ln 2 split into a head with
// trailing zero bits (n times it is exact for the n of the range) and a tail;
// the Taylor terms kept; the range of x whose e^x is a normal number.
template <class T>
struct ExpConstants;
template <>
struct ExpConstants<double> {
  static constexpr double ln2_head = 0.693147180369123816490;  // 21 trailing zero bits
  static constexpr double ln2_tail = 1.90821492927058770002e-10;
  static constexpr int terms = 13;  // (ln 2 / 2)^14 / 14! < 2^-57
  static constexpr double lowest = -708, highest = 709;
};
template <>
struct ExpConstants<float> {
  static constexpr float ln2_head = 0.693145751953125f;  // 9 trailing zero bits
  static constexpr float ln2_tail = 1.428606765330187045e-06f;
  static constexpr int terms = 7;  // (ln 2 / 2)^8 / 8! < 2^-27
  static constexpr float lowest = -87, highest = 88;
};

// 1 / k! in the precision built (k! is exact for the k used).
constexpr Real inverse_factorial(int k) {
  Real f = 1;
  for (int i = 2; i <= k; ++i) f *= i;
  return 1 / f;
}

// e^x per lane for x in [lowest, highest], within 2 ulp (measured). x = n ln 2 + r
// with n the nearest integer to x / ln 2, |r| <= ln 2 / 2, r formed with ln 2
// in two parts (Cody & Waite 1980, ch. 6); e^r by its Taylor series in Horner's
// form, cut where the next term is below the last bit; 2^n from its exponent bits.
[[gnu::always_inline]] inline LogPack exp_in_range(LogPack x) {
  using B = FloatBits<Real>;
  using C = ExpConstants<Real>;
  using Int = typename B::Int;
  // x / ln 2 + 1.5 2^mantissa rounds x / ln 2 to an integer in the low bits.
  constexpr Real shifter = Real(3) * Real(Int{1} << (B::mantissa - 1));
  const LogPack t = x * Real(1.44269504088896340736) + shifter;
  const LogPack n = t - shifter;
  const LogPack r = (x - n * C::ln2_head) - n * C::ln2_tail;
  LogPack p = LogPack{} + inverse_factorial(C::terms);
  for (int k = C::terms - 1; k >= 0; --k) p = fused(p, r, LogPack{} + inverse_factorial(k));
  const LogInts n_int = std::bit_cast<LogInts>(t) - std::bit_cast<Int>(shifter);
  const LogPack two_n = std::bit_cast<LogPack>((n_int + B::bias) << B::mantissa);
  return p * two_n;
}

}  // namespace detail

// y[k] = e^x[k] for k < n, a register of lanes at a time. Values outside the
// range where e^x is a normal number (and NaN) get std::exp's result.
inline void batch_exp(const Real* x, Real* y, int n) {
  using C = detail::ExpConstants<Real>;
  detail::batch_apply(
      x, y, n, [](detail::LogPack v) { return (v >= C::lowest) & (v <= C::highest); }, Real(0),
      [](detail::LogPack v) { return detail::exp_in_range(v); },
      [](Real a) { return std::exp(a); });
}

}  // namespace mpmtb

#pragma GCC diagnostic pop
