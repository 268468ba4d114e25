// The damage stress pass's vectorised exponential (core/batch_exp.hpp) against
// the C library's long-double expl.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "core/batch_exp.hpp"

namespace batch_exp_test {
using namespace mpmtb;

// |y - e^x| in units in the last place of e^x, against expl.
double ulps(Real x, Real y) {
  const long double exact = expl(static_cast<long double>(x));
  const Real r = static_cast<Real>(exact);
  const Real ulp = std::nextafter(r, std::numeric_limits<Real>::infinity()) - r;
  return static_cast<double>(std::abs(static_cast<long double>(y) - exact) / ulp);
}

std::vector<Real> batch(const std::vector<Real>& x) {
  std::vector<Real> y(x.size());
  batch_exp(x.data(), y.data(), static_cast<int>(x.size()));
  return y;
}

TEST(BatchExp, WithinTwoUlpOverTheWholeRangeAndNearZero) {
  std::vector<Real> x;
  std::mt19937_64 rng(11);
  const double lo = std::log(std::numeric_limits<Real>::min()),
               hi = std::log(std::numeric_limits<Real>::max());
  std::uniform_real_distribution<double> whole(lo, hi), near_zero(-1e-2, 1e-2);
  for (int k = 0; k < 20000; ++k) x.push_back(static_cast<Real>(whole(rng)));
  for (int k = 0; k < 20000; ++k) x.push_back(static_cast<Real>(near_zero(rng)));
  // Around the reduction's switches at (n + 1/2) ln 2, and the neighbours of 0.
  Real u = 0, d = 0;
  for (int n = -6; n <= 6; ++n) {
    Real s = static_cast<Real>((n + 0.5) * 0.69314718055994530942);
    for (int k = 0; k < 16; ++k) x.push_back(s), s = std::nextafter(s, Real(100));
  }
  for (int k = 0; k < 64; ++k) {
    x.push_back(u = std::nextafter(u, Real(1)));
    x.push_back(d = std::nextafter(d, Real(-1)));
  }
  const std::vector<Real> y = batch(x);
  double worst = 0;
  for (std::size_t k = 0; k < x.size(); ++k) worst = std::max(worst, ulps(x[k], y[k]));
  EXPECT_LE(worst, 2.0);
  EXPECT_EQ(batch({Real(0)})[0], Real(1));
}

TEST(BatchExp, ValuesOutsideTheNormalRangeGetTheLibraryResult) {
  const Real inf = std::numeric_limits<Real>::infinity();
  const std::vector<Real> x = {-inf,       inf,        std::numeric_limits<Real>::quiet_NaN(),
                               Real(-745), Real(-720), Real(710),
                               Real(-100), Real(100),  Real(0.5)};
  const std::vector<Real> y = batch(x);
  for (std::size_t k = 0; k < x.size(); ++k) {
    const Real expected = std::exp(x[k]);
    if (std::isnan(expected)) {
      EXPECT_TRUE(std::isnan(y[k])) << x[k];
    } else if (!(x[k] >= detail::ExpConstants<Real>::lowest &&
                 x[k] <= detail::ExpConstants<Real>::highest)) {
      EXPECT_EQ(y[k], expected) << x[k];
    } else {
      EXPECT_LE(ulps(x[k], y[k]), 2.0) << x[k];
    }
  }
}

TEST(BatchExp, EveryLengthGivesTheSameValuesAsOneByOne) {
  std::vector<Real> x;
  for (int k = 0; k < 19; ++k) x.push_back(Real(-3.7) + Real(0.41) * k);
  for (int n = 1; n <= 19; ++n) {
    std::vector<Real> y(n);
    batch_exp(x.data(), y.data(), n);
    for (int k = 0; k < n; ++k) {
      Real one;
      batch_exp(&x[k], &one, 1);
      EXPECT_EQ(y[k], one) << "n " << n << " k " << k;
    }
  }
}

}  // namespace batch_exp_test
